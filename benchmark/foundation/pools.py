"""Process pools that Ctrl-C always stops, at once and quietly.

The parent process owns the interrupt. :class:`WorkerPool` is a
:class:`concurrent.futures.ProcessPoolExecutor` whose workers ignore SIGINT (a Ctrl-C at a
terminal goes to every process of the foreground group; a worker that raised
``KeyboardInterrupt`` would print a traceback and break the pool), and which the parent stops
with :meth:`WorkerPool.stop` when it is interrupted or a task fails: the workers are
terminated, nothing is waited for, and no further Ctrl-C can interrupt the stopping.

Why not ``shutdown(cancel_futures=True)``, as the standard library suggests: it waits for the
running tasks (a simulation: many seconds), a second Ctrl-C inside that wait leaves the pool's
manager thread half-joined (the interpreter then hangs in its exit-time join, and a third
Ctrl-C prints ``Exception ignored in atexit callback``), and futures cancelled in the parent
make the manager thread fail with ``InvalidStateError: CANCELLED`` when a worker dies. So
:meth:`WorkerPool.stop` cancels no future: it terminates the workers, lets the manager thread
mark the outstanding futures broken, and waits for that thread at most briefly.

``with pool_closing(pool): ...`` shuts a pool down normally after the block and stops it when
the block raises (``KeyboardInterrupt`` or an error).

Every study, suite and ensemble takes its pool here (the one pool constructor):
:func:`make_executor` / :func:`make_side_executor` and :func:`run_tasks` run independent,
deterministic tasks and gather their results in task order, so the outputs are the same for
any number of workers; ``jobs=1`` runs every task in this process. Every task runs with
OpenBLAS limited to one thread (:func:`single_threaded_blas`; the pool's workers for good, the
inline path for the duration of the tasks): the matrices are small, and OpenBLAS's own threads
in two or more worker processes oversubscribe the cores (on a 2-core machine the identification
study took 73 s instead of 32 s). Running the same BLAS configuration inline and in the workers
also keeps the results identical whatever ``jobs`` is.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import ctypes
import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures import Executor
from typing import Any, Callable, Iterable, Iterator, Sequence

from benchmark.foundation.errors import InputError

__all__ = ["WorkerPool", "stop_pool", "pool_closing", "stop_children", "sigint_held", "ignore_sigint",
           "worker_count", "make_executor", "make_side_executor", "run_tasks", "single_threaded_blas"]

#: seconds a terminated worker gets to end before it is killed
_TERMINATE_GRACE_S = 1.0
#: seconds the pool's manager thread gets to notice the ended workers
_MANAGER_GRACE_S = 2.0


def ignore_sigint() -> None:
    """Leave Ctrl-C to the parent process: SIGINT ignored, and unblocked (see :func:`sigint_held`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


#: seconds between a worker's checks that its parent still lives
_PARENT_POLL_S = 1.0


def _exit_with_parent(parent: int) -> None:
    """End this worker once its parent is gone (killed by SIGKILL or SIGTERM, it cannot stop its
    pool: the workers were left running, each holding its memory, until killed by hand)."""
    while True:
        time.sleep(_PARENT_POLL_S)
        if os.getppid() != parent:  # re-parented: the parent ended
            os._exit(1)


def _start_worker(initializer: Callable[..., Any] | None, initargs: tuple) -> None:
    ignore_sigint()
    threading.Thread(target=_exit_with_parent, args=(os.getppid(),), daemon=True,
                     name="sbib-parent-watch").start()
    if initializer is not None:
        initializer(*initargs)


@contextlib.contextmanager
def sigint_held() -> Iterator[None]:
    """Hold Ctrl-C back in this process while new processes may be started; honour it after.

    Inside the block SIGINT is blocked in this thread (a child forked or spawned here starts
    with it blocked, until :func:`ignore_sigint` runs in it) and, in the main thread with
    Python's default handler installed, recorded instead of raised (another thread may take a
    process-directed signal). A Ctrl-C pressed inside is raised as ``KeyboardInterrupt`` on
    leaving the block.
    """
    pressed: list[int] = []
    previous = None
    if (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
        previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    blocked = hasattr(signal, "pthread_sigmask")
    if blocked:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        if blocked:  # a signal pending on this thread arrives now, at the recorder
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    if pressed:
        raise KeyboardInterrupt


class WorkerPool(cf.ProcessPoolExecutor):
    """A process pool whose workers leave Ctrl-C to the parent and which stops at once.

    Parameters
    ----------
    max_workers : int
        Number of worker processes.
    mp_context : str, optional
        Start method (``"fork"``, ``"spawn"``, ``"forkserver"``); default ``fork`` where it
        exists (the workers inherit the parent's modules and compiled kernels), else ``spawn``.
    initializer, initargs : optional
        Called in each worker after SIGINT is ignored there.

    Notes
    -----
    Used as a context manager it shuts down normally (waiting for the tasks) when the block
    ends normally and calls :meth:`stop` when the block raises.
    """

    def __init__(self, max_workers: int, mp_context: str | None = None,
                 initializer: Callable[..., Any] | None = None, initargs: tuple = ()) -> None:
        if mp_context is None:
            mp_context = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
        super().__init__(max_workers=max_workers, mp_context=multiprocessing.get_context(mp_context),
                         initializer=_start_worker, initargs=(initializer, tuple(initargs)))
        self._stopped = False

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        """Schedule ``fn(*args, **kwargs)`` as :meth:`concurrent.futures.Executor.submit` does.

        Parameters
        ----------
        fn : callable
            A picklable function.
        *args, **kwargs
            Its arguments.

        Returns
        -------
        concurrent.futures.Future
        """
        # Workers are started on submit: hold Ctrl-C back while they are created.
        with sigint_held():
            return super().submit(fn, *args, **kwargs)

    def stop(self) -> None:
        """Stop now: terminate the workers (running tasks are lost), wait for nothing long.

        Outstanding futures end with ``BrokenProcessPool``. Further Ctrl-C during the stop is
        ignored. Calling it again, or after a normal shutdown, does nothing.
        """
        if self._stopped:
            return
        self._stopped = True
        with _sigint_ignored():
            processes = list((getattr(self, "_processes", None) or {}).values())
            manager = getattr(self, "_executor_manager_thread", None)
            for process in processes:
                with contextlib.suppress(Exception):
                    process.terminate()
            for process in processes:
                with contextlib.suppress(Exception):
                    process.join(_TERMINATE_GRACE_S)
                    if process.is_alive():
                        process.kill()
                        process.join(_TERMINATE_GRACE_S)
            # No cancel_futures: a future cancelled here would make the manager thread fail
            # (InvalidStateError) when it marks the outstanding work broken.
            self.shutdown(wait=False)
            if manager is not None and manager is not threading.current_thread():
                manager.join(_MANAGER_GRACE_S)

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            _shutdown_or_stop(self)
        else:
            self.stop()
        return False


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """Ignore SIGINT in the block (main thread only; restored after)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)


def stop_pool(pool: cf.Executor | None) -> None:
    """Stop ``pool`` at once (:meth:`WorkerPool.stop`); other executors are shut down without waiting.

    Parameters
    ----------
    pool : Executor or None
        The pool (``None``: nothing to stop).
    """
    if pool is None:
        return
    if isinstance(pool, WorkerPool):
        pool.stop()
    else:
        pool.shutdown(wait=False, cancel_futures=True)


@contextlib.contextmanager
def pool_closing(pool: cf.Executor | None) -> Iterator[cf.Executor | None]:
    """Shut ``pool`` down after the block: normally when it ends normally, at once when it raises.

    Parameters
    ----------
    pool : Executor or None
        The pool (``None``: the block runs inline).

    Yields
    ------
    Executor or None
        ``pool``.
    """
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    _shutdown_or_stop(pool)


def _shutdown_or_stop(pool: cf.Executor | None) -> None:
    """Shut down waiting for the tasks; a Ctrl-C during the wait stops the pool at once."""
    if pool is None:
        return
    try:
        pool.shutdown(wait=True)
    except BaseException:
        stop_pool(pool)
        raise


def stop_children() -> None:
    """Terminate every child process this process started (last resort on Ctrl-C)."""
    children = multiprocessing.active_children()
    for child in children:
        with contextlib.suppress(Exception):
            child.terminate()
    for child in children:
        with contextlib.suppress(Exception):
            child.join(_TERMINATE_GRACE_S)
            if child.is_alive():
                child.kill()


# ------------------------------------------------------------- tasks in a pool, results in order

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
    """Number of worker processes for ``jobs`` (``None`` or 0: all cores), at most ``n_tasks``.

    Parameters
    ----------
    jobs : int | None
        Requested workers; None or 0: all cores.
    n_tasks : int | None, optional
        Number of tasks; None: no cap.
    """
    if jobs is not None and (not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 0):
        raise InputError(f"jobs: expected a whole number >= 0 (0 or None: all cores), got {jobs!r}")
    n = jobs or os.cpu_count() or 1
    if n_tasks is not None:
        n = min(n, max(1, n_tasks))
    return max(1, n)


def make_executor(jobs: int | None) -> Executor | None:
    """A process pool of :func:`worker_count` workers, or ``None`` when that is 1 (run inline).

    Parameters
    ----------
    jobs : int | None
        Requested workers; None or 0: all cores.
    """
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

    Parameters
    ----------
    fn : Callable
        A picklable function.
    tasks : Sequence[tuple]
        Argument tuples, one per call.
    executor : Executor | None, optional
        Process pool to run on (:func:`benchmark.foundation.pools.make_executor`); None: run inline.
    progress : Callable[[Any], None] | None, optional
        Called with each result as it arrives; None: silent.
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
