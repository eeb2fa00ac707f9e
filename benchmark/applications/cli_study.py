"""``sbib study``: the main job (what ``make run`` runs)."""

from __future__ import annotations

import argparse
import contextlib
import io
import tempfile
import time

from benchmark.applications.study import run_study
from benchmark.foundation.atomic import output_dir


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``study`` sub-command (the main job) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    p = subparsers.add_parser("study", help="run the main job: records, benchmark suite, controllers, identification",
                              description="Run everything end to end and write results and plots to --out.")
    p.add_argument("--out", default="results", type=output_dir, help="output directory (default: results)")
    p.add_argument("--records-dir", default=None, help="directory of the benchmark record files")
    p.add_argument("--quick", action="store_true", help="fewer runs (smoke test)")
    p.add_argument("--dyke", action="store_true",
                   help="also run the residual loop on the shared Dyke recording (a real damper, random "
                        "motion and voltage; Spencer base, 60 s budget): its diagnosis joins the report "
                        "page, at about half a minute more on two cores")
    p.set_defaults(func=_run)
    w = subparsers.add_parser(
        "warm-up", help="compile the kernels once (what `make setup` runs): the main job's smoke run",
        description="Run the main job's smoke version (sbib study --quick) in a temporary directory, so "
                    "that numba compiles every kernel the main job needs into its on-disk cache once, "
                    "at set-up (about two minutes on 2 cores), instead of during the first run.")
    w.set_defaults(func=_warm_up)


def _run(args: argparse.Namespace) -> int:
    summary = run_study(args.out, records_dir=args.records_dir, quick=args.quick,
                        dyke=bool(getattr(args, "dyke", False)))
    print(f"\nmain job finished in {summary['elapsed_s']:.1f} s; results in {args.out}/")
    for name, step in summary["steps"].items():
        where = step.get("output", "") if isinstance(step, dict) else ""
        took = step.get("elapsed_s") if isinstance(step, dict) else None
        beside = f"  (beside the {step['beside']})" if isinstance(step, dict) and step.get("beside") else ""
        print(f"  {name:<15} {'' if took is None else f'{took:7.1f} s'}  {where}{beside}")
    print(f"summary: {args.out}/summary.json")
    print(f"report:  {summary['report']}  (open it in a browser; works offline)")
    return 0


def _warm_up(args: argparse.Namespace) -> int:
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="sbib-warm-up-") as tmp:
        with contextlib.redirect_stdout(io.StringIO()):  # the smoke run's tables are not the point
            run_study(tmp, quick=True)
    print(f"sbib warm-up: kernels compiled and cached, smoke run of the main job passed "
          f"({time.perf_counter() - start:.0f} s)")
    return 0
