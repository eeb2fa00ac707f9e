"""J labels and keys (issue #16 item 7): one definition table (benchmark.simulator.criteria) behind every
table, figure and JSON that shows J's; J6 and J9 are not called ratios to the uncontrolled run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from benchmark.simulator import criteria
from benchmark.applications.comparison import ComparisonResult, ComparisonRun

ROOT = Path(__file__).resolve().parents[2]
RATIOS = {"J1", "J2", "J3", "J4", "J5", "J7", "J8"}


def _result() -> ComparisonResult:
    runs = []
    for k, (rec, ori) in enumerate([("kobe", "FN-x"), ("elcentro", "FP-x")]):
        for name in ("passive-on", "skyhook"):
            J = {f"J{i}": 0.5 + 0.05 * i + 0.01 * k for i in range(1, 10)}
            t = np.arange(0, 2, 0.02)
            hist = {"t": t, "base_displacement": np.zeros((t.size, 2)), "device_force_total": np.zeros((t.size, 2)),
                    "voltage": np.zeros((t.size, 3))}
            runs.append(ComparisonRun(rec, ori, name, J, {"peak_base_displacement": 0.1}, hist))
    return ComparisonResult(runs=runs, references={})


def test_one_definition_table():
    from benchmark.simulator import evaluation
    from benchmark.applications import comparison, comparison_plots

    assert criteria.J_NAMES == tuple(f"J{i}" for i in range(1, 10))
    assert evaluation.J_NAMES == criteria.J_NAMES and comparison.J_NAMES == criteria.J_NAMES
    assert comparison_plots.J_NAMES == criteria.J_NAMES
    assert evaluation.J_DESCRIPTIONS == {k: c.description for k, c in criteria.CRITERIA.items()}
    assert {k for k in criteria.J_NAMES if criteria.is_ratio(k)} == RATIOS
    for k, c in criteria.CRITERIA.items():
        assert c.name and c.formula and "Narasimhan" in c.source, k
    assert criteria.CRITERIA["J6"].choice and criteria.CRITERIA["J9"].choice


@pytest.fixture
def saved(monkeypatch):
    """Texts of every saved figure: axis labels per J panel, figure-level texts."""
    seen = []
    original = Figure.savefig

    def savefig(self, *args, **kwargs):
        seen.append({"axes": [(ax.get_title(), ax.get_ylabel()) for ax in self.axes],
                     "text": [t.get_text() for t in self.texts]
                     + ([self._suptitle.get_text()] if self._suptitle else [])})
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return seen


def test_figures_label_each_J_for_what_it_is_and_carry_a_key(tmp_path, saved):
    from benchmark.applications.comparison_plots import plot_J_by_record, plot_J_summary

    result = _result()
    plot_J_by_record(result, tmp_path / "a.png")
    plot_J_summary(result, tmp_path / "b.png")
    by_record, summary = saved
    panels = {title: ylabel for title, ylabel in by_record["axes"] if title}
    assert set(panels) == set(criteria.J_NAMES)
    for j, ylabel in panels.items():
        assert ("ratio to uncontrolled" in ylabel) == (j in RATIOS), (j, ylabel)
    for fig in (by_record, summary):
        text = "\n".join(fig["text"])
        assert "ratio to the uncontrolled building; 1 = no change)" not in text  # the old blanket label
        for j, c in criteria.CRITERIA.items():
            assert f"{j}: {c.name}" in text, (j, text)
        assert "Narasimhan" in text
    assert not any("ratio to uncontrolled" in ylabel for _, ylabel in summary["axes"])


def test_table_and_json_carry_the_key():
    result = _result()
    table = result.table()
    for j, c in criteria.CRITERIA.items():
        assert f"{j}: {c.name}" in table and c.formula in table
    doc = json.loads(json.dumps(result.to_json()))
    assert set(doc["criteria"]) == set(criteria.J_NAMES)
    assert all({"name", "formula", "normalised_by", "source"} <= set(v) for v in doc["criteria"].values())


def test_criteria_are_documented():
    doc = (ROOT / "docs" / "criteria.md").read_text()
    for j, c in criteria.CRITERIA.items():
        assert f"| {j} " in doc and c.name in doc, j
    assert "Narasimhan" in doc and "own choice" in doc
    assert "docs/criteria.md" in (ROOT / "README.md").read_text()


def _fake_run(case):
    return {"J3": 0.5, "J6": 0.25, "peak_base_displacement": 0.1}


def test_ensemble_results_carry_the_key(tmp_path):
    import dataclasses

    import h5py

    from benchmark.applications.ensemble import EnsembleConfig, run_ensemble

    cfg = tmp_path / "e.toml"
    cfg.write_text('run = "probe"\nbase_seed = 3\ncontrollers = ["a"]\nrecords = ["kobe"]\n')
    config = dataclasses.replace(EnsembleConfig.from_toml(cfg), run=_fake_run)
    run_ensemble(config, tmp_path / "e.h5", progress=False, jobs=1)
    with h5py.File(tmp_path / "e.h5") as f:
        for k in ("J3", "J6"):
            assert f["results"][k].attrs["formula"] == criteria.CRITERIA[k].formula
            assert f["results"][k].attrs["normalised_by"] == criteria.CRITERIA[k].normalised_by
        assert "formula" not in f["results"]["peak_base_displacement"].attrs
