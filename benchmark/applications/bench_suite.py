"""The suite measurement of ``sbib bench`` in a fresh interpreter (cold start, own memory).

:func:`benchmark.applications.speed.bench_suite` runs ``python -m benchmark.applications.bench_suite
ARGS`` twice, so that the import time, the first run (loading the numba cache, or compiling) and the
peak memory are those of a new process, not of the ``sbib bench`` process that already holds
every kernel. ``ARGS`` is a JSON object (``jobs``, ``controllers``, ``repeat``, ``synthetic``,
``serial``); the one line ``BENCH-JSON {...}`` on standard output carries the measurements.
"""

from __future__ import annotations

import json
import resource
import sys
import time
from typing import Any

_T0 = time.perf_counter()
# the project's import time is one of the measurements: these imports are timed
from benchmark.applications import speed  # noqa: E402
from benchmark.applications.comparison import compare  # noqa: E402
import benchmark.simulator.evaluation  # noqa: E402, F401

_IMPORT_S = time.perf_counter() - _T0

__all__ = ["measure_suite"]


def measure_suite(args: dict[str, Any]) -> dict[str, Any]:
    """Time the project's imports, one short warm-up run and the suite (``repeat`` times).

    Parameters
    ----------
    args : dict
        ``jobs`` (worker processes), ``controllers`` (names), ``repeat`` (suite runs),
        ``synthetic`` (synthetic records), ``serial`` (also run the suite on one process).

    Returns
    -------
    dict
        Seconds of the imports, of the first run and of each suite run (parallel and serial),
        the run count, the process's total CPU time [s], peak memory of this process and of its
        largest worker [MB] and the numba compilation counts.
    """
    t_import = _IMPORT_S  # measured when this module was loaded (a fresh process: the project's imports)
    t1 = time.perf_counter()
    speed._simulate(speed._building(), speed._record(1.0))  # load (or compile) every kernel
    t_first = time.perf_counter() - t1
    counts = speed.compile_counts()
    times, res = [], None
    for _ in range(int(args["repeat"])):
        t2 = time.perf_counter()
        res = compare(records="all", orientations="both", controllers=list(args["controllers"]),
                      jobs=args["jobs"], synthetic=args["synthetic"], progress=False)
        times.append(time.perf_counter() - t2)
    # peak memory of the suite run itself (parent and workers), before the one-process pass that
    # measures the parallel efficiency runs every case in this process
    suite_self_kb = speed.own_peak_rss_kb()
    serial = []
    if args.get("serial"):
        t3 = time.perf_counter()
        compare(records="all", orientations="both", controllers=list(args["controllers"]),
                jobs=1, synthetic=args["synthetic"], progress=False)
        serial.append(time.perf_counter() - t3)
    ru_self, ru_child = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = ru_self.ru_utime + ru_self.ru_stime + ru_child.ru_utime + ru_child.ru_stime
    return {"import_s": t_import, "first_run_s": t_first, "suite_s": times, "serial_s": serial,
            "n_runs": len(res.runs) if res is not None else 0, "cpu_total_s": cpu_s,
            "peak_rss_parent_mb": suite_self_kb / 1024, "peak_rss_worker_mb": ru_child.ru_maxrss / 1024,
            "peak_rss_after_serial_mb": speed.own_peak_rss_kb() / 1024, "compile": counts}


if __name__ == "__main__":
    print("BENCH-JSON " + json.dumps(measure_suite(json.loads(sys.argv[1]))))
