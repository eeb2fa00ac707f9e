"""Progress on stderr, the same way for every long step: a bar on a terminal, lines in a log.

A tqdm bar redraws itself with carriage returns; written to a file (``make run > log``,
``nohup``) those redraws pile up into one enormous line. :func:`progress_bar` therefore draws a
tqdm bar only when its stream is a terminal and otherwise prints one complete line per step::

    compare: 7/24 runs (29 %), 41 s elapsed, ~100 s left; kobe FN-x skyhook

:func:`progress_lines` is the same for steps that report messages rather than counts (the
residual loop of :mod:`damper.diagnosis`).
"""

from __future__ import annotations

import sys
import time
from typing import Callable, TextIO

__all__ = ["progress_bar", "progress_lines", "LineProgress", "is_terminal"]


def is_terminal(stream: TextIO | None) -> bool:
    """Whether ``stream`` is an interactive terminal (False for files, pipes and closed streams).

    Parameters
    ----------
    stream : TextIO | None
        Stream to write to; None: standard error.
    """
    try:
        return bool(stream is not None and stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def _duration(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


class LineProgress:
    """The non-terminal progress display: one line per :meth:`update`, flushed at once.

    Has the part of tqdm's interface the project uses (``update``, ``set_postfix_str``,
    ``write``, ``close``, use as a context manager), so callers do not care which they got.

    Parameters
    ----------
    total : int | None
        Number of steps expected; None: unknown.
    desc : str, optional
        Text at the start of each line.
    unit : str, optional
        Name of a step (``"step"``, ``"run"``).
    initial : int, optional
        Steps already done (a resumed run).
    stream : TextIO | None, optional
        Stream to write to; None: standard error.
    """

    def __init__(self, total: int | None, desc: str = "", unit: str = "step", initial: int = 0,
                 stream: TextIO | None = None) -> None:
        self.total = None if total is None else int(total)
        self.desc = desc
        self.unit = unit
        self.n = int(initial)
        self._initial = int(initial)
        self._postfix = ""
        self._stream = stream
        self._start = time.monotonic()
        self._closed = False

    @property
    def stream(self) -> TextIO:
        return self._stream if self._stream is not None else sys.stderr

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:  # noqa: ARG002 - tqdm's signature
        """Text appended to the next line (what the step was).

        Parameters
        ----------
        text : str, optional
            Text to append.
        refresh : bool, optional
            Accepted for tqdm compatibility; the line is printed at the next update anyway.
        """
        self._postfix = str(text)

    def write(self, message: str) -> None:
        """A message line of its own.

        Parameters
        ----------
        message : str
            The line.
        """
        print(message, file=self.stream, flush=True)

    def update(self, n: int = 1) -> None:
        """Count ``n`` more steps and print one line.

        Parameters
        ----------
        n : int, optional
            Steps done since the last call.
        """
        self.n += int(n)
        elapsed = time.monotonic() - self._start
        units = self.unit if self.unit.endswith("s") else self.unit + "s"
        head = f"{self.desc}: " if self.desc else ""
        if self.total:
            line = f"{head}{self.n}/{self.total} {units} ({100.0 * self.n / self.total:.0f} %), " \
                   f"{_duration(elapsed)} elapsed"
            done = self.n - self._initial
            if 0 < done and self.n < self.total:
                line += f", ~{_duration(elapsed / done * (self.total - self.n))} left"
        else:
            line = f"{head}{self.n} {units}, {_duration(elapsed)} elapsed"
        if self._postfix:
            line += f"; {self._postfix}"
        self.write(line)

    def close(self) -> None:
        """Stop printing (later updates are ignored)."""
        self._closed = True

    def __enter__(self) -> "LineProgress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class _Disabled(LineProgress):
    def update(self, n: int = 1) -> None:
        self.n += int(n)

    def write(self, message: str) -> None:
        pass


def progress_bar(total: int | None, desc: str = "", unit: str = "step", enabled: bool = True,
                 initial: int = 0, stream: TextIO | None = None, leave: bool = True):
    """A progress display on ``stream`` (default stderr): tqdm on a terminal, lines otherwise.

    Parameters
    ----------
    total : int or None
        Number of steps (None: unknown).
    desc, unit : str
        Label of the display and name of one step.
    enabled : bool
        False gives a display that shows nothing (same interface).
    initial : int
        Steps already done (a resumed run).
    stream : file-like, optional
        Where to write; default ``sys.stderr`` at the time of each write.
    leave : bool
        Keep tqdm's bar on the terminal after it closes.

    Returns
    -------
    tqdm.tqdm or LineProgress
        Both have ``update(n)``, ``set_postfix_str(text)`` and ``close()`` (tqdm's ``write``
        goes to stdout unless given ``file=``: print messages to stderr yourself).
    """
    if not enabled:
        return _Disabled(total, desc, unit, initial, stream)
    target = stream if stream is not None else sys.stderr
    if is_terminal(target):
        from tqdm import tqdm

        return tqdm(total=total, desc=desc, unit=unit, initial=initial, file=target, leave=leave,
                    dynamic_ncols=True)
    return LineProgress(total, desc, unit, initial, stream)


def progress_lines(prefix: str = "", stream: TextIO | None = None) -> Callable[[str], None]:
    """A callable that prints each progress message as one flushed line on ``stream`` (stderr).

    Each line starts with ``prefix`` and the time since the callable was made, e.g.
    ``diagnosis [12 s]: round 1: tried ...``.

    Parameters
    ----------
    prefix : str, optional
        Text put before each message.
    stream : TextIO | None, optional
        Stream to write to; None: standard error.
    """
    start = time.monotonic()

    def say(message: str) -> None:
        head = f"{prefix} " if prefix else ""
        print(f"{head}[{_duration(time.monotonic() - start)}] {message}",
              file=stream if stream is not None else sys.stderr, flush=True)

    return say
