"""The ``sbib`` command line: a thin layer that parses, calls the Python API and prints.

Each command lives in the package it serves (``records/cli.py``, ``damper/cli.py``, ...):
such a module defines ``register(subparsers)``, which adds its sub-parsers and sets
``func`` (a callable taking the parsed namespace and returning an exit status) as the
default. This module only gathers them and turns the project's errors into one-line
messages with a non-zero exit status.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from typing import Sequence

from benchmark import __version__
from benchmark.errors import InputError, NumericalError, SbibError

__all__ = ["main", "build_parser", "COMMAND_MODULES"]

# Modules that contribute sub-commands, in the order they appear in ``sbib --help``.
COMMAND_MODULES: tuple[str, ...] = (
    "benchmark.cli_study",
    "records.cli",
    "benchmark.cli_run",
    "benchmark.cli_ensemble",
    "benchmark.cli_bench",
    "controllers.cli",
    "damper.cli",
    "damper.cli_diagnose",
)

EXIT_INPUT_ERROR = 2
EXIT_NUMERICAL_ERROR = 3
EXIT_INTERRUPTED = 130


def build_parser() -> argparse.ArgumentParser:
    """Return the ``sbib`` argument parser with every registered sub-command."""
    parser = argparse.ArgumentParser(
        prog="sbib",
        description="Smart base-isolated benchmark building with MR dampers: simulation, "
                    "semi-active control and damper identification.")
    parser.add_argument("--version", action="version", version=f"sbib {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``sbib`` command line and return its exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_INPUT_ERROR
    try:
        return int(args.func(args) or 0)
    except NumericalError as exc:
        print(f"sbib: numerical failure: {exc}", file=sys.stderr)
        return EXIT_NUMERICAL_ERROR
    except (InputError, SbibError) as exc:
        print(f"sbib: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    except KeyboardInterrupt:
        print("sbib: interrupted; finished result files are complete, unfinished ones were removed",
              file=sys.stderr)
        return EXIT_INTERRUPTED
