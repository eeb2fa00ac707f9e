"""``sbib identify``: the identification study on the virtual damper, or identification of measured files.

* ``sbib identify [--out DIR] [--json]``: :func:`benchmark.applications.identification_study.run_identify_study`
  on the virtual benchmark damper (voltage grid, voltage laws, field lag, validation in all
  earthquake runs, HDF5, figures).
* ``sbib identify --data FILE [FILE ...] [--model normalized|extended] [--keep-flagged] [--json]``:
  :func:`damper.identification.measured.identify_files` (each file read and screened once;
  parameters, uncertainty, fit error per file, held-out check per level, ONE model per level
  over all its tests with each test's error under it, parameters at a bound and warnings
  flagged in the text output too, one error figure per file in ``--out``) and one model file per
  model form in ``--out`` (``normalized_model.json``, ``extended_model.json``; :mod:`damper.io.model_file`).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from benchmark.foundation.errors import InputError
from benchmark.foundation.arguments import positive_int
from benchmark.applications.identification_study import run_identify_study
from records.options import orientation_name

from benchmark.foundation.display_units import format_si
from benchmark.foundation.progress import progress_bar
from benchmark.foundation.atomic import output_dir
from damper.identification.measured import identify_files
from damper.io.reader import read_usable
from damper.io.screening import Finding, finding_lines, units_line
from benchmark.applications.model_files import write_identified_models

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``identify`` sub-command.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    p = subparsers.add_parser(
        "identify", help="identify normalized/extended Bouc-Wen MR damper models (seed paper study)",
        description="Without --data: identify the virtual benchmark damper over 0-1 V through the "
                    "virtual laboratory, fit the voltage laws and validate inside every earthquake "
                    "run. With --data: identify measured constant-voltage/current tests.")
    p.add_argument("--out", default=None, type=output_dir,
                   help="output directory (default: results/identify, or results/identify-data with --data)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--data", nargs="+", metavar="FILE", default=None,
                   help="measured test files (UTFSM <amp>mm<freq>Hz<cur>A.txt or CSV)")
    p.add_argument("--model", choices=("normalized", "extended"), default=None,
                   help="with --data: identify only this model (default: both)")
    p.add_argument("--keep-flagged", action="store_true",
                   help="with --data: keep the samples the screening flags (stuck or clipped "
                        "channels, idle spans, ...) in the fits and errors; the findings are still "
                        "reported")
    p.add_argument("--bootstrap", type=int, default=10,
                   help="with --data: cycle-bootstrap refits per file (default 10)")
    p.add_argument("--records", default=None,
                   help="comma list of benchmark records for the validation (default: all seven)")
    p.add_argument("--orientations", default=None, type=_orientation_list,
                   help="comma list of FN-x, FP-x (default: both); the seed paper's FP-y (= FN-x) and "
                        "FN-y (= FP-x) are accepted")
    p.add_argument("--controller", default="clipped-optimal",
                   help="semi-active controller of the validation runs (default: clipped-optimal)")
    p.add_argument("--records-dir", default=None, help="directory of the benchmark record files")
    p.add_argument("--synthetic", action="store_true", help="validate on synthetic benchmark-like records")
    p.add_argument("--no-validation", action="store_true", help="skip the earthquake validation")
    p.add_argument("--no-plots", action="store_true", help="write no figures")
    p.add_argument("--kappa-x", default="large-loop", metavar="MODE",
                   help="extended model's kappa_x: large-loop (seed step a: read once from the ±0.4 m "
                        "0 V loop, held fixed; default), joint (one value refined over the whole grid), "
                        "per-voltage (free at each voltage), or a number in N/m held fixed")
    p.add_argument("--no-free-kappa-x", action="store_true",
                   help="do not identify/validate the per-voltage-kappa_x variant for comparison")
    p.add_argument("--full-histories", action="store_true",
                   help="keep every device's histories in double precision in identification.h5 "
                        "(about 120 MB for the 14 runs; default: single precision, one device per "
                        "run, about 8 MB)")
    p.add_argument("--no-ceiling", action="store_true",
                   help="skip the structural ceiling (the best each model form reaches fitted to "
                        "each run's own damper motion at 0 V and 1 V)")
    p.add_argument("--no-closed-loop", action="store_true",
                   help="skip the closed loop (laboratory campaign with changing voltage, residual loop, "
                        "augmented models validated in the building, the seed's claim)")
    p.add_argument("--campaign-scale", type=float, default=0.5, metavar="F",
                   help="duration factor of the closed loop's laboratory tests (default 0.5: 30 s of "
                        "training and 22 s of held-out tests)")
    p.add_argument("--jobs", type=positive_int, default=None,
                   help="worker processes (default: all cores; 1: no pool)")
    p.set_defaults(func=_run)


def _orientation_list(value: str) -> str:
    """``argparse`` type: a comma list of orientations, made canonical (``FP-y`` → ``FN-x``)."""

    return ",".join(orientation_name(o.strip()) for o in value.split(",") if o.strip())


def _split(value: str | None) -> list[str] | None:
    return [s.strip() for s in value.split(",") if s.strip()] if value else None


def _print_tree(obj, indent: str = "") -> None:
    """Nested dicts/lists as indented ``key: value`` lines (JSON is for ``--json`` only)."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            if isinstance(value, (dict, list)) and value:
                print(f"{indent}{key}:")
                _print_tree(value, indent + "  ")
            else:
                print(f"{indent}{key}: {value:.4g}" if isinstance(value, float) else f"{indent}{key}: {value}")
    elif isinstance(obj, list):
        for k, value in enumerate(obj):
            if isinstance(value, (dict, list)):
                print(f"{indent}- [{k}]")
                _print_tree(value, indent + "  ")
            else:
                print(f"{indent}- {value}")
    else:
        print(f"{indent}{obj}")


def _run_data(args: argparse.Namespace) -> int:
    """``sbib identify --data``: progress on stderr; a table with units, or JSON with ``--json``."""

    models = (args.model,) if args.model else ("normalized", "extended")
    if args.bootstrap < 0 or args.bootstrap == 1:
        # one refit has no spread (its standard deviation printed numpy's warnings per fit)
        raise InputError(f"--bootstrap {args.bootstrap}: expected 0 (none) or at least 2 refits")
    out = args.out or "results/identify-data"
    # read (and screen) every file once, before any fit: a bad one stops the command with its
    # one-line error before any progress line is written
    # the fit needs usable samples: a file too short, or one the screening empties, stops here in one line
    # (a raw UTFSM logger export is one test per coil current: damper.io.reader.read_tests)
    tests = [test for _, test in read_usable(args.data, args.keep_flagged)]
    existed = Path(out).exists()
    # on stderr (tqdm's own write() would go to stdout, where --json puts the JSON)
    print(f"identify: {len(tests)} test(s) x {len(models)} model(s), {args.bootstrap} bootstrap "
          "refits each", file=sys.stderr, flush=True)
    bar = progress_bar(len(tests) * len(models), desc="identify", unit="fit")

    def tick(label: str) -> None:
        bar.set_postfix_str(label)
        bar.update()

    try:
        result = identify_files(tests, models=models, n_bootstrap=args.bootstrap,
                                out=None if args.no_plots else out, progress=tick)
    finally:
        bar.close()
    if not result["tests"]:
        # nothing identified: no model file, no empty output folder; the reasons in one line
        if not existed and Path(out).is_dir() and not any(Path(out).iterdir()):
            Path(out).rmdir()
        files = {Path(path).name: str(path) for path in args.data}  # the labels are the files' names
        # one entry per file and reason, the model forms it failed for gathered ([normalized,
        # extended]): a changing command fails every form the same way
        gathered: dict[tuple[str, str], list[str]] = {}
        for key, reason in result["failed"].items():
            label, form = key.rsplit(" [", 1)
            gathered.setdefault((files.get(label, label), reason), []).append(form.rstrip("]"))
        raise InputError("no test identified: " + "; ".join(
            f"{path} [{', '.join(forms)}]: {reason}" for (path, reason), forms in gathered.items()))
    # one model file per model form (damper.io.model_file), read by sbib run/compare --damper
    result["model_files"] = {k: str(v) for k, v in write_identified_models(result, out, args.data).items()}
    if args.json:
        print(json.dumps(result, indent=2, default=float))
        return 0 if result["tests"] else 2
    for name, scr in result.get("screening", {}).items():
        if scr.get("file_units"):
            print(f"screening {name}: {units_line(scr['file_units'])}")
        if scr.get("units_unstated"):
            print(f"screening {name}: {scr['units_unstated']}")
        est = scr.get("estimates", {})
        if "force_velocity_lag_s" in est and scr["findings"]:
            print(f"screening {name}: estimated force lag behind the velocity "
                  f"{1e3 * est['force_velocity_lag_s']:.3g} ms, velocity channel "
                  f"{1e3 * est.get('velocity_lag_s', 0.0):.3g} ms behind d(x)/dt")
        for line in finding_lines([Finding(**f) for f in scr["findings"]], kept=args.keep_flagged):
            print(f"screening {name}: {line}")
        if scr["findings"]:
            print(f"screening {name}: {scr['n_excluded']} of {scr['n_samples']} samples "
                  + ("kept (--keep-flagged)" if args.keep_flagged else "excluded from fit and error"))
    for s in result["tests"]:
        p = s["parameters"]
        level = "" if s["level"] is None else f" at {s['level']:g} {s['level_unit']}"
        print(f"{s['file']} [{s['model']}]{level}: fit error {100 * s['errors']['rel_rms_error']:.2f} %")
        print("    " + ", ".join(format_si(k, p[k]) for k in p))
        for k, where in s.get("at_bounds", {}).items():
            print(f"    at a bound: {k} ({where}): not identified by this test")
        for w in s.get("warnings", []):
            print(f"    warning: {w}")
        for other, e in s.get("held_out", {}).items():
            print(f"    predicts {other}: error {100 * e['rel_rms_error']:.2f} %")
    for key, entry in result.get("levels", {}).items():
        p = entry["parameters"]
        print(f"one model at {key} over {len(entry['tests'])} tests (started from "
              f"{entry['started_from']}): mean error {100 * entry['mean_error']:.2f} %")
        print("    " + ", ".join(format_si(k, p[k]) for k in p))
        for k, where in entry["at_bounds"].items():
            print(f"    at a bound: {k} ({where}): not identified by these tests")
        for name, err in entry["errors"].items():
            own = entry["per_test_errors"][name]
            print(f"    {name}: error {100 * err:.2f} % (its own fit: {100 * own:.2f} %)")
    for name, reason in result["failed"].items():
        print(f"{name}: not identified: {reason}")
    for m, entry in result["summary"].items():
        fit, ho = entry["mean_fit_rel_rms_error"], entry["mean_held_out_rel_rms_error"]
        print(f"{m}: {entry['n_tests']} test(s), mean fit error "
              + ("-" if fit is None else f"{100 * fit:.2f} %") + ", mean held-out error "
              + ("-" if ho is None else f"{100 * ho:.2f} %"))
    for f in result["figures"]:
        print(f"figure: {f}")
    for form, f in result["model_files"].items():
        print(f"model file ({form}): {f}")
    return 0 if result["tests"] else 2


def _run(args: argparse.Namespace) -> int:
    if args.data:
        return _run_data(args)


    if args.model:
        print("sbib identify: --model applies to --data only", file=sys.stderr)
        return 2
    kappa_x = args.kappa_x
    if kappa_x not in ("large-loop", "joint", "per-voltage"):
        try:
            kappa_x = float(kappa_x)
        except ValueError:
            print(f"sbib identify: --kappa-x: expected large-loop, joint, per-voltage or a number "
                  f"in N/m, got {args.kappa_x!r}", file=sys.stderr)
            return 2
    summary = run_identify_study(args.out or "results/identify", records=_split(args.records),
                                 orientations=_split(args.orientations), controller=args.controller,
                                 validate=not args.no_validation, records_dir=args.records_dir,
                                 synthetic=args.synthetic, progress=True,
                                 plots=not args.no_plots, kappa_x=kappa_x,
                                 compare_free_kappa_x=not args.no_free_kappa_x,
                                 ceiling=not args.no_ceiling, jobs=args.jobs,
                                 close_loop=not args.no_closed_loop, campaign_scale=args.campaign_scale,
                                 full_histories=args.full_histories)
    if args.json:
        print(json.dumps({k: summary[k] for k in ("device", "voltages", "kappa_x", "parameters", "identification_errors",
                                                   "at_bounds", "law_errors", "field_lag", "validation", "ceiling",
                                                   "closed_loop", "claim_test", "files", "timings")}, indent=2, default=float))
    else:
        val = summary["validation"]
        print(f"identified {summary['device']} at {len(summary['voltages'])} voltages; files in "
              f"{summary['files']['parameters'].rsplit('/', 1)[0]}")
        for model, where in (summary.get("at_bounds") or {}).items():
            print(f"at a bound of the search ({model}; not identified by these tests): "
                  + ", ".join(f"{v}: {names}" for v, names in where.items()))
        if val:
            print("validation in the earthquake runs (relative errors as fractions):")
            _print_tree(val["summary"], "  ")
        if summary.get("claim_test"):
            print("the seed's claim, extended/normalized relative RMS error per run:")
            for label, c in summary["claim_test"].items():
                print(f"  {label}: {c['extended']} / {c['normalized']}: mean {c['ratio_mean']:.3f}, "
                      f"max {c['ratio_max']:.3f}, below 1 on every run: {c['below_one_every_run']}")
        if summary.get("ceiling"):
            print("structural ceiling (constant voltage, each run's most-moving damper):")
            _print_tree(summary["ceiling"], "  ")
        print(f"total {summary['timings']['total_s']:.1f} s")
    return 0
