"""The record options every ``sbib`` command that takes a record shares.

:func:`add_record_options` adds them to a command's parser (``sbib run``, ``sbib compare``,
``sbib records show``) and :func:`record_kwargs` turns the parsed values into the keyword
arguments of :func:`records.resolve.resolve_record`, so that a single-column file in g reads
the same way everywhere::

    --orientation FN-x|FP-x|FP-y|FN-y     (compare: --orientations, a comma list or 'both')
    --records-dir DIR                     directory of the benchmark record files
    --format auto|benchmark|at2|single|csv
    --dt S                                time step of a record file [s] (single-column files)
    --units g|m/s2|cm/s2|gal|mm/s2        units of a record file's values
    --baseline-correct                    polynomial baseline correction
"""

from __future__ import annotations

import argparse
from typing import Any
from benchmark.foundation.errors import InputError
from records.catalogue import canonical_orientation
from records.catalogue import ORIENTATION_HELP
from records.readers import FORMATS

__all__ = ["add_record_options", "record_kwargs", "orientation_name"]


def orientation_name(text: str) -> str:
    """``argparse`` type: an orientation name, returned canonical (``FP-y`` → ``FN-x``, ``FN-y`` → ``FP-x``).

    Parameters
    ----------
    text : str
        Orientation as typed on the command line (``FN-x``, ``FP-x``, ``FP-y``, ``FN-y``, any case).
    """

    try:
        return canonical_orientation(text)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_record_options(parser: argparse.ArgumentParser, orientation: bool = True, several: bool = False) -> None:
    """Add the shared record options to ``parser``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A command's parser.
    orientation : bool
        Also add ``--orientation`` (a command with ``--orientations`` adds its own).
    several : bool
        The command takes several records (the help texts say "record files").
    """

    files = "record files" if several else "a record file"
    if orientation:
        parser.add_argument("--orientation", default="FN-x", type=orientation_name, metavar="FN-x|FP-x|FP-y|FN-y",
                            help=ORIENTATION_HELP + " (default FN-x)")
    parser.add_argument("--records-dir", default=None, metavar="DIR",
                        help="directory of the benchmark record files (default: SBIB_RECORDS_DIR, "
                             "then <shared>/records/raw/FDZ)")
    parser.add_argument("--format", default="auto", choices=FORMATS,
                        help=f"format of {files} (default: auto)")
    parser.add_argument("--dt", type=float, default=None, metavar="S",  # the readers check it (names the file)
                        help=f"time step of {files} [s]: required for single-column files, checked "
                             "against the others")
    parser.add_argument("--units", default=None, metavar="U",
                        help=f"units of the values in {files}: g, m/s2, cm/s2 (gal), mm/s2 (default: what "
                             "the file says, else per format: benchmark cm/s2, single-column g, CSV m/s2)")
    parser.add_argument("--baseline-correct", action="store_true",
                        help="apply the polynomial baseline correction (off by default, as the benchmark "
                             "distributes its records)")


def record_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of :func:`records.resolve.resolve_record` from parsed options
    (``orientation`` excluded).

    Parameters
    ----------
    args : argparse.Namespace
        Options parsed by a parser that :func:`records.options.add_record_options` filled.
    """
    return {"records_dir": getattr(args, "records_dir", None),
            "baseline_correct": bool(getattr(args, "baseline_correct", False)),
            "format": getattr(args, "format", "auto") or "auto",
            "dt": getattr(args, "dt", None),
            "units": getattr(args, "units", None)}
