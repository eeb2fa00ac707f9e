"""The main job (``sbib study --quick``) runs end to end and writes every step's outputs."""

from __future__ import annotations

import json

import pytest

from benchmark.applications.cli import main


@pytest.mark.slow
def test_quick_study_writes_every_step(tmp_path, shared_dir, capsys):
    out = tmp_path / "results"
    assert main(["study", "--out", str(out), "--quick"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["steps"]) == {"records", "suite", "identification", "diagnosis"}
    assert (out / "suite" / "comparison.h5").is_file()
    assert (out / "identification" / "parameters.csv").is_file()
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "suite/comparison.json" in report and "identification/parameters.csv" in report
    virtual = summary["steps"]["diagnosis"]["virtual"]
    assert [e["name"] for e in virtual["effects"]] == ["stiffness"]
    assert virtual["error_after"] < virtual["error_before"]
    assert "main job finished" in capsys.readouterr().out
