"""``sbib study``: the main job (what ``make run`` runs)."""

from __future__ import annotations

import argparse
import json


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("study", help="run the main job: records, benchmark suite, controllers, identification",
                              description="Run everything end to end and write results and plots to --out.")
    p.add_argument("--out", default="results", help="output directory (default: results)")
    p.add_argument("--records-dir", default=None, help="directory of the benchmark record files")
    p.add_argument("--quick", action="store_true", help="fewer runs (smoke test)")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from benchmark.study import run_study

    summary = run_study(args.out, records_dir=args.records_dir, quick=args.quick)
    print(json.dumps(summary, indent=2))
    return 0
