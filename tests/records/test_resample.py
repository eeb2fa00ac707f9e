"""Resampling a record (records.resample) and ``sbib records resample`` (issue 22)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from records import load_record
from records.record import Record
from records.resample import resample


def _sine(dt: float, hz: float, seconds: float = 8.0, amplitude: float = 2.0) -> Record:
    t = np.arange(int(round(seconds / dt)) + 1) * dt
    return Record("sine", dt, amplitude * np.sin(2 * np.pi * hz * t), labels=("x",), source="synthetic: sine",
                  synthetic=True)


def test_a_finer_step_interpolates_linearly_between_the_samples():
    rec = Record("ramp", 0.02, np.column_stack([np.arange(11.0), -2 * np.arange(11.0)]), labels=("x", "y"))
    fine = resample(rec, 0.005)
    assert fine.dt == 0.005 and fine.n_samples == 41 and fine.labels == ("x", "y")
    np.testing.assert_allclose(fine.acceleration[:, 0], np.arange(41) / 4, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fine.acceleration[::4], rec.acceleration, rtol=0, atol=1e-12)
    assert "linear interpolation from 0.02 s to 0.005 s" in fine.metadata["resampled"]
    assert resample(rec, 0.02) is rec


def test_a_coarser_step_filters_what_would_alias():
    # 2 Hz survives a 0.02-s step (Nyquist 25 Hz); 40 Hz, above it, is removed instead of folding to 10 Hz
    low = resample(_sine(0.002, 2.0), 0.02)
    assert np.max(np.abs(low.acceleration[50:-50])) == pytest.approx(2.0, rel=0.01)
    high = resample(_sine(0.002, 40.0), 0.02)
    assert np.max(np.abs(high.acceleration[50:-50])) < 0.05
    assert "low-pass" in high.metadata["resampled"] and high.metadata["resampled_from_dt_s"] == 0.002


@pytest.mark.parametrize("step, match", [(0.0, "positive"), (-0.01, "positive"), (float("nan"), "positive"),
                                         ("x", "positive"), (100.0, "longer than the record")])
def test_bad_steps_are_refused(step, match):
    with pytest.raises(InputError, match=match):
        resample(_sine(0.01, 1.0), step)


def test_cli_writes_units_and_provenance_and_reads_back(shared_dir, tmp_path, capsys):
    src = shared_dir / "records" / "raw" / "SLAMMER" / "Kobe_Japan_1995" / "KJM-000"
    out = tmp_path / "kjm.csv"
    assert main(["records", "resample", str(src), "--dt", "0.02", "--units", "g", "--step", "0.005",
                 "--out", str(out)]) == 0
    assert "2238 samples at 0.02 s -> 8949 samples at 0.005 s" in capsys.readouterr().out
    text = out.read_text().splitlines()
    assert text[0].startswith("# ground motion: KJM-000; source: ") and str(src) in text[0]
    assert any(line.startswith("# resampled by sbib records resample: linear interpolation") for line in text)
    assert any(line.startswith("# provenance: package=sbib") and "git_commit=" in line for line in text)
    assert "time [s],KJM-000 [g]" in text
    back = load_record(out)
    assert back.dt == pytest.approx(0.005) and back.metadata["units_in_file"] == "g"
    original = load_record(src, dt=0.02, units="g")
    np.testing.assert_allclose(back.acceleration[::4, 0], original.acceleration[:, 0], rtol=1e-9, atol=1e-12)
    # another unit on request
    assert main(["records", "resample", str(src), "--dt", "0.02", "--step", "0.01", "--out-units", "m/s2",
                 "--out", str(tmp_path / "kjm-si.csv")]) == 0
    assert "KJM-000 [m/s2]" in (tmp_path / "kjm-si.csv").read_text()
    # and it reads back: the comment naming the original's units is not a statement of the file's
    # (it was refused: "the header says 'm/s2' but a comment says 'g'")
    si = load_record(tmp_path / "kjm-si.csv")
    assert si.metadata["units_in_file"] == "m/s2"
    np.testing.assert_allclose(si.acceleration[::2, 0], original.acceleration[:, 0], rtol=1e-5, atol=1e-9)  # SI both


@pytest.mark.parametrize("extra, match", [
    (["--step", "0"], "--step"),
    (["--step", "-1"], "--step"),
    (["--step", "500"], "between 0.0001 and 0.05"),
    (["--step", "0.01", "--out-units", "furlong"], "--out-units"),
])
def test_cli_refuses_bad_input_in_one_line_and_writes_nothing(records_dir, tmp_path, capsys, extra, match):
    out = tmp_path / "x.csv"
    assert main(["records", "resample", "kobe", "--records-dir", str(records_dir), "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and match in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_cli_refuses_to_overwrite_its_input(tmp_path, capsys):
    src = tmp_path / "rec.csv"
    src.write_text("time [s],ax [g]\n0,0\n0.01,0.1\n0.02,0\n0.03,-0.1\n")
    before = src.read_text()
    assert main(["records", "resample", str(src), "--step", "0.005", "--out", str(src)]) == 2
    assert "input record itself" in capsys.readouterr().err
    assert src.read_text() == before


@pytest.mark.parametrize("step", ["1e-7", "5"])
def test_resample_refuses_steps_no_accelerograph_has(tmp_path, capsys, step):
    """1e-7 s wrote 3e8 rows for minutes; 5 s kept 6 samples of kobe (and sbib run then called
    the file implausible): both are refused before any work, in one line."""
    out = tmp_path / "r.csv"
    assert main(["records", "resample", "kobe", "--step", step, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "between 0.0001 and 0.05" in err and "\n" not in err and not out.exists()
