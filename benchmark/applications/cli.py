"""The ``sbib`` command line: a thin layer that parses, calls the Python API and prints.

Each command lives in the package it serves (``benchmark/applications/cli_records.py``, ``benchmark/applications/cli_damper.py``, ...):
such a module defines ``register(subparsers)``, which adds its sub-parsers and sets
``func`` (a callable taking the parsed namespace and returning an exit status) as the
default. This module only gathers them and turns the project's errors into one-line
messages with a non-zero exit status.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import signal
import sys
import textwrap

# One BLAS thread per process, set before numpy is imported (an explicit setting wins): the
# simulator's dense products are small (54 states, 6000 samples), so OpenBLAS's extra threads only
# spin against the kernels and the suite's other workers. On the 2-core machine of the README's
# performance section, a 30-s linear run took 3x longer with the default threads.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from typing import Sequence

from benchmark import __version__
from benchmark.foundation.errors import InputError, NumericalError, SbibError
from benchmark.foundation.kernel_cache import ensure_fresh_once, stepping_kernel_cached
from benchmark.foundation.provenance import record_command
from benchmark.foundation.paths import structure_file
from benchmark.foundation.pools import stop_children
from benchmark.simulator.structure import load_superstructure

__all__ = ["main", "run", "build_parser", "COMMAND_MODULES"]

# Modules that contribute sub-commands, in the order they appear in ``sbib --help``.
COMMAND_MODULES: tuple[str, ...] = (
    "benchmark.applications.cli_study",
    "benchmark.applications.cli_records",
    "benchmark.applications.cli_run",
    "benchmark.applications.cli_ensemble",
    "benchmark.applications.cli_bench",
    "benchmark.applications.cli_controllers",
    "benchmark.applications.cli_damper",
    "benchmark.applications.cli_diagnose",
    "benchmark.applications.cli_identify",
    "benchmark.applications.cli_hysteresis",
)

EXIT_INPUT_ERROR = 2
EXIT_NUMERICAL_ERROR = 3
EXIT_INTERRUPTED = 130


class _WholeNames(argparse.HelpFormatter):
    """Wrap option help between words only: ``clipped-optimal`` stays one name on one line."""

    def _split_lines(self, text, width):
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False) or [""]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one ``sbib: error: ...`` line (exit status 2),
    like every other input error, instead of the usage block followed by the message.
    Sub-command parsers inherit the class (``add_subparsers`` uses the parent's type)."""

    def error(self, message: str):  # type: ignore[override]
        where = "" if self.prog == "sbib" else f"{self.prog}: "
        self.exit(EXIT_INPUT_ERROR, f"sbib: error: {where}{message} (see '{self.prog} --help')\n")

    def __init__(self, *args, **kwargs) -> None:
        kind = kwargs.get("formatter_class", argparse.HelpFormatter)
        kwargs["formatter_class"] = type(f"Whole{kind.__name__}", (_WholeNames, kind), {})
        super().__init__(*args, **kwargs)

    def format_help(self) -> str:
        # Descriptions come from module docstrings: show their reST as plain text in a terminal.
        return plain_text(super().format_help())

    def parse_known_args(self, args=None, namespace=None):  # type: ignore[override]
        namespace, extras = super().parse_known_args(args, namespace)
        # Python 3.11's argparse turns "--option=--" into an empty list instead of an error.
        for action in self._actions:
            if (action.nargs is None and action.type is not None and action.option_strings
                    and isinstance(getattr(namespace, action.dest, None), list)
                    and not isinstance(action, argparse._AppendAction)):
                self.error(f"argument {'/'.join(action.option_strings)}: expected one value")
        return namespace, extras


_ROLE = re.compile(r":(?:mod|func|class|meth|attr|data|obj|exc|ref|doc|py:\w+):`~?([^`]*)`")


def plain_text(text: str) -> str:
    """``text`` with its reST inline markup shown as plain text (for ``--help``).

    ``:func:`~a.b``` -> ``b``, ````x```` -> ``x``, a trailing ``::`` (literal block) -> ``:``.
    """
    text = _ROLE.sub(lambda m: m.group(1).split(" <")[0].rsplit(".", 1)[-1] if m.group(0).count("~")
                     else m.group(1).split(" <")[0], text)
    text = re.sub(r"``([^`]*)``", r"\1", text)
    return re.sub(r"(\S)::[ \t]*$", r"\1:", text, flags=re.MULTILINE)


#: Commands that run the building (and so its stepping kernel).
_BUILDING_COMMANDS = frozenset({"run", "compare", "ensemble", "study", "identify", "bench"})


def build_parser() -> argparse.ArgumentParser:
    """Return the ``sbib`` argument parser with every registered sub-command."""
    parser = _Parser(
        prog="sbib",
        description="Smart base-isolated benchmark building with MR dampers: simulation, "
                    "semi-active control and damper identification.")
    parser.add_argument("--version", action="version", version=f"sbib {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    for command in _STRUCTURE_COMMANDS:
        subparsers.choices[command].add_argument(
            "--structure", default=None, metavar="FILE.json",
            help="a variant of the benchmark's structure file (the fields of shared/benchmark/"
                 "structure.json: masses, modes, damping ratio, bearing plan; n_floors, default 8); the named "
                 "isolation layers carry its weight on its bearings. Same as SBIB_STRUCTURE "
                 "(default: shared/benchmark/structure.json)")
    return parser


#: Commands that take ``--structure`` (it reaches their worker processes through SBIB_STRUCTURE).
_STRUCTURE_COMMANDS = ("run", "compare", "ensemble")


def _use_structure(path: str) -> None:
    """Check ``--structure`` now (one-line error) and hand it to this process and its workers."""
    resolved = structure_file(path).resolve()
    load_superstructure(resolved)  # a malformed file is refused before anything runs
    os.environ["SBIB_STRUCTURE"] = str(resolved)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``sbib`` command line and return its exit status.

    Ctrl-C (SIGINT) anywhere, from the first import on, ends in one line on stderr and exit
    status 130 (:func:`_interrupted`); further Ctrl-C after the first are ignored.

    Parameters
    ----------
    argv : Sequence[str] | None, optional
        Command-line arguments without the program name; None: ``sys.argv[1:]``.
    """
    _terminate_as_interrupt()
    try:
        ensure_fresh_once()  # before any kernel is loaded from numba's cache (kernel_cache)
        parser = build_parser()
        args = parser.parse_args(argv)
        record_command(["sbib", *(sys.argv[1:] if argv is None else argv)])  # the result files' provenance
        if not getattr(args, "func", None):
            parser.print_help()
            return EXIT_INPUT_ERROR
        if args.command in _BUILDING_COMMANDS and not stepping_kernel_cached():
            # a fresh checkout, or kernels edited since: minutes of silence otherwise
            print("sbib: compiling the simulation kernels once (a few minutes on 2 cores; `make run` and "
                  "`sbib warm-up` do it at set-up; later runs load them in about 2 s)", file=sys.stderr, flush=True)
        return _dispatch(args)
    except KeyboardInterrupt:
        return _interrupted()


def _dispatch(args: argparse.Namespace) -> int:
    try:
        if getattr(args, "structure", None):
            _use_structure(args.structure)
        return int(args.func(args) or 0)
    except NumericalError as exc:
        print(f"sbib: numerical failure: {exc}", file=sys.stderr)
        return EXIT_NUMERICAL_ERROR
    except (InputError, SbibError) as exc:
        print(f"sbib: error: {exc}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    except UnicodeDecodeError as exc:  # a reader that missed benchmark.foundation.textfile: still one line
        print(f"sbib: error: an input file is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset "
              f"{exc.start}); expected a UTF-8 text file", file=sys.stderr)
        return EXIT_INPUT_ERROR
    except BrokenPipeError:  # output piped into `head` and the like: stop quietly
        _silence_stdout()
        return 0
    except OSError as exc:  # an output path that cannot be created or written: name it, not errno
        print(f"sbib: error: {_os_error_line(exc)}", file=sys.stderr)
        return EXIT_INPUT_ERROR


def _os_error_line(exc: OSError) -> str:
    """``path: reason`` for an OSError (the destination, not an atomic writer's temporary name)."""
    path = exc.filename2 if exc.filename2 is not None else exc.filename
    reason = exc.strerror or str(exc)
    if path is None:
        return reason
    return f"{path}: {reason.lower() if reason[:1].isupper() and reason[1:2].islower() else reason}"


def _terminate_as_interrupt() -> None:
    """SIGTERM (``kill``, a batch scheduler's time limit) ends a command as Ctrl-C does: the same
    deferrals, finished files written (an ensemble's ``.h5`` from its journal), workers stopped,
    status 130. Before, an ensemble ended by SIGTERM left its file behind its journal."""
    def forward(signum, frame):
        os.kill(os.getpid(), signal.SIGINT)

    try:
        signal.signal(signal.SIGTERM, forward)
    except ValueError:  # not the main thread (main() called from a thread): leave it as it is
        pass


def _interrupted() -> int:
    """Ctrl-C: ignore any further one, end the worker processes still alive, say so, return 130.

    The pools stop their own workers on the way up (:class:`benchmark.foundation.pools.WorkerPool`);
    this is the last resort for any other child (a forked figure drawer, a pool not stopped).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    stop_children()
    try:
        print("sbib: interrupted; finished result files are complete, unfinished ones were removed",
              file=sys.stderr, flush=True)
    except (OSError, ValueError):  # stderr closed
        pass
    return EXIT_INTERRUPTED


def run() -> None:
    """Entry point of the ``sbib`` script (and ``python -m benchmark``): :func:`main`, then exit.

    After an interrupt the process ends at once (``os._exit`` once the output is flushed): the
    result files are already complete or removed, and the interpreter's exit-time joins of
    threads that a Ctrl-C cut short (process-pool manager threads) could otherwise block it.
    """
    status = main()
    if status == EXIT_INTERRUPTED:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(status)
    sys.exit(status)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush raises no second error."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout replaced by an object without a descriptor (tests)
        pass
