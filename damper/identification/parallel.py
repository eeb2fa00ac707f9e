"""Process pools for the identification study (voltage grid and earthquake validation).

The tasks of the study are independent, deterministic functions of their arguments, so they
run in a process pool (:class:`benchmark.foundation.pools.WorkerPool`: ``fork`` where available,
workers that leave Ctrl-C to the parent, stopped at once when interrupted) and their results are gathered in task order: the outputs
are the same for any number of workers. ``jobs=1`` runs every task in this process.

Every task runs with OpenBLAS limited to one thread (:func:`single_threaded_blas`; the pool's
workers for good, the inline path for the duration of the tasks): the study's matrices are
small, and OpenBLAS's own threads in two or more worker processes oversubscribe the cores (on a
2-core machine the whole study took 73 s instead of 32 s). Running the same BLAS configuration
inline and in the workers also keeps the results identical whatever ``jobs`` is.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
from concurrent.futures import Executor
from typing import Any, Callable, Iterable, Sequence

from benchmark.foundation.errors import InputError
from benchmark.foundation.pools import WorkerPool

__all__ = ["worker_count", "make_executor", "make_side_executor", "run_tasks", "single_threaded_blas"]

_SETTERS = ("scipy_openblas_set_num_threads64_", "scipy_openblas_set_num_threads",
            "openblas_set_num_threads64_", "openblas_set_num_threads")
_GETTERS = ("scipy_openblas_get_num_threads64_", "scipy_openblas_get_num_threads",
            "openblas_get_num_threads64_", "openblas_get_num_threads")


def _openblas_controls() -> list[tuple]:
    """(get, set) C functions of every OpenBLAS loaded in this process (Linux; else none)."""
    try:
        with open("/proc/self/maps", encoding="utf-8") as fh:
            paths = sorted({line.split()[-1] for line in fh if "openblas" in line.lower() and "/" in line})
    except OSError:
        return []
    controls = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        get = next((getattr(lib, n) for n in _GETTERS if hasattr(lib, n)), None)
        put = next((getattr(lib, n) for n in _SETTERS if hasattr(lib, n)), None)
        if get is not None and put is not None:
            get.restype = ctypes.c_int
            controls.append((get, put))
    return controls


@contextlib.contextmanager
def single_threaded_blas():
    """Limit every loaded OpenBLAS to one thread inside the block (best effort; restored after)."""
    controls = _openblas_controls()
    before = [get() for get, _ in controls]
    for _, put in controls:
        put(ctypes.c_int(1))
    try:
        yield
    finally:
        for (_, put), n in zip(controls, before):
            put(ctypes.c_int(n))


def _init_worker() -> None:
    for _, put in _openblas_controls():
        put(ctypes.c_int(1))


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
    return None if n == 1 else _pool(n)


def make_side_executor() -> Executor | None:
    """One extra worker process for a single-core job that runs beside a pool of
    :func:`make_executor`, or ``None`` on a one-core machine (run it inline afterwards)."""
    return None if worker_count(None) == 1 else _pool(1)


def _pool(n: int) -> Executor:
    # WorkerPool: the workers ignore Ctrl-C; the owner stops the pool at once when interrupted
    # (benchmark.foundation.pools.pool_closing).
    return WorkerPool(n, initializer=_init_worker)


def run_tasks(fn: Callable, tasks: Sequence[tuple], executor: Executor | None = None,
              progress: Callable[[Any], None] | None = None) -> list:
    """``[fn(*task) for task in tasks]``, on ``executor`` when given; results in task order.

    ``progress`` is called with each result as it is gathered (in task order).
    """
    out = []
    results: Iterable
    if executor is None:
        for task in tasks:
            with single_threaded_blas():
                r = fn(*task)
            out.append(r)
            if progress is not None:
                progress(r)
        return out
    futures = [executor.submit(fn, *task) for task in tasks]
    for f in futures:
        r = f.result()
        out.append(r)
        if progress is not None:
            progress(r)
    return out
