"""Process pools for the identification study (voltage grid and earthquake validation).

The tasks of the study are independent, deterministic functions of their arguments, so they
run in a :class:`concurrent.futures.ProcessPoolExecutor` (``fork`` where available, as
:mod:`controllers.comparison` does) and their results are gathered in task order: the outputs
are the same for any number of workers. ``jobs=1`` runs every task in this process.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import Executor, ProcessPoolExecutor
from typing import Any, Callable, Iterable, Sequence

from benchmark.errors import InputError

__all__ = ["worker_count", "make_executor", "run_tasks"]


def worker_count(jobs: int | None, n_tasks: int | None = None) -> int:
    """Number of worker processes for ``jobs`` (``None`` or 0: all cores), at most ``n_tasks``."""
    if jobs is not None and (not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 0):
        raise InputError(f"jobs: expected a whole number >= 0 (0 or None: all cores), got {jobs!r}")
    n = jobs or os.cpu_count() or 1
    if n_tasks is not None:
        n = min(n, max(1, n_tasks))
    return max(1, n)


def make_executor(jobs: int | None) -> Executor | None:
    """A process pool of :func:`worker_count` workers, or ``None`` when that is 1 (run inline)."""
    n = worker_count(jobs)
    if n == 1:
        return None
    ctx = multiprocessing.get_context("spawn" if os.name == "nt" else "fork")
    return ProcessPoolExecutor(max_workers=n, mp_context=ctx)


def run_tasks(fn: Callable, tasks: Sequence[tuple], executor: Executor | None = None,
              progress: Callable[[Any], None] | None = None) -> list:
    """``[fn(*task) for task in tasks]``, on ``executor`` when given; results in task order.

    ``progress`` is called with each result as it is gathered (in task order).
    """
    out = []
    results: Iterable
    if executor is None:
        results = (fn(*task) for task in tasks)
    else:
        futures = [executor.submit(fn, *task) for task in tasks]
        results = (f.result() for f in futures)
    for r in results:
        out.append(r)
        if progress is not None:
            progress(r)
    return out
