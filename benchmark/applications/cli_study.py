"""``sbib study``: the main job (what ``make run`` runs)."""

from __future__ import annotations

import argparse
from benchmark.applications.study import run_study


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("study", help="run the main job: records, benchmark suite, controllers, identification",
                              description="Run everything end to end and write results and plots to --out.")
    p.add_argument("--out", default="results", help="output directory (default: results)")
    p.add_argument("--records-dir", default=None, help="directory of the benchmark record files")
    p.add_argument("--quick", action="store_true", help="fewer runs (smoke test)")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    summary = run_study(args.out, records_dir=args.records_dir, quick=args.quick)
    print(f"\nmain job finished in {summary['elapsed_s']:.1f} s; results in {args.out}/")
    for name, step in summary["steps"].items():
        where = step.get("output", "") if isinstance(step, dict) else ""
        took = step.get("elapsed_s") if isinstance(step, dict) else None
        print(f"  {name:<15} {'' if took is None else f'{took:7.1f} s'}  {where}")
    print(f"summary: {args.out}/summary.json")
    print(f"report:  {summary['report']}  (open it in a browser; works offline)")
    return 0
