"""Record files as users write their headers: units and steps in the words people use.

Each case was a silent misread or a traceback before (a review of the readers, 2026-11-26):
a unit the header spelled otherwise than the old pattern was read as cm/s² (100 or 981 times
off), a ``#`` header or a ``DT:`` step was ignored, a time column under a ``%`` header was read
as an acceleration. Values are compared at 1e-12 relative: they are the file's numbers times an
exact factor (``benchmark/foundation/file_units.py``), no kernel is involved.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from records.readers import detect_format, load_record, read_at2
from records.resolve import resolve_record

G = 9.80665
VALUES = [0.0, 0.1, -0.2, 0.3, -0.15, 0.05, 0.0, 0.02]


def _two_columns(header: str) -> str:
    return header + "".join(f"{v:.6f} {0.5 * v:.6f}\n" for v in VALUES)


@pytest.mark.parametrize("header, factor", [
    ("% acc in mm/s2\n", 1e-3),
    ("% units: g\n", G),
    ("% acc [g]\n", G),
    ("% values in m/s**2\n", 1.0),
    ("% Acc in m/s²\n", 1.0),
    ("% m/sec/sec, dt=0.005 sec\n", 1.0),
    ("# Acceleration in g\n", G),
    ("%Kobe, PGA 0.82 g. Acc. in cm/sec^2 and dt=0.005 sec.\n", 0.01),  # "0.82 g" is a value
])
def test_header_units_in_any_spelling_the_unit_table_knows(tmp_path, header, factor):
    path = tmp_path / "rec.txt"
    path.write_text(_two_columns(header), encoding="utf-8")
    rec = load_record(path, dt=None if "dt=" in header else 0.005)  # two columns: the step stated or given
    np.testing.assert_allclose(rec.acceleration[:, 0], np.array(VALUES) * factor, rtol=1e-12, atol=0)
    assert rec.metadata["units_from"] == "header"


def test_two_units_named_as_the_files_are_refused(tmp_path):
    path = tmp_path / "rec.txt"
    path.write_text(_two_columns("% units: g\n% values in cm/s2\n"), encoding="utf-8")
    with pytest.raises(InputError, match="names two acceleration units"):
        load_record(path)


@pytest.mark.parametrize("header, dt", [("# dt=0.01 s, units: g\n", 0.01), ("% DT: 0.01 s, cm/s2\n", 0.01),
                                        ("% time step = 20 ms\n", 0.02)])
def test_a_step_stated_in_a_comment_header(tmp_path, header, dt):
    path = tmp_path / "rec.txt"
    path.write_text(_two_columns(header), encoding="utf-8")
    assert load_record(path).dt == pytest.approx(dt, rel=1e-12)


def test_a_time_column_under_a_percent_header_that_states_its_step(tmp_path):
    path = tmp_path / "rec.txt"
    path.write_text("% dt=0.01\n" + "".join(f"{0.01 * k:.2f} {v:.6f}\n" for k, v in enumerate(VALUES)))
    assert detect_format(path) == "csv"
    rec = load_record(path)
    assert rec.dt == pytest.approx(0.01) and rec.acceleration.shape[1] == 1
    np.testing.assert_allclose(rec.acceleration[:, 0], VALUES, rtol=1e-12)


def test_peer_header_with_dt_before_npts(tmp_path):
    path = tmp_path / "a.AT2"
    path.write_text("PEER NGA STRONG MOTION DATABASE RECORD\nKOBE 1995, KJMA, 000\n"
                    "ACCELERATION TIME HISTORY. UNITS OF CM/SEC/SEC\nDT= .0100 SEC, NPTS= 4\n"
                    "  1.0  2.0  -3.0  4.0\n")
    rec = read_at2(path)
    assert rec.dt == pytest.approx(0.01) and rec.n_samples == 4
    np.testing.assert_allclose(rec.acceleration[:, 0], [0.01, 0.02, -0.03, 0.04], rtol=1e-12)


@pytest.mark.parametrize("header", ["time [s]\tax [g]\tay [g]", "Time (s)\tAcc X (g)\tAcc Y (g)",
                                    "Time (s)  Acc X (g)  Acc Y (g)", "time [s] ax [g] ay [g]"])
def test_whitespace_separated_data_under_names_with_spaces(tmp_path, header):
    path = tmp_path / "rec.txt"
    path.write_text(header + "\n" + "".join(f"{0.005 * k:.3f}\t{v:.6f}\t{0.5 * v:.6f}\n"
                                            for k, v in enumerate(VALUES)))
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[:, 1], 0.5 * np.array(VALUES) * G, rtol=1e-12)


def test_one_unit_spelled_two_ways_and_a_comment_that_disagrees(tmp_path):
    ok = tmp_path / "ok.csv"
    ok.write_text("time,ax [g],ay [G]\n" + "".join(f"{0.005 * k:.3f},{v},{v}\n" for k, v in enumerate(VALUES)))
    assert load_record(ok).metadata["units_in_file"] == "g"
    bad = tmp_path / "bad.csv"
    bad.write_text("# units: cm/s2\ntime,ax [g]\n" + "".join(f"{0.005 * k:.3f},{v}\n" for k, v in enumerate(VALUES)))
    with pytest.raises(InputError, match="header says 'g' but a comment says 'cm/s2'"):
        load_record(bad)


@pytest.mark.parametrize("rate, decimals", [(300.0, 4), (128.0, 3), (200.0, 3)])
def test_time_stamps_rounded_to_their_printed_digits(tmp_path, rate, decimals):
    n = 500
    path = tmp_path / "rec.csv"
    path.write_text("time [s],ax [g]\n" + "".join(f"{k / rate:.{decimals}f},{math.sin(k / 7):.6f}\n"
                                                  for k in range(n)))
    rec = load_record(path)
    assert rec.dt == pytest.approx(1.0 / rate, rel=10.0 ** -decimals / (n / rate))
    assert rec.n_samples == n


def test_uneven_steps_beyond_the_printed_digits_are_still_refused(tmp_path):
    path = tmp_path / "rec.csv"
    times = [0.0, 0.005, 0.010, 0.016, 0.020, 0.025, 0.030, 0.035]  # 0.016: a millisecond off
    path.write_text("time [s],ax [g]\n" + "".join(f"{t:.3f},{v}\n" for t, v in zip(times, VALUES)))
    with pytest.raises(InputError, match="expected uniform sampling"):
        load_record(path)


@pytest.mark.parametrize("content", [b"\xef\xbb\xbf", b"\xef\xbb\xbf\r\n", b"\xc2\xa0\n"])
def test_a_file_of_a_byte_order_mark_or_a_no_break_space_is_empty(tmp_path, content):
    path = tmp_path / "rec.txt"
    path.write_bytes(content)
    with pytest.raises(InputError, match="file is empty"):
        load_record(path)


@pytest.mark.parametrize("dt", [500.0, 1e200, 1e-200])
def test_a_time_step_no_record_has_is_refused(tmp_path, dt):
    path = tmp_path / "rec.txt"
    path.write_text("".join(f"{v}\n" for v in VALUES))
    with pytest.raises(InputError, match="a ground-motion record is sampled every"):
        load_record(path, dt=dt)


def test_columns_the_building_does_not_take_are_named(tmp_path):
    path = tmp_path / "rec.csv"
    rows = "".join(f"{0.005 * k:.3f},{v},{0.5 * v},{0.25 * v}\n" for k, v in enumerate(VALUES * 200))
    path.write_text("time,H1,H2,V\n" + rows)
    rec = resolve_record(path)
    assert rec.labels == ("H1", "H2") and "vertical column V not used" in rec.metadata["columns"]
    path.write_text("time,a,b,c\n" + rows)
    assert "c (acceleration column 3) " in resolve_record(path).metadata["columns"] + " "
