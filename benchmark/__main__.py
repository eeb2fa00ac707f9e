"""``python -m benchmark`` is the ``sbib`` command."""

try:
    from benchmark.applications.cli import run
except KeyboardInterrupt:  # Ctrl-C while the command line itself is imported: one line, 130
    import sys

    print("sbib: interrupted", file=sys.stderr)
    raise SystemExit(130) from None

run()
