"""``sbib compare``: every record × orientation × controller, J1–J9 table, JSON, HDF5, plots.

``--controllers`` also takes a user's class (``package.module:Class``, ``file.py:Class``);
``--damper FILE.json|NAME`` (or ``--dampers A.json,B.json,...``: every model in the same runs,
with the J differences and the force-difference figures of
:mod:`benchmark.applications.model_comparison`), ``--devices`` and ``--damper-scale`` choose the
devices (:mod:`benchmark.applications.damper_choice`).
"""

from __future__ import annotations

import argparse
import json
import sys
from controllers.registry import controller_names
from benchmark.foundation.errors import InputError
from benchmark.foundation.arguments import positive_int
from benchmark.foundation.atomic import output_dir, output_file_of
from benchmark.applications.comparison import compare
from records.options import add_record_options
from benchmark.applications.damper_choice import add_damper_options

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``compare`` sub-command.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """

    p = subparsers.add_parser(
        "compare", help="compare controllers over the benchmark records (J1-J9)",
        description="Run every record x orientation x controller against the uncontrolled building, "
                    "print J1-J9 per run and the mean/max over records.")
    p.add_argument("--records", default="all",
                   help="'all' or a comma list of benchmark record names and/or record files "
                        "(read as sbib run --record reads them; see --format, --dt, --units)")
    p.add_argument("--orientations", default="both",
                   help="'both', or a comma list of FN-x, FP-x; the seed paper's FP-y (= FN-x) and "
                        "FN-y (= FP-x) are accepted")
    p.add_argument("--controllers", default="passive-off,passive-on,clipped-optimal",
                   help="comma list of: " + ", ".join(controller_names())
                        + ", or classes of yours as package.module:Class or path/to/file.py:Class")
    p.add_argument("--isolation", default=None, help="isolation configuration name (default: the building's)")
    p.add_argument("--synthetic", action="store_true",
                   help="use the synthetic benchmark-like records (rows say 'kobe (synthetic)')")
    add_record_options(p, orientation=False, several=True)  # --records-dir, --format, --dt, --units, ...
    p.add_argument("--control-step", type=float, default=None,
                   help="control step [s], any positive time (default: the benchmark's 0.005 s); a record "
                        "at another step is interpolated onto the integration step, e.g. --control-step 0.01")
    p.add_argument("--n-modes", type=int, default=None, help="reduced superstructure (default: all modes)")
    p.add_argument("--jobs", type=positive_int, default=None, help="worker processes (default: all cores)")
    p.add_argument("--json", action="store_true", help="print {\"runs\": [...]} as JSON instead of the table")
    p.add_argument("--out", default=None, type=output_file_of("hdf5"), help="write every run to this HDF5 file (atomic)")
    p.add_argument("--plot", default=None, metavar="DIR", type=output_dir, help="write the PNG figures into DIR")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    add_damper_options(p)  # --damper, --devices, --damper-scale
    p.add_argument("--dampers", default=None, metavar="A.json,B.json",
                   help="several damper models (files or names) run side by side in the same runs: J's per "
                        "model, their differences and the force-difference figures (the seed's Fig. 11)")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    if args.damper and args.dampers:
        raise InputError("--damper and --dampers: give one of them")
    dampers = args.dampers or args.damper
    result = compare(dampers=dampers, devices=args.devices, damper_scale=args.damper_scale,
                     records=args.records, orientations=args.orientations, controllers=args.controllers,
                     isolation=args.isolation, records_dir=args.records_dir, jobs=args.jobs,
                     control_step=args.control_step, n_modes=args.n_modes, synthetic=args.synthetic,
                     progress=not args.no_progress and sys.stderr.isatty(), format=args.format, dt=args.dt,
                     units=args.units, baseline_correct=args.baseline_correct)
    if args.out:
        path = result.write_hdf5(args.out)
        print(f"wrote {path}", file=sys.stderr)
    if args.plot:
        for path in result.plot(args.plot):
            print(f"wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps(result.to_json(), indent=2))
    else:
        print(result.table())
        info = result.settings.get("damper")
        if info:
            for d in info["dampers"]:
                print(f"damper {d['damper']} ({d['model']}): {d['scale_basis']}; {d['input_mapping']}")
                for note in d["notes"]:
                    print(f"  {note if note.startswith('warning: ') else 'note: ' + note}")
        units = result.settings.get("record_units") or {}
        if units:
            print("record values read as: " + "; ".join(f"{k}: {v}" for k, v in units.items()))
    return 0
