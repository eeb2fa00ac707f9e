"""``sbib diagnose``: close the loop between a damper model and measured data.

::

    sbib diagnose --data FILE [FILE ...] [--model normalized|extended]
                  [--holdout FRACTION | --validate FILE ...] [--coarse-samples N]
                  [--out DIR] [--json]

Fits the base model, traces its held-out residual, adds library effects while they pay (held-out
BIC), and reports the held-out relative RMS force error before and after
(:func:`damper.diagnosis.diagnose`). Data files: the damper CSV format
(:mod:`damper.data`; ``time, displacement, force[, velocity][, voltage|current]``, SI), the
UTFSM preprocessed files (``<amp>mm<freq>Hz<current>A.txt``) or Dyke's records
(:mod:`damper.dyke_data`, converted to SI when read). ``--json`` prints
``{"model", "error_before", "error_after", "effects": [{"name", "parameters",
"error_after_adding"}], "unexplained", "residual_trace": {variable: share}, ...}``; ``--out DIR``
writes ``report.md``, ``diagnosis.json``, the plots and the two model files ``base_model.json``
and ``final_model.json`` (:mod:`damper.model_file`: parameters with their voltage or current
laws, effects, held-out errors, provenance), which ``sbib run --damper`` and ``sbib compare
--dampers`` read.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from benchmark.foundation.errors import InputError
from damper.data import parse_utfsm_name, read_csv, read_utfsm
from damper.effects import EFFECT_NAMES
from damper.diagnosis import diagnose
from damper.diagnosis.dataset import DEFAULT_HOLDOUT
from damper.diagnosis.report import write_report
from damper.dyke_data import is_dyke_file, read_dyke
from damper.diagnosis.coarse import DEFAULT_COARSE_SAMPLES
from benchmark.applications.model_files import write_diagnosis_models

__all__ = ["register", "run", "read_test_file"]


def read_test_file(path: str):
    """Read a damper test: UTFSM preprocessed ``.txt`` (by its name pattern), a Dyke record (CSV
    with columns t, D [cm], Y [V], V [cm/s], F [N]; :mod:`damper.dyke_data`) or damper CSV."""
    p = Path(path)
    if p.suffix.lower() == ".txt":
        try:
            parse_utfsm_name(p)
        except InputError:
            pass
        else:
            return read_utfsm(p)
    if p.is_file() and is_dyke_file(p):
        return read_dyke(p)
    return read_csv(p)


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a fraction between 0 and 1, got {text!r}") from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"expected a fraction between 0 and 1, got {text!r}")
    return value


def register(subparsers) -> None:
    """Add the ``diagnose`` sub-command."""
    p = subparsers.add_parser(
        "diagnose", help="residual loop: find the effects a damper model lacks in test data",
        description="Fit a Bouc-Wen base model to damper tests, trace the held-out residual, add "
                    "effects from the library (" + ", ".join(EFFECT_NAMES) + ") while they pay "
                    "(held-out BIC) and report the error before and after.")
    p.add_argument("--data", nargs="+", required=True, metavar="FILE",
                   help="test files: damper CSV (SI) or UTFSM <amp>mm<freq>Hz<current>A.txt")
    p.add_argument("--model", choices=("normalized", "extended"), default="normalized",
                   help="base model (default: normalized)")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--holdout", type=_fraction, default=None, metavar="FRACTION",
                       help="fraction of each test, at its end, held out (default 0.25)")
    group.add_argument("--validate", nargs="+", metavar="FILE",
                       help="separate test files for the held-out errors")
    p.add_argument("--effects", nargs="+", choices=EFFECT_NAMES, metavar="EFFECT",
                   help="restrict the candidates to these effects (default: the whole library)")
    p.add_argument("--coarse-samples", type=int, default=None, metavar="N",
                   help="fit on the tests decimated to about N samples, then evaluate on all "
                        "(default 6000; 0: fit every sample)")
    p.add_argument("--out", metavar="DIR", help="write report.md, diagnosis.json, plots, base_model.json and final_model.json here")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress messages on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    """Execute ``sbib diagnose`` with parsed ``args``; return the exit status."""

    tests = [read_test_file(f) for f in args.data]
    validate = [read_test_file(f) for f in args.validate] if args.validate else None
    progress = None if args.quiet else (lambda msg: print(msg, file=sys.stderr, flush=True))
    holdout = args.holdout if args.holdout is not None else DEFAULT_HOLDOUT
    coarse = getattr(args, "coarse_samples", None)
    if coarse is not None and coarse < 0:
        raise InputError(f"--coarse-samples: expected 0 or a number of samples >= 100, got {coarse}")
    coarse = DEFAULT_COARSE_SAMPLES if coarse is None else (None if coarse == 0 else coarse)
    result = diagnose(tests, model=args.model, holdout=holdout, validate=validate,
                      candidates=args.effects, progress=progress, coarse_samples=coarse)
    if args.out:
        paths = write_report(result, args.out)
        models = write_diagnosis_models(result, args.out, args.data)  # damper.model_file format
        if progress:
            progress(f"report written to {paths['report']}; models: {models['base_model']}, "
                     f"{models['final_model']}")
    if args.json:
        print(json.dumps(result.to_json(), indent=2))
    else:
        print(f"model: {result.model_kind}")
        print(f"held-out relative RMS error: {result.error_before:.4f} -> {result.error_after:.4f}")
        for step in result.selection.steps:
            params = ", ".join(f"{k}={v:.4g}" for k, v in step.parameters.items())
            print(f"  + {step.name} ({params}): {step.error_before:.4f} -> {step.error_after:.4f}")
        if not result.selection.steps:
            print("  no library effect paid on the held-out data")
        if result.unexplained:
            print("unexplained structure in: " + ", ".join(
                f"{v} (share {s:.2f}, {100 * lv:.1f} % of force RMS)" for v, s, lv in result.unexplained_in))
        else:
            print("no unexplained structure left")
    return 0
