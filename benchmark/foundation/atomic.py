"""Atomic file writing: a result file is either the previous one or a complete new one.

Write to a temporary file in the destination's directory, flush and fsync it, then
``os.replace`` it onto the destination (atomic on POSIX within one filesystem). On any
exception, including ``KeyboardInterrupt``, the temporary file is removed. Ctrl-C pressed
while the file is written is held back until the writer returns, then honoured (see
:func:`_deferred_sigint`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import tempfile
import threading
from pathlib import Path
from typing import Callable, Iterator

__all__ = ["atomic_path", "atomic_write_text"]


@contextlib.contextmanager
def atomic_path(destination: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path next to ``destination``; rename it onto ``destination`` on success.

    Parameters
    ----------
    destination : path-like
        Final file path. Its parent directory is created if needed.
    suffix : str, optional
        Suffix of the temporary file (defaults to the destination's, so that libraries
        that choose a format from the extension, like matplotlib, still work).

    Examples
    --------
    >>> with atomic_path("out.h5") as tmp:          # doctest: +SKIP
    ...     with h5py.File(tmp, "w") as f: ...
    """
    destination = Path(destination)
    destination.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{destination.name}.partial-",
                                suffix=destination.suffix if suffix is None else suffix,
                                dir=destination.parent)
    os.close(fd)
    tmp = Path(name)
    # mkstemp creates 0600; a result file should get the permissions any new file gets.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        with _deferred_sigint() as interrupted:
            yield tmp
            if interrupted():  # Ctrl-C during the write: keep the previous file
                raise KeyboardInterrupt
            with open(tmp, "rb") as fh:
                os.fsync(fh.fileno())
            os.replace(tmp, destination)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    if interrupted():  # Ctrl-C during the rename: the new file is complete; stop now
        raise KeyboardInterrupt


@contextlib.contextmanager
def _deferred_sigint() -> Iterator[Callable[[], bool]]:
    """Hold Ctrl-C (SIGINT) back while the file is written; yield "was it pressed?".

    A KeyboardInterrupt raised inside h5py's C code is often swallowed by a weakref callback
    ("Exception ignored in ..."), so the program would go on as if Ctrl-C had not been
    pressed. Holding the signal until the write returns makes Ctrl-C reliable: the temporary
    file is then removed and KeyboardInterrupt raised. Only in the main thread and only when
    Python's default handler is installed (a program's own handler is left alone).
    """
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield lambda: False
        return
    pressed: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        yield lambda: bool(pressed)
    finally:
        signal.signal(signal.SIGINT, previous)


def atomic_write_text(destination: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``destination`` atomically and return the path.

    Parameters
    ----------
    destination : str | os.PathLike
        File to write (replaced atomically).
    text : str
        The text (UTF-8).
    """
    with atomic_path(destination) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(destination)
