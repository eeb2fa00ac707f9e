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

from benchmark.foundation.errors import InputError

__all__ = ["atomic_path", "atomic_write_text", "check_output", "output_file", "output_file_of", "output_dir",
           "DATA_SUFFIXES"]


def check_output(path: str | os.PathLike, directory: bool = False, option: str = "--out") -> Path:
    """Refuse an output path that cannot be written, before any work is done.

    Parameters
    ----------
    path : path-like
        The output file, or directory with ``directory=True``; missing parents are created
        later by the writers.
    directory : bool
        The output is a directory.
    option : str
        The command-line option named in the message.

    Raises
    ------
    InputError
        A file where a directory is expected or the reverse, a parent that is a file, or a
        directory that cannot be written.
    """
    p = Path(path)
    if not directory and p.exists() and not p.is_dir() and not p.is_file():
        # a device or a pipe (/dev/null): the atomic rename would replace the node with a file
        raise InputError(f"{option} {path}: exists and is not a regular file (a device or a pipe); "
                         "expected a file name")
    if directory and p.exists() and not p.is_dir():
        raise InputError(f"{option} {path}: exists and is not a directory; expected a directory")
    if not directory and p.is_dir():
        raise InputError(f"{option} {path}: is a directory; expected a file name")
    parent = p if directory else p.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(f"{option} {path}: {parent} is a file, not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {path}: cannot write into {parent} (permission denied)")
    return p


def _checked_output(text: str, directory: bool) -> str:
    import argparse  # only the command line needs it
    try:
        check_output(text, directory=directory, option="")
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc).strip()) from None
    return text


def output_file(text: str) -> str:
    """``argparse`` type of an output file option: :func:`check_output` at parse time.

    Parameters
    ----------
    text : str
        The option's value.
    """
    return _checked_output(text, directory=False)


#: File name endings of the data formats the commands read or write, by format: an output
#: named for another format would be misread later (``sbib run --record x.h5`` on a CSV).
DATA_SUFFIXES = {
    "csv": (".csv",),
    "text": (".txt", ".dat"),  # any text: CSV or JSON may carry them, HDF5 or PNG may not
    "hdf5": (".h5", ".hdf5", ".hdf"),
    "json": (".json",),
    "png": (".png",),
    "other": (".at2", ".mat", ".toml", ".npy", ".npz", ".pdf", ".svg", ".html"),
}


def output_file_of(fmt: str) -> Callable[[str], str]:
    """``argparse`` type of an output file in format ``fmt``: :func:`output_file`, and a name
    ending in another format's suffix (:data:`DATA_SUFFIXES`) is refused.

    A name with no suffix or an unknown one is accepted: the check only catches a file that
    would announce another format than its contents.

    Parameters
    ----------
    fmt : str
        A key of :data:`DATA_SUFFIXES` (``"csv"``, ``"hdf5"``, ``"json"``, ``"png"``); CSV and
        JSON files may also be named ``.txt`` or ``.dat``.
    """
    expected = DATA_SUFFIXES[fmt] + (DATA_SUFFIXES["text"] if fmt in ("csv", "json") else ())
    others = {s for key, group in DATA_SUFFIXES.items() if key != fmt for s in group} - set(expected)

    def check(text: str) -> str:
        import argparse  # only the command line needs it
        suffix = Path(text).suffix.lower()
        if suffix in others:
            raise argparse.ArgumentTypeError(
                f"{text}: this option writes {fmt.upper()}, not {suffix[1:].upper()}; "
                f"name it with {' or '.join(expected[:2])}")
        return _checked_output(text, directory=False)

    check.__name__ = f"{fmt} output file"  # argparse names the type in its messages
    return check


def output_dir(text: str) -> str:
    """``argparse`` type of an output directory option: :func:`check_output` at parse time.

    Parameters
    ----------
    text : str
        The option's value.
    """
    return _checked_output(text, directory=True)


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
    if destination.is_symlink():
        # write through the link to its target (the rename would replace the link by a file)
        destination = destination.resolve()
    if destination.exists() and not destination.is_file() and not destination.is_dir():
        raise InputError(f"{destination}: exists and is not a regular file (a device or a pipe); "
                         "expected a file name")
    try:
        destination.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{destination.name}.partial-",
                                    suffix=destination.suffix if suffix is None else suffix,
                                    dir=destination.parent)
    except OSError as exc:  # name the file asked for, not the temporary one
        raise InputError(f"{destination}: cannot be written ({exc.strerror or exc})") from None
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
