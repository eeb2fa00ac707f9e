"""Helpers of the reliability tests: what a "clear error" is, and running ``sbib`` in-process.

A clear error is an :class:`benchmark.foundation.errors.InputError` (or subclass) whose message is one
line, names the file (or field) it is about, and says what was expected; from the command
line it is exit status 2 with exactly one ``sbib: error: ...`` line on stderr.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Callable, Sequence

import pytest

from benchmark.foundation.errors import InputError


def one_line(message: str) -> bool:
    """True when ``message`` would print as a single terminal line."""
    return "\n" not in message and "\r" not in message and message.strip() != ""


def check_clear_error(exc: BaseException, names: Sequence[str] = ()) -> str:
    """Assert ``exc`` is a clear InputError naming one of ``names``; return its message."""
    assert isinstance(exc, InputError), f"{type(exc).__name__} instead of InputError: {exc!r}"
    message = str(exc)
    assert one_line(message), f"error message is not one line: {message!r}"
    if names:
        assert any(str(n) in message for n in names), f"message does not name {list(names)}: {message!r}"
    return message


def run_cli(argv: Sequence[str]) -> tuple[int, str, str]:
    """Run ``sbib argv`` in this process; return (exit status, stdout, stderr).

    ``SystemExit`` (argparse) is turned into its status, as the console script would.
    """
    from benchmark.applications.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(list(argv))
        except SystemExit as exc:  # argparse's own exit (--help, bad option syntax)
            rc = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    return int(rc), out.getvalue(), err.getvalue()


def check_cli_error(rc: int, err: str, names: Sequence[str] = (), status: int = 2,
                    prefix: str = "sbib: error: ") -> str:
    """Assert a CLI failure: ``status``, exactly one stderr line starting with ``prefix``."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert rc == status, f"exit status {rc}, expected {status}; stderr: {err!r}"
    assert len(lines) == 1, f"expected one stderr line, got {len(lines)}: {err!r}"
    assert lines[0].startswith(prefix), f"stderr line does not start with {prefix!r}: {lines[0]!r}"
    assert "Traceback" not in err
    if names:
        assert any(str(n) in lines[0] for n in names), f"message does not name {list(names)}: {lines[0]!r}"
    return lines[0]


@pytest.fixture
def clear_error() -> Callable[..., str]:
    """:func:`check_clear_error` as a fixture."""
    return check_clear_error


@pytest.fixture
def cli() -> Callable[[Sequence[str]], tuple[int, str, str]]:
    """:func:`run_cli` as a fixture."""
    return run_cli


@pytest.fixture
def cli_error() -> Callable[..., str]:
    """:func:`check_cli_error` as a fixture."""
    return check_cli_error


@pytest.fixture
def write_file(tmp_path: Path) -> Callable[[str, str | bytes], Path]:
    """Write text (UTF-8) or bytes to ``tmp_path/name`` and return the path."""
    def _write(name: str, content: str | bytes) -> Path:
        path = tmp_path / name
        path.write_bytes(content.encode("utf-8") if isinstance(content, str) else content)
        return path
    return _write
