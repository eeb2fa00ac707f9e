"""``python -m benchmark`` is the ``sbib`` command."""

import os
import signal
import sys


def _interrupted_while_importing(signum, frame):  # noqa: ARG001 (a signal handler's signature)
    # Ctrl-C while the command line itself is imported: one line, 130. Exiting from the handler
    # itself: a KeyboardInterrupt raised inside an extension module's import code (charset_normalizer,
    # Cython, imported by numpy.f2py under scipy) had ended the process by the signal (-2) after
    # the line, whatever the except clause below did. Nothing is written before the command runs.
    print("sbib: interrupted", file=sys.stderr, flush=True)
    os._exit(130)


signal.signal(signal.SIGINT, _interrupted_while_importing)
try:
    from benchmark.applications.cli import run
except KeyboardInterrupt:  # a Ctrl-C delivered as the exception all the same
    print("sbib: interrupted", file=sys.stderr)
    raise SystemExit(130) from None
signal.signal(signal.SIGINT, signal.default_int_handler)  # the command's own handling from here

run()
