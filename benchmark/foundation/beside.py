"""Run one function in a forked child process while the caller goes on.

For single-core work on large inputs already in memory (the main job draws half of the
comparison's figures this way while it draws the other half): the child is a ``fork`` of the
caller, so the inputs are inherited, never pickled; only the return value, which must be small
and picklable, comes back through a pipe. Where ``fork`` is not available (Windows) the
function runs at once in the caller instead.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import traceback
from typing import Any, Callable

from benchmark.foundation.errors import SbibError

__all__ = ["Beside", "run_beside"]


class Beside:
    """Handle of a function running beside the caller (:func:`run_beside`).

    Parameters
    ----------
    fn : Callable[..., Any]
        The function running in the child.
    args : tuple
        Its arguments.
    """

    def __init__(self, fn: Callable[..., Any], args: tuple) -> None:
        self._value: Any = None
        self._process: Any = None
        self._conn: Any = None
        if "fork" not in multiprocessing.get_all_start_methods():
            self._value = fn(*args)  # no fork: inline, at once
            return
        ctx = multiprocessing.get_context("fork")
        receive, send = ctx.Pipe(duplex=False)
        self._process = ctx.Process(target=_child, args=(send, fn, args), daemon=True)
        self._process.start()
        send.close()
        self._conn = receive

    def result(self) -> Any:
        """Wait for the function and return its value.

        Raises
        ------
        SbibError
            The function raised in the child (its traceback is in the message), or the child
            died without an answer (killed, out of memory).
        """
        if self._process is None:
            return self._value
        try:
            ok, payload = self._conn.recv()
        except EOFError:
            ok, payload = False, "the process ended without an answer"
        finally:
            self._conn.close()
            self._process.join()
        if not ok:
            raise SbibError(f"work run beside the main process failed (exit code "
                            f"{self._process.exitcode}): {payload}")
        return payload


def _child(conn: Any, fn: Callable[..., Any], args: tuple) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's: it ends this process
    try:
        conn.send((True, fn(*args)))
    except BaseException:  # noqa: BLE001 - everything goes back to the parent, which raises
        conn.send((False, traceback.format_exc(limit=8)))
    finally:
        conn.close()
        os._exit(0)  # neither the parent's atexit handlers nor its inherited buffers run twice


def run_beside(fn: Callable[..., Any], *args: Any) -> Beside:
    """Start ``fn(*args)`` in a forked child and return its handle; ``.result()`` waits.

    Parameters
    ----------
    fn : Callable[..., Any]
        A function whose result can be pickled.
    *args
        Its positional arguments.
    """
    return Beside(fn, args)
