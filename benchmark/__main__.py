"""``python -m benchmark`` is the ``sbib`` command."""

from benchmark.cli import main

raise SystemExit(main())
