"""The shared infrastructure: errors, atomic writes, CLI error handling."""

from __future__ import annotations

import pytest

from benchmark.foundation.atomic import atomic_path, atomic_write_text
from benchmark.applications.cli import main
from benchmark.foundation.errors import NumericalError


def test_atomic_write_replaces_only_on_success(tmp_path):
    dest = tmp_path / "out.txt"
    atomic_write_text(dest, "old")
    with pytest.raises(RuntimeError):
        with atomic_path(dest) as tmp:
            tmp.write_text("half-written")
            raise RuntimeError("interrupted")
    assert dest.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_numerical_error_names_time_state_and_hint():
    err = NumericalError("state blew up", time=1.25, state={"w": float("nan")}, hint="reduce the tolerance")
    text = str(err)
    assert "1.25" in text and "w=nan" in text and "reduce the tolerance" in text


def test_cli_without_command_prints_help_and_fails(capsys):
    assert main([]) == 2
    assert "usage" in capsys.readouterr().out.lower()


def test_cli_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert "sbib" in capsys.readouterr().out


def test_atomic_write_respects_umask(tmp_path):
    import os
    import stat
    old = os.umask(0o022)
    try:
        path = atomic_write_text(tmp_path / "r.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
