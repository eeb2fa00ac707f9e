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


def test_warm_up_runs_the_smoke_study_in_a_directory_it_removes(monkeypatch, capsys):
    import benchmark.applications.cli_study as cli_study
    seen = {}

    def fake_study(out, quick=False, **_):
        seen["out"], seen["quick"] = out, quick
        (__import__("pathlib").Path(out) / "summary.json").write_text("{}")
        print("a table nobody needs at set-up")
        return {}

    monkeypatch.setattr(cli_study, "run_study", fake_study)
    assert main(["warm-up"]) == 0
    assert seen["quick"] is True
    assert not __import__("pathlib").Path(seen["out"]).exists()
    out = capsys.readouterr().out
    assert "kernels compiled" in out and "a table nobody needs" not in out


def test_warm_up_fails_when_the_smoke_run_fails(monkeypatch):
    import benchmark.applications.cli_study as cli_study
    from benchmark.foundation.errors import NumericalError

    def broken(out, quick=False, **_):
        raise NumericalError("kernel returned NaN")

    monkeypatch.setattr(cli_study, "run_study", broken)
    assert main(["warm-up"]) != 0
