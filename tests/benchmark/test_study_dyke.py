"""``sbib study --dyke``: the main job's diagnosis adds the shared Dyke recording (Spencer base, 30 %
held out, the time budget, its screening in the report); without the option it is not run (its
base fit alone is about half a minute of one core). The loops themselves are stubbed: they are
tested in tests/damper."""

from __future__ import annotations

import argparse
from types import SimpleNamespace

import benchmark.applications.study as study
from benchmark.applications import cli_study


def test_dyke_case_is_run_only_on_request(monkeypatch, tmp_path, shared_dir):
    if not (shared_dir / study.DYKE_RECORDING).is_file():
        import pytest
        pytest.skip("the shared Dyke recording is absent")
    calls, written = [], {}

    def fake_diagnose(tests, model="normalized", **options):
        calls.append((tests, model, options))
        return SimpleNamespace(to_json=lambda: {"model": model, "n_tests": len(tests)})

    def fake_write(diagnosis, folder, tests=None, keep_flagged=False):
        written[folder.name] = tests

    monkeypatch.setattr(study, "diagnose", fake_diagnose)
    monkeypatch.setattr(study, "write_diagnosis_report", fake_write)
    result = study._diagnosis(tmp_path / "a", quick=False)
    assert "dyke" not in result and "dyke" not in written
    calls.clear()
    result = study._diagnosis(tmp_path / "b", quick=False, dyke=True)
    tests, model, options = calls[-1]
    assert model == "spencer" and options["holdout"] == 0.3
    assert options["time_budget"] == study.DYKE_TIME_BUDGET
    assert len(tests) == 1 and tests[0].metadata.get("screening") is not None   # screened when read
    assert written["dyke"] == tests                                             # its screening is reported
    assert result["dyke"] == {"model": "spencer", "n_tests": 1}
    if "utfsm_1A" in written:                                                  # the UTFSM tests' screening too
        assert written["utfsm_1A"] and all(t.metadata.get("screening") for t in written["utfsm_1A"])


def test_cli_passes_the_option(monkeypatch, tmp_path, capsys):
    seen = {}

    def fake_run_study(out, records_dir=None, quick=False, dyke=False):
        seen.update(dyke=dyke)
        return {"elapsed_s": 1.0, "steps": {}, "report": str(tmp_path / "report.html")}

    monkeypatch.setattr(cli_study, "run_study", fake_run_study)
    args = argparse.Namespace(out=str(tmp_path), records_dir=None, quick=True, dyke=True)
    assert cli_study._run(args) == 0 and seen["dyke"] is True
