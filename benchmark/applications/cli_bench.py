"""``sbib bench``: the performance benchmarks (what ``make bench`` runs)."""

from __future__ import annotations

import argparse
from benchmark.foundation.arguments import positive_int
from benchmark.foundation.atomic import output_dir
from benchmark.applications.speed import run_bench

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``bench`` sub-command to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    p = subparsers.add_parser(
        "bench", help="measure speed, memory and scaling against targets and the solve_ivp reference",
        description="Time one 30-s run, compare it with the scipy solve_ivp reference, time the "
                    "benchmark suite under 5 controllers on 2 processes (cold start apart), check "
                    "that a second process does not recompile, time the identification study, "
                    "measure peak memory and scaling. Prints a table; writes bench.json and "
                    "scaling.png into --out. Timings are measured, never asserted.")
    p.add_argument("--out", default="results/bench", type=output_dir, help="output directory (default: results/bench)")
    p.add_argument("--quick", action="store_true", help="fewer repeats and scaling points (smoke run)")
    p.add_argument("--jobs", type=positive_int, default=2, help="processes of the suite and ensemble cases (default 2)")
    p.add_argument("--only", default=None,
                   help="comma list of sections: single, suite, identify, diagnose, scaling (default: all)")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    sections = ("single", "suite", "identify", "diagnose", "scaling")
    if args.only:
        sections = tuple(s.strip() for s in args.only.split(",") if s.strip())
    run_bench(args.out, quick=args.quick, jobs=args.jobs, sections=sections)
    return 0
