"""Interrupting an ensemble (kill -9, Ctrl-C) and resuming it: no finished run is redone and
the results equal those of an uninterrupted run, bit for bit."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from benchmark.applications.ensemble import EnsembleConfig, journal_path, read_ensemble, run_ensemble
from benchmark.applications.ensemble_journal import Journal

TOML = """
run = "probe"
base_seed = 11
controllers = ["a", "b", "c", "d"]
records = ["kobe", "elcentro", "sylmar"]
[grid]
"probe.delay" = [0.08]
"""


def _start(tmp_path: Path, jobs: int, preexec_fn=None) -> tuple[subprocess.Popen, Path, Path]:
    cfg = tmp_path / "int.toml"
    cfg.write_text(TOML)
    out = tmp_path / "int.h5"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "benchmark", "ensemble", "--config", str(cfg),
                             "--out", str(out), "--jobs", str(jobs), "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, preexec_fn=preexec_fn)
    return proc, cfg, out


def _wait_for_lines(path: Path, n: int, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists() and path.read_bytes().count(b"\n") >= n:
            return
        if proc.poll() is not None:
            pytest.fail(f"ensemble ended early: {proc.stderr.read().decode()}")
        time.sleep(0.02)
    proc.kill()
    pytest.fail("ensemble did not write its journal in time")


def _check_resume(tmp_path: Path, cfg: Path, out: Path) -> None:
    config = EnsembleConfig.from_toml(cfg)
    n_cases = len(config.cases())
    journaled = Journal(journal_path(out), {"base_seed": 11, "run": "probe"}).entries
    assert 0 < len(journaled) < n_cases
    summary = run_ensemble(config, out, jobs=2, progress=False)
    assert summary.n_resumed == len(journaled)
    assert summary.n_run == n_cases - len(journaled) and summary.complete
    reference = run_ensemble(config, tmp_path / "reference.h5", jobs=1, progress=False)
    assert reference.complete
    a, b = read_ensemble(out), read_ensemble(tmp_path / "reference.h5")
    assert list(a.cases["key"]) == list(b.cases["key"])
    for name in b.results:
        assert a.results[name].tobytes() == b.results[name].tobytes(), name
    # elapsed times of the runs finished before the kill are the journaled ones (not redone)
    keys = list(a.cases["key"])
    for key, entry in journaled.items():
        assert a.cases["elapsed_s"][keys.index(key)] == entry.elapsed_s


def test_kill_9_then_resume(tmp_path):
    proc, cfg, out = _start(tmp_path, jobs=2)
    _wait_for_lines(journal_path(out), 5, proc)  # header + 4 runs
    children = _children(proc.pid)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    # the workers end with their parent (they had run on, 145 MB each, until killed by hand)
    deadline = time.monotonic() + 15
    while any(os.path.exists(f"/proc/{c}") for c in children) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert children and not [c for c in children if os.path.exists(f"/proc/{c}")]
    # simulate the worst moment of death: a half-written line at the end of the journal
    with open(journal_path(out), "ab") as fh:
        fh.write(b"0badc0de {\"key\": \"record=kobe")
    _check_resume(tmp_path, cfg, out)


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (Linux /proc)."""
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    if int(fh.read().rsplit(")", 1)[1].split()[1]) == pid:
                        out.append(int(entry))
            except (OSError, ValueError, IndexError):
                pass
    return out


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_writes_partial_results_then_resume(tmp_path, sigint_default, signum):
    # SIGTERM (a scheduler's kill) ends as Ctrl-C does: before, only the journal was current
    proc, cfg, out = _start(tmp_path, jobs=2, preexec_fn=sigint_default)
    _wait_for_lines(journal_path(out), 4, proc)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err.decode()
    assert b"interrupted" in err
    partial = read_ensemble(out)  # written on the way out, from the journal
    assert not partial.attrs["complete"] and 0 < partial.attrs["n_done"] < partial.n_cases
    _check_resume(tmp_path, cfg, out)
