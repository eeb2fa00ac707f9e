"""The device-family table (issue 25 item 5) on the report page and in the example's Markdown."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

from benchmark.applications.report import build_report_html

ROOT = Path(__file__).resolve().parents[2]


def _rows():
    def pair(ratios):
        return {"ratio_by_run": {f"r{i}": r for i, r in enumerate(ratios)}, "ratio_mean": sum(ratios) / len(ratios)}
    return [{"variant": "default", "description": "as calibrated",
             "claim_test": {"seed": pair([1.2, 1.3]), "closed_loop": pair([0.7, 0.9])}},
            {"variant": "no-roll-off", "description": "c1 x100",
             "claim_test": {"seed": pair([0.9, 1.1]), "closed_loop": pair([0.5, 0.6])}}]


def test_report_shows_the_recorded_family_or_the_results_own(tmp_path):
    # no run in the results folder: the recorded run of docs/data, labelled as such
    page = build_report_html(tmp_path)
    assert 'id="device-family"' in page and "recorded run" in page and "no-roll-off-no-lag" in page
    (tmp_path / "device-family").mkdir()
    (tmp_path / "device-family" / "family.json").write_text(json.dumps(_rows()))
    page = build_report_html(tmp_path)
    assert 'id="device-family"' in page and "no-roll-off" in page
    assert "1.25" in page and "0.90–1.10" in page and "1/2" in page and "2/2" in page


def test_example_table():
    spec = importlib.util.spec_from_file_location("device_family", ROOT / "examples" / "device_family.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    text = module.table(_rows())
    assert "| `default`: as calibrated | 1.25 (1.20–1.30) | 0/2 | 0.80 (0.70–0.90) | 2/2 |" in text
    assert set(module.VARIANTS) == set(module.DESCRIPTION)
