"""``python -m benchmark`` is the ``sbib`` command."""

from benchmark.applications.cli import main

raise SystemExit(main())
