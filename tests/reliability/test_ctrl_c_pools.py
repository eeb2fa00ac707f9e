"""Ctrl-C always ends the commands that run process pools: exit 130 within 10 s, no traceback.

``sbib compare``, ``sbib ensemble`` and ``sbib identify`` are started as subprocesses in a
session of their own and sent SIGINT at several moments (during the imports, while the pool's
workers run, a moment later) either once or three times 0.25 s apart, to the parent alone or to
the whole process group (what a Ctrl-C at a terminal does). Every time the command must exit
with status 130 within 10 s of the first signal, print no traceback, leave no worker process
behind and leave an existing result file as it was (or complete). Before the fix, repeated
signals hung ``compare`` in its exit-time join of the pool's manager thread.

The default suite runs a few representative cases; the whole matrix is marked slow.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and /proc")

ROOT = Path(__file__).resolve().parents[2]
DEADLINE_S = 10.0

ENSEMBLE_TOML = """
run = "probe"
base_seed = 5
controllers = ["a", "b", "c", "d", "e", "f"]
records = ["kobe", "elcentro", "sylmar", "northridge"]
[grid]
"probe.delay" = [0.2]
"""


def _command(kind: str, tmp_path: Path) -> tuple[list[str], Path]:
    """The command line of ``kind`` and the result file it would write."""
    if kind == "compare":
        out = tmp_path / "compare.h5"
        # all seven records: long enough (14 runs) that the command is still running when the
        # signals come, however fast the machine (with two records it could end first)
        args = ["compare", "--records", "all", "--orientations", "FN-x",
                "--controllers", "passive-off,clipped-optimal", "--jobs", "2", "--no-progress", "--out", str(out)]
    elif kind == "ensemble":
        cfg = tmp_path / "ens.toml"
        cfg.write_text(ENSEMBLE_TOML)
        out = tmp_path / "ens.h5"
        args = ["ensemble", "--config", str(cfg), "--out", str(out), "--jobs", "2", "--no-progress"]
    elif kind == "identify":
        out = tmp_path / "identify" / "summary.json"
        args = ["identify", "--out", str(out.parent), "--no-plots", "--records", "kobe", "--orientations",
                "FN-x", "--jobs", "2", "--no-free-kappa-x", "--no-ceiling"]
    else:
        raise AssertionError(kind)
    return [sys.executable, "-m", "benchmark", *args], out


def _children(pid: int) -> list[int]:
    """Child process ids of ``pid`` (Linux /proc; empty elsewhere)."""
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return found


def _wait_for_workers(proc: subprocess.Popen, n: int, timeout: float = 240.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"the command ended before its workers started: {proc.stderr.read().decode()[-2000:]}")
        if len(_children(proc.pid)) >= n:
            return
        time.sleep(0.05)
    pytest.fail("the command's worker processes did not start in time")


def _interrupt(kind: str, tmp_path: Path, preexec_fn, moment: str, signals: int, group: bool) -> None:
    cmd, out = _command(kind, tmp_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    previous = b"a previous result file: must stay whole\n"
    out.write_bytes(previous)
    env = dict(os.environ, PYTHONUNBUFFERED="1", PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(cmd, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env,
                            preexec_fn=preexec_fn, start_new_session=True)
    try:
        if moment == "imports":
            time.sleep(0.3)
        else:
            _wait_for_workers(proc, 2)
            if moment == "running-later":
                time.sleep(1.5)
        workers = _children(proc.pid)
        if proc.poll() is not None:
            pytest.fail(f"{kind} ended (exit {proc.returncode}) before the first SIGINT: the test's command is "
                        "too short for this machine")
        t0 = time.monotonic()
        for i in range(signals):
            if i:
                time.sleep(0.25)
            try:
                (os.killpg if group else os.kill)(proc.pid, signal.SIGINT)
            except ProcessLookupError:  # already ended after an earlier signal
                break
        try:
            _, err = proc.communicate(timeout=DEADLINE_S - (time.monotonic() - t0))
        except subprocess.TimeoutExpired:
            pytest.fail(f"{kind}: still running {DEADLINE_S} s after the first of {signals} SIGINT "
                        f"({moment}, {'group' if group else 'parent'})")
        elapsed = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = err.decode(errors="replace")
    assert proc.returncode == 130, f"exit {proc.returncode} after {elapsed:.1f} s:\n{text[-3000:]}"
    assert not re.search(r"Traceback|Exception ignored|\w+Error\b", text), text[-3000:]
    assert "interrupted" in text
    # no worker left behind
    time.sleep(0.2)
    alive = [w for w in workers if Path(f"/proc/{w}").exists() and "zombie" not in _state(w)]
    assert not alive, f"worker processes still alive: {alive}"
    # the result file: the previous one, or a complete new one; no temporary file left
    assert not [p for p in out.parent.iterdir() if ".partial-" in p.name]
    if kind != "ensemble":  # the ensemble writes its finished runs on the way out (a complete file)
        assert out.read_bytes() == previous


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/status").read_text().lower()
    except OSError:
        return "zombie"


@pytest.mark.parametrize("moment, signals, group", [
    ("imports", 1, False),
    ("running", 1, True),
    ("running", 3, False),
    ("running-later", 3, True),
])
def test_compare_ends_on_ctrl_c(tmp_path, sigint_default, moment, signals, group):
    _interrupt("compare", tmp_path, sigint_default, moment, signals, group)


@pytest.mark.parametrize("kind", ["ensemble", "identify"])
def test_pool_commands_end_on_repeated_ctrl_c(tmp_path, sigint_default, kind):
    _interrupt(kind, tmp_path, sigint_default, "running", 3, True)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["compare", "ensemble", "identify"])
@pytest.mark.parametrize("moment", ["imports", "running", "running-later"])
@pytest.mark.parametrize("signals", [1, 2, 3])
@pytest.mark.parametrize("group", [False, True])
def test_every_pool_command_ends_on_ctrl_c(tmp_path, sigint_default, kind, moment, signals, group):
    _interrupt(kind, tmp_path, sigint_default, moment, signals, group)
