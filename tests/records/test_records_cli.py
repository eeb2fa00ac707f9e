"""``sbib records list | show | generate``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmark.applications.cli import main
from records import load_record


def test_list_shows_all_seven_with_pgas_and_flaws(capsys, records_dir):
    assert main(["records", "list", "--records-dir", str(records_dir)]) == 0
    out = capsys.readouterr().out
    assert "(7 of 7 found)" in out
    for name, pga in (("newhall", "0.736 / 0.656"), ("sylmar", "0.875 / 0.605"), ("elcentro", "0.313 / 0.215"),
                      ("rinaldi", "0.840 / 0.476"), ("kobe", "0.841 / 0.631"), ("jiji", "0.512 / 0.369"),
                      ("erzikan", "0.515 / 0.496")):
        line = next(line for line in out.splitlines() if line.startswith(name))
        assert line.count(pga) == 2, line          # measured and catalogue
    assert "identical components, known): erzikan: the last 105 samples" in out
    assert out.count("flaw (baseline drift, known)") == 3 and "rinaldi 318 (FP)" in out


def test_list_json_and_missing_directory(capsys, tmp_path, records_dir):
    assert main(["records", "list", "--records-dir", str(records_dir), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["n_found"] == 7 and len(doc["records"]) == 7
    assert main(["records", "list", "--records-dir", str(tmp_path / "nowhere")]) == 2
    out = capsys.readouterr().out
    assert "unavailable" in out and out.count("MISSING") == 7


def test_show_prints_peaks_and_writes_a_plot(capsys, records_dir, tmp_path):
    png = tmp_path / "kobe.png"
    assert main(["records", "show", "kobe", "--orientation", "FP-x", "--records-dir", str(records_dir),
                 "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "orientation FP-x (x = file column 2)" in out
    assert "x: E-W (FP)" in out and "0.631" in out and "dt 0.005 s, 6000 samples, duration 30.000 s" in out
    assert png.stat().st_size > 20_000 and png.read_bytes()[:4] == b"\x89PNG"
    assert main(["records", "show", "jiji", "--records-dir", str(records_dir), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["pga_g"] == pytest.approx([0.512, 0.369], abs=6e-4) and doc["duration_s"] == pytest.approx(90.0)
    assert len(doc["flaws"]) == 2 and doc["pgv_m_s"][0] == pytest.approx(2.803, abs=1e-3)


def test_show_a_synthetic_record_and_a_file(capsys, tmp_path):
    assert main(["records", "show", "erzincan", "--synthetic", "--seed", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["synthetic"] and doc["name"] == "synthetic-erzikan" and doc["source"].startswith("synthetic:")
    assert doc["pga_g"] == pytest.approx([0.515, 0.496], rel=1e-9)
    single = tmp_path / "ELC-180"
    single.write_text("\n".join(str(x) for x in 0.1 * np.sin(np.arange(400) * 0.05)) + "\n")
    assert main(["records", "show", str(single), "--dt", "0.01"]) == 0
    assert "PGA" in capsys.readouterr().out


def test_show_errors_are_one_line(capsys, tmp_path):
    single = tmp_path / "ELC-180"
    single.write_text("0.1\n0.2\n")
    assert main(["records", "show", str(single)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sbib: error:") and "give dt (option --dt)" in err and "\n" not in err
    assert main(["records", "show", "loma-prieta"]) == 2
    assert "neither a benchmark record" in capsys.readouterr().err
    assert main(["records", "show", str(single), "--dt", "-0.01"]) == 2
    assert "dt" in capsys.readouterr().err
    assert main(["records", "show", "kobe", "--records-dir", str(tmp_path)]) == 2
    assert f"kobe.txt not found in {tmp_path}" in capsys.readouterr().err
    assert main(["records"]) == 2


def test_generate_writes_a_readable_synthetic_csv(capsys, tmp_path):
    out = tmp_path / "syn.csv"
    assert main(["records", "generate", "newhall", "--seed", "4", "--out", str(out)]) == 0
    assert "SYNTHETIC" in capsys.readouterr().out
    rec = load_record(out)
    assert rec.n_samples == 6000 and rec.dt == pytest.approx(0.005)
    assert rec.pga_g == pytest.approx([0.736, 0.656], rel=1e-8)
    assert rec.labels[0].startswith("synthetic")
