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
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
import signal
import threading
from typing import Any, Callable, Iterator

__all__ = ["WorkerPool", "stop_pool", "pool_closing", "stop_children", "sigint_held", "ignore_sigint"]

#: seconds a terminated worker gets to end before it is killed
_TERMINATE_GRACE_S = 1.0
#: seconds the pool's manager thread gets to notice the ended workers
_MANAGER_GRACE_S = 2.0


def ignore_sigint() -> None:
    """Leave Ctrl-C to the parent process: SIGINT ignored, and unblocked (see :func:`sigint_held`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _start_worker(initializer: Callable[..., Any] | None, initargs: tuple) -> None:
    ignore_sigint()
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
    """Stop ``pool`` at once (:meth:`WorkerPool.stop`); other executors are shut down without waiting."""
    if pool is None:
        return
    if isinstance(pool, WorkerPool):
        pool.stop()
    else:
        pool.shutdown(wait=False, cancel_futures=True)


@contextlib.contextmanager
def pool_closing(pool: cf.Executor | None) -> Iterator[cf.Executor | None]:
    """Shut ``pool`` down after the block: normally when it ends normally, at once when it raises."""
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

