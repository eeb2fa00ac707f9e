"""The benchmark catalogue: names, orientations, directory lookup, flaws of the distributed files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError
from records import (BENCHMARK_RECORDS, CATALOGUE, ORIENTATIONS, canonical_name, check_catalogue,
                     load_benchmark_record)
from records.measures import mean_period, significant_duration
from records.readers import read_benchmark

DOMAIN_PGA_G = {"newhall": (0.736, 0.656), "sylmar": (0.875, 0.605), "elcentro": (0.313, 0.215),
                "rinaldi": (0.840, 0.476), "kobe": (0.841, 0.631), "jiji": (0.512, 0.369),
                "erzikan": (0.515, 0.496)}


def test_names_aliases_orientations():
    assert BENCHMARK_RECORDS == ("newhall", "sylmar", "elcentro", "rinaldi", "kobe", "jiji", "erzikan")
    assert ORIENTATIONS == ("FN-x", "FP-x")
    assert canonical_name("Erzincan") == "erzikan" and canonical_name("KOBE.txt") == "kobe"
    with pytest.raises(InputError, match="'loma' is not a benchmark record; expected one of newhall"):
        canonical_name("loma")
    for name, pga in DOMAIN_PGA_G.items():
        assert CATALOGUE[name].pga_g == pga


def test_orientations_put_the_right_column_on_x(records_dir):
    raw = read_benchmark(records_dir / "kobe.txt")
    fn = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    fp = load_benchmark_record("kobe", "FP-x", records_dir=records_dir)
    assert np.array_equal(fn.acceleration, raw.acceleration)
    assert np.array_equal(fp.acceleration[:, 0], raw.acceleration[:, 1])
    assert np.array_equal(fp.acceleration[:, 1], raw.acceleration[:, 0])
    assert fn.labels == ("N-S (FN)", "E-W (FP)") and fp.labels == ("E-W (FP)", "N-S (FN)")
    assert fp.metadata["x_file_column"] == 2 and fp.metadata["orientation"] == "FP-x"
    assert fn.dt == 0.005 and not fn.synthetic
    assert fn.pga_g[0] == pytest.approx(0.841, abs=5e-4)
    with pytest.raises(InputError, match="orientation 'NS-x'"):
        load_benchmark_record("kobe", "NS-x", records_dir=records_dir)


def test_erzincan_alias_and_flaws_in_metadata(records_dir):
    rec = load_benchmark_record("erzincan", records_dir=records_dir)
    assert rec.name == "erzikan" and rec.duration == pytest.approx(21.3)
    assert any("last 105 samples" in f for f in rec.metadata["flaws"])


def test_missing_directory_and_file_are_named(tmp_path, monkeypatch):
    with pytest.raises(DataNotFoundError, match=f"kobe.txt not found in {tmp_path}"):
        load_benchmark_record("kobe", records_dir=tmp_path)
    with pytest.raises(DataNotFoundError, match="does-not-exist"):
        load_benchmark_record("kobe", records_dir=tmp_path / "does-not-exist")
    monkeypatch.setenv("SBIB_RECORDS_DIR", str(tmp_path))
    with pytest.raises(DataNotFoundError, match=f"{tmp_path}.*SBIB_RECORDS_DIR"):
        load_benchmark_record("sylmar")


def test_environment_variable_lookup(records_dir, monkeypatch):
    monkeypatch.setenv("SBIB_RECORDS_DIR", str(records_dir))
    source = Path(load_benchmark_record("elcentro").source)
    assert source.resolve() == (records_dir / "elcentro.txt").resolve()  # shared/ may be a symlink


def test_catalogue_check_of_the_distributed_files(records_dir):
    report = check_catalogue(records_dir)
    assert report["error"] is None and report["n_found"] == 7
    flaws = {}
    for item in report["records"]:
        assert item["found"], item["name"]
        assert np.allclose(item["pga_g"], DOMAIN_PGA_G[item["name"]], atol=6e-4), item["name"]
        assert item["dt_s"] == 0.005
        assert item["duration_s"] == pytest.approx(90.0 if item["name"] == "jiji" else
                                                   21.3 if item["name"] == "erzikan" else 30.0)
        flaws[item["name"]] = [(f["kind"], f["component"]) for f in item["flaws"]]
        assert all(f["known"] for f in item["flaws"])
    assert flaws == {"newhall": [], "sylmar": [], "elcentro": [], "kobe": [],
                     "rinaldi": [("baseline_drift", 1)],
                     "jiji": [("baseline_drift", 0), ("baseline_drift", 1)],
                     "erzikan": [("identical_components", None)]}
    erz = next(i for i in report["records"] if i["name"] == "erzikan")
    assert erz["flaws"][0]["details"] == {"start": 4155, "stop": 4260, "n_samples": 105}


def test_catalogue_check_without_data(tmp_path):
    report = check_catalogue(tmp_path / "absent")
    assert report["n_found"] == 0 and "absent" in report["error"]
    assert [i["found"] for i in report["records"]] == [False] * 7
    (tmp_path / "kobe.txt").write_text("%h\n1 2\n3 x\n")
    report = check_catalogue(tmp_path)
    kobe = next(i for i in report["records"] if i["name"] == "kobe")
    assert kobe["found"] and "'x' is not a number" in kobe["error"]


def test_catalogue_measures_were_measured_on_the_files(records_dir):
    """D5-95 and mean period in the catalogue are those of the files (rounded), as its docstring says."""
    for name, entry in CATALOGUE.items():
        rec = read_benchmark(records_dir / entry.file)
        for c in range(2):
            a = rec.acceleration[:, c]
            assert significant_duration(a, rec.dt) == pytest.approx(entry.significant_duration_s[c], abs=0.006)
            assert mean_period(a, rec.dt) == pytest.approx(entry.mean_period_s[c], abs=6e-4)
        assert np.allclose(rec.pgv, entry.pgv_m_s, atol=6e-4)
        from records.baseline import baseline_correct

        assert np.allclose(baseline_correct(rec).pgd, entry.pgd_m, atol=6e-4)
        assert rec.n_samples == entry.n_samples


@pytest.mark.slow
def test_catalogue_pulse_periods_were_measured_on_the_files(records_dir):
    from records.pulse import fit_pulse

    for name, entry in CATALOGUE.items():
        if entry.pulse_period_s[0] is None:
            continue
        rec = read_benchmark(records_dir / entry.file)
        fit = fit_pulse(rec.velocity()[:, 0], rec.dt)
        assert fit.period == pytest.approx(entry.pulse_period_s[0], abs=0.006 if fit.period < 10 else 0.06), name
