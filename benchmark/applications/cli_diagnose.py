"""``sbib diagnose``: close the loop between a damper model and measured data.

::

    sbib diagnose --data FILE [FILE ...] [--model normalized|extended|spencer]
                  [--holdout FRACTION] [--validate FILE ...] [--coarse-samples N]
                  [--time-budget SECONDS] [--keep-flagged] [--out DIR] [--json]

Every file is screened when read (:mod:`damper.io.screening`); the flagged samples count neither
in the fit nor in the errors (``--keep-flagged`` keeps them) and the findings are printed, and
listed under ``screening`` in the JSON.

Fits the base model, traces its held-out residual, adds library effects while they pay (held-out
BIC), and reports the held-out relative RMS force error before and after
(:func:`damper.diagnosis.diagnose`); ``--validate`` scores both models on other recordings of
the same device as well (never fitted: the JSON's ``validation``). Data files: the damper CSV format
(:mod:`damper.io.data`; ``time, displacement, force[, velocity][, voltage|current]``, SI), the
UTFSM preprocessed files (``<amp>mm<freq>Hz<current>A.txt``) or Dyke's records
(:mod:`damper.io.dyke`, converted to SI when read). ``--json`` prints
``{"model", "error_before", "error_after", "effects": [{"name", "parameters",
"error_after_adding"}], "unexplained", "residual_trace": {variable: share}, ...}``; ``--out DIR``
writes ``report.md``, ``diagnosis.json``, the plots and the two model files ``base_model.json``
and ``final_model.json`` (:mod:`damper.io.model_file`: parameters with their voltage or current
laws, effects, held-out errors, provenance), which ``sbib run --damper`` and ``sbib compare
--dampers`` read.
"""

from __future__ import annotations

import argparse
import json
import sys
import textwrap
from pathlib import Path

from benchmark.foundation.errors import InputError
from benchmark.foundation.arguments import fraction
from benchmark.foundation.atomic import output_dir
from damper.io.reader import read_usable, unique_names
from damper.io.screening import screening_lines, screening_summary
from damper.diagnosis.effects import EFFECTS, effect_names
from damper.diagnosis import diagnose
from damper.diagnosis.interference import interference_lines
from damper.diagnosis.coverage import coverage_lines
from damper.diagnosis.levels import level_lines
from damper.diagnosis.loop import force_zero_text, tare_matters
from damper.diagnosis.dataset import DEFAULT_HOLDOUT
from damper.diagnosis.report import format_parameters, input_word, residual_not_white, write_report
from damper.diagnosis.coarse import DEFAULT_COARSE_SAMPLES
from benchmark.applications.model_files import write_diagnosis_models

__all__ = ["register", "run"]


def _paragraphs(text: str, width: int = 78) -> str:
    """Wrap each line of ``text`` to ``width``; a line starting with a tab is an indented item."""
    out = []
    for line in text.split("\n"):
        indent = "  " if line.startswith("\t") else ""
        out.append(textwrap.fill(line.strip(), width, initial_indent=indent, subsequent_indent=indent * 2,
                                 break_on_hyphens=False) if line.strip() else "")
    return "\n".join(out)


def register(subparsers) -> None:
    """Add the ``diagnose`` sub-command.

    Parameters
    ----------
    subparsers
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    p = subparsers.add_parser(
        "diagnose", help="residual loop: find the effects a damper model lacks in test data",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=_paragraphs(
            "Fit a Bouc-Wen model to damper tests (force, displacement, voltage or current), look at "
            "what it gets wrong and add the missing physical effects one at a time.\n\n"
            "The last part of each test (--holdout) is held out: not used in the fit, only to judge "
            "it. The error left there (the held-out residual) is traced against displacement, "
            "velocity, acceleration, time and the coil input; each variable it depends on points to "
            "candidate effects, each an extra force term:\n"
            + "".join(f"\t{name}: {EFFECTS[name].description}\n" for name in effect_names())
            + "An effect is kept when it lowers the held-out Bayesian information criterion (BIC: "
            "the held-out error, penalised by the number of parameters), i.e. when it pays for "
            "its extra parameters; structure no effect explains is reported as unexplained.\n\n"
            "Writes (with --out DIR): report.md (the findings, parameters with units), "
            "diagnosis.json (the same, machine-readable) and PNG plots of the residual, the loops "
            "and the forces. Prints the held-out relative RMS force error before and after.\n\n"
            "Example:\n\tsbib diagnose --data tests/*Hz1A.txt --model normalized --out out/diagnose-1A"))
    p.add_argument("--data", nargs="+", required=True, metavar="FILE",
                   help="test files: damper CSV (units in the header, converted to SI), UTFSM <amp>mm<freq>Hz<current>A.txt, "
                        "a Dyke record, or a raw UTFSM logger export: ME*.txt (one test per coil current) or one "
                        "current named at the end of its name (15Hz1A.txt)")
    p.add_argument("--model", choices=("normalized", "extended", "spencer", "auto"), default="normalized",
                   help="base model (default: normalized; auto = spencer when the coil input changes "
                        "within a test, as in a random-voltage recording, else normalized)")
    p.add_argument("--holdout", type=fraction, default=None, metavar="FRACTION",
                   help="fraction of each test, at its end, held out: not used in the fit, only to "
                        "judge it (0-1, default 0.25)")
    p.add_argument("--validate", nargs="+", metavar="FILE",
                   help="other recordings of the same device: both models are scored on all of "
                        "them too (never fitted)")
    p.add_argument("--time-budget", type=float, default=None, metavar="SECONDS",
                   help="no new round of the effect selection after this many seconds (the run "
                        "ends cleanly and says so)")
    p.add_argument("--effects", nargs="+", choices=effect_names(), metavar="EFFECT",
                   help="restrict the candidates to these effects (default: the whole library)")
    p.add_argument("--coarse-samples", type=int, default=None, metavar="N",
                   help="speed-up: fit on the tests thinned to about N samples in all (all tests "
                        "together; a count, no unit), then evaluate on every sample (default "
                        f"{DEFAULT_COARSE_SAMPLES}; 0: fit every sample; e.g. --coarse-samples 20000 "
                        "for a closer fit of long tests)")
    p.add_argument("--keep-flagged", action="store_true",
                   help="keep the samples the screening flags (stuck or clipped channels, frozen "
                        "displacement, idle spans, ...) in the fit and the errors; the findings are "
                        "still reported")
    p.add_argument("--out", metavar="DIR", type=output_dir, help="write report.md, diagnosis.json, plots, base_model.json and final_model.json here")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress messages on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    """Execute ``sbib diagnose`` with parsed ``args``; return the exit status.

    Parameters
    ----------
    args
        Parsed command-line options of the sub-command.
    """

    keep = bool(getattr(args, "keep_flagged", False))
    # the options first (a bad one costs no file reading), then the files
    coarse = getattr(args, "coarse_samples", None)
    if coarse is not None and coarse < 0:
        raise InputError(f"--coarse-samples: expected 0 or a number of samples >= 100, got {coarse}")
    coarse = DEFAULT_COARSE_SAMPLES if coarse is None else (None if coarse == 0 else coarse)
    budget = getattr(args, "time_budget", None)
    if budget is not None and not budget > 0:
        raise InputError(f"--time-budget: expected a number of seconds > 0, got {budget:g}")
    # a file too short to fit, or one the screening empties, stops here in one line naming it
    # a raw UTFSM logger export is one test per coil current (damper.io.reader.read_tests)
    tests = read_usable(args.data, keep)
    validate = read_usable(args.validate, keep) if args.validate else None
    # one name per recording (two files with one stem would share an entry of the report)
    named = unique_names([*tests, *(validate or [])])
    validate = [t for _, t in named[len(tests):]] if validate is not None else None
    tests = [t for _, t in named[:len(tests)]]
    screened_tests = tests + (validate or [])
    screening = screening_summary(screened_tests, keep)
    progress = None if args.quiet else (lambda msg: print(msg, file=sys.stderr, flush=True))
    holdout = args.holdout if args.holdout is not None else DEFAULT_HOLDOUT
    result = diagnose(tests, model=args.model, holdout=holdout, cross_validate=validate,
                      candidates=args.effects, progress=progress, coarse_samples=coarse,
                      time_budget=budget)
    doc = {**result.to_json(), "screening": screening}
    if args.out:
        # the screening (the reader's) goes into report.md and diagnosis.json
        paths = write_report(result, args.out, tests=screened_tests, keep_flagged=keep)
        models = write_diagnosis_models(result, args.out, args.data)  # damper.io.model_file format
        if progress:
            progress(f"report written to {paths['report']}; models: {models['base_model']}, "
                     f"{models['final_model']}")
    if args.json:
        print(json.dumps(doc, indent=2))
    else:
        for line in screening_lines(screened_tests, keep):
            print(line)
        if not getattr(result.data, "input_recorded", True):
            print("coil input: no voltage or current column in the files: taken as 0 V")
        print(f"model: {result.model_kind}"
              + (f" (the {result.data.input_name} changes within the tests: --model spencer, or auto, starts "
                 "from Spencer et al.'s model with its field lag, the standard model of such data)"
                 if result.model_kind != "spencer" and result.data.input_varies_within_tests else ""))
        print(f"held-out relative RMS error: {result.error_before:.4f} -> {result.error_after:.4f}")
        for name, where in result.base_at_bounds.items():
            side, bound = where.split()
            print(f"base {name} = {getattr(result.final_model.base, name):.4g}: at the search's {side} bound "
                  f"{bound}, not identified by the data")
        # the final model's values, as in the JSON (a step's own values precede the final joint refit)
        final = {e.name: e.parameters for e in result.final_model.effects}
        for step in result.selection.steps:
            params = format_parameters(step.name, final.get(step.name, step.parameters))
            print(f"  + {step.name} ({params}): {step.error_before:.4f} -> {step.error_after:.4f}")
        if not result.selection.steps:
            print("  no library effect paid on the held-out data")
        if result.validation is not None:
            v = result.validation
            print(f"validation on {', '.join(v['tests'])}: relative RMS error "
                  f"{v['error_before']:.4f} -> {v['error_after']:.4f}")
            if len(v["tests"]) > 1:  # a pooled figure hides which recording the model misses
                for name, e in v["errors_by_test"].items():
                    print(f"  {name}: {e['before']:.4f} -> {e['after']:.4f}")
            if tare_matters(v):
                print(f"  with each recording's force zero re-estimated on it (a load cell's tare): "
                      f"{v['error_before_force_zero']:.4f} -> {v['error_after_force_zero']:.4f} (zeros "
                      + force_zero_text(v) + ")")
            for name, c in (v.get("input_clipped") or {}).items():
                print(f"  {name}: {c['samples']} samples of the coil input outside the fitted tests' range "
                      f"(by up to {c['largest_excess']:.3g}), held at its edge")
            for name, c in (v.get("input_beyond_levels") or {}).items():
                print(f"  {name}: {c['samples']} scored samples ({100 * c['share']:.0f} %) of the "
                      f"{result.data.input_name} outside the fitted levels ({c['levels'][0]:.4g}-"
                      f"{c['levels'][1]:.4g} {result.data.input_unit}): the laws extrapolate there")
            for text, _ in coverage_lines(v.get("coverage")):
                print(f"  {text}")
        al = getattr(result, "alignment", None)
        if al is not None and al["finding"]:
            print(f"the measured force is {1e3 * al['shift_s']:+.3g} ms ({al['shift_samples']:+.1f} samples) off "
                  f"the final model (error {al['error_unshifted']:.4f} -> {al['error_shifted']:.4f} if shifted): "
                  "check the force and motion channels' timing; nothing was shifted")
        for text, _ in interference_lines(getattr(result, "interference", None)):
            print(text)
        for text, _ in level_lines(getattr(result, "force_levels", None)):
            print(text)
        if result.settings.get("dropped_at_full_rate"):
            print(f"left out: {', '.join(result.settings['dropped_at_full_rate'])} (chosen on the coarse pass, "
                  "no lower held-out error at every sample)")
        if result.settings.get("stopped_by_budget"):
            print(f"stopped by the time budget ({result.settings['time_budget']:g} s): the model "
                  "so far is reported")
        if result.unexplained:
            print("unexplained structure in: " + ", ".join(
                f"{input_word(v, result.data.input_name)} (share {s:.2f}, {100 * lv:.1f} % of force RMS)"
                for v, s, lv in result.unexplained_in))
        else:
            print("no structure left that the trace's variables explain" + residual_not_white(result))
    return 0
