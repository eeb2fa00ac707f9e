"""Progress in logs (issue #16 item 11): one line per step when stderr is not a terminal."""

from __future__ import annotations

import io
import os
import subprocess
import sys

from benchmark.foundation.progress import LineProgress, progress_bar, progress_lines


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_lines_when_not_a_terminal():
    stream = io.StringIO()
    bar = progress_bar(4, desc="compare", unit="run", stream=stream)
    assert isinstance(bar, LineProgress)
    for k in range(4):
        bar.set_postfix_str(f"case {k}")
        bar.update()
    bar.close()
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert len(lines) == 4 and text.endswith("\n")
    assert lines[0].startswith("compare: 1/4 runs (25 %)") and lines[0].endswith("case 0")
    assert "left" in lines[1] and lines[-1].startswith("compare: 4/4 runs (100 %)")


def test_bar_on_a_terminal_and_nothing_when_disabled():
    stream = _Terminal()
    bar = progress_bar(3, desc="x", stream=stream)
    assert type(bar).__module__.startswith("tqdm")
    bar.update(3)
    bar.close()
    assert "\r" in stream.getvalue()
    quiet = io.StringIO()
    off = progress_bar(3, enabled=False, stream=quiet)
    off.update()
    off.write("hello")
    assert quiet.getvalue() == ""


def test_progress_lines_prefix_and_flush():
    stream = io.StringIO()
    say = progress_lines("diagnosis", stream=stream)
    say("round 1")
    say("round 2")
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and lines[0].startswith("diagnosis [") and lines[1].endswith("round 2")


def test_ensemble_progress_in_a_log_is_one_line_per_run(tmp_path):
    """End to end: ``sbib ensemble`` with stderr to a file writes a line per run, no redraws."""
    cfg = tmp_path / "p.toml"
    cfg.write_text('run = "probe"\nbase_seed = 3\ncontrollers = ["a", "b"]\nrecords = ["kobe", "elcentro"]\n')
    log = tmp_path / "log.txt"
    with open(log, "w") as err:
        proc = subprocess.run([sys.executable, "-m", "benchmark", "ensemble", "--config", str(cfg),
                               "--out", str(tmp_path / "p.h5"), "--jobs", "1"],
                              stdout=subprocess.PIPE, stderr=err, timeout=300,
                              env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert proc.returncode == 0, log.read_text()
    text = log.read_text()
    assert "\r" not in text
    runs = [line for line in text.splitlines() if " runs (" in line]
    n = int(runs[-1].split("/")[1].split()[0])
    assert n >= 4 and len(runs) == n, text


def test_study_diagnosis_step_reports_progress(tmp_path, monkeypatch, capsys):
    """The diagnosis step of ``sbib study`` passes a progress callable that prints lines."""
    import damper.diagnosis
    import damper.diagnosis.report
    from benchmark.applications import study

    seen = []

    class _Done:
        def to_json(self):
            return {}

    def fake_diagnose(tests, model, progress=None, **kwargs):
        assert progress is not None, "diagnose called without progress"
        progress("round 1: tried stiffness")
        seen.append(model)
        return _Done()

    monkeypatch.setattr(study, "diagnose", fake_diagnose)
    monkeypatch.setattr(study, "write_diagnosis_report", lambda d, folder: {})
    study._diagnosis(tmp_path / "diagnosis", quick=True)
    err = capsys.readouterr().err
    assert seen and "round 1: tried stiffness" in err and "diagnosis" in err
