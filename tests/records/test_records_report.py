"""The records step of the main job (catalogue.json and figures; synthetic when no file is found)."""

from __future__ import annotations

import json

from records.report import write_records_report


def test_report_with_the_benchmark_files(tmp_path, records_dir):
    summary = write_records_report(tmp_path / "records", records_dir=records_dir, per_record_plots=False)
    assert summary["n_found"] == 7 and not summary["synthetic"]
    assert summary["flaws"] == {"newhall": 0, "sylmar": 0, "elcentro": 0, "rinaldi": 1, "kobe": 0, "jiji": 2,
                                "erzikan": 1}
    doc = json.loads((tmp_path / "records" / "catalogue.json").read_text())
    assert doc["n_found"] == 7 and doc["figures"]["synthetic"] is False
    assert (tmp_path / "records" / "spectra.png").stat().st_size > 10_000


def test_report_without_files_uses_labelled_synthetic_records(tmp_path):
    summary = write_records_report(tmp_path / "out", records_dir=tmp_path / "absent", per_record_plots=False)
    assert summary["synthetic"] and summary["n_found"] == 0
    assert summary["plotted"][0] == "synthetic-newhall" and len(summary["plotted"]) == 7
    doc = json.loads((tmp_path / "out" / "catalogue.json").read_text())
    assert doc["error"] and doc["figures"]["synthetic"] is True
    assert (tmp_path / "out" / "spectra.png").is_file() and not (tmp_path / "out" / "kobe.png").exists()
