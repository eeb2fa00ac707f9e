"""Damper CSVs whose time column is a logger's clock: ISO 8601 date-times or times of day
(damper.io.data.clock_seconds), read as seconds since the first stamp."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.io.data import clock_seconds
from damper.io.reader import read_test

RATE = 1000.0


def _rows(n=3000):
    t = np.arange(n) / RATE
    x = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    f = 800.0 * np.tanh(np.gradient(x, t) / 0.02)
    return t, x, f


def _write(path, header, stamps, x, f):
    path.write_text(header + "\n" + "".join(f"{s},{a * 1e3:.6f},{b:.4f}\n" for s, a, b in zip(stamps, x, f)))
    return path


@pytest.mark.parametrize("column, start, form", [
    ("timestamp", dt.datetime(2022, 5, 13, 17, 6, 51, 728000), "iso"),
    ("datetime", dt.datetime(2022, 5, 13, 17, 6, 51, 728000), "isoT"),
    ("time", dt.datetime(2022, 5, 13, 23, 59, 59, 0), "tod"),    # runs past midnight
])
def test_clock_stamps_read_as_seconds_since_the_first(tmp_path, column, start, form):
    t, x, f = _rows()
    clock = [start + dt.timedelta(seconds=float(s)) for s in t]
    stamps = {"iso": [c.isoformat(sep=" ", timespec="microseconds") for c in clock],
              "isoT": [c.isoformat(timespec="microseconds") for c in clock],
              "tod": [c.time().isoformat(timespec="microseconds") for c in clock]}[form]
    test = read_test(_write(tmp_path / "clock.csv", f"{column},disp [mm],force [N]", stamps, x, f))
    # microsecond stamps of a 1-ms grid: exact to the float's rounding of the seconds
    np.testing.assert_allclose(test.time, t, rtol=0, atol=1e-9)
    assert test.n_samples == t.size and test.usable.all()
    assert test.metadata["clock_origin"] == stamps[0]


def test_numbers_are_no_clock_and_a_bad_clock_cell_is_named():
    assert clock_seconds(["0.0", "0.001"]) is None
    assert clock_seconds(["", "1e-3"]) is None
    seconds, origin = clock_seconds(["2022-05-13 17:06:51.5", "2022-05-13 17:06:52", "garbage"])
    assert origin == "2022-05-13 17:06:51.5" and seconds[:2].tolist() == [0.0, 0.5] and np.isnan(seconds[2])


def test_a_clock_cell_that_is_not_one_is_dropped_and_said(tmp_path):
    t, x, f = _rows()
    clock = [(dt.datetime(2022, 5, 13, 17, 0, 0) + dt.timedelta(seconds=float(s))).isoformat(sep=" ") for s in t]
    clock[1500] = "n/a"
    test = read_test(_write(tmp_path / "clock.csv", "timestamp,disp [mm],force [N]", clock, x, f))
    findings = test.metadata["screening"].findings
    assert any(fd.kind == "time" and "clock.csv:1502" in fd.message for fd in findings)
    assert test.n_samples == t.size  # the row dropped, its slot put back (lost)
    with pytest.raises(InputError, match="time"):
        read_test(_write(tmp_path / "none.csv", "timestamp,disp [mm],force [N]", ["n/a"] * t.size, x, f))


def test_a_review_of_the_clock_reader():
    """A stray 00:00:00 in a 17:06 file is a step back for the screening, not a day later for
    every row after it; out-of-range times are no clock; a first cell written as n/a does not
    decide the column's form; zones are taken to UTC."""
    seconds, _ = clock_seconds(["17:06:51", "17:06:52", "00:00:00", "17:06:53"])
    assert seconds[[0, 1, 3]].tolist() == [0.0, 1.0, 2.0] and seconds[2] < 0
    seconds, _ = clock_seconds(["23:59:59.5", "00:00:00.5", "00:00:01.5"])
    assert seconds.tolist() == [0.0, 1.0, 2.0]
    assert np.isnan(clock_seconds(["17:00:00", "25:61:61"])[0][1])
    seconds, origin = clock_seconds(["n/a", "2022-05-13T17:00:00Z", "2022-05-13T19:00:01+02:00"])
    assert origin == "2022-05-13T17:00:00Z" and np.isnan(seconds[0]) and seconds[2] == pytest.approx(1.0)


def test_a_millisecond_wall_clock_at_3_khz_with_a_bad_cell_keeps_every_row(tmp_path):
    """A wall clock in ms at 3 kHz (each stamp two or three times) with one cell that is no
    stamp: the coarse clock's grid gives that row its slot's time, and every row is kept."""
    n = 9000
    t = np.arange(n) / 3004.8
    x = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    f = 500.0 * np.cos(2 * np.pi * 2.0 * t) + 120.0 * np.sin(2 * np.pi * 6.0 * t)
    start = dt.datetime(2022, 5, 13, 17, 0, 0)
    stamps = [(start + dt.timedelta(milliseconds=int(s * 1e3 + 1e-9))).isoformat(sep=" ", timespec="milliseconds")
              for s in t]
    stamps[4000] = "n/a"
    test = read_test(_write(tmp_path / "ms.csv", "timestamp [ms],disp [mm],force [N]", stamps, x, f))
    assert test.n_samples == n and test.usable.all()
    np.testing.assert_allclose(np.diff(test.time), 1.0 / 3004.8, rtol=1e-4)
    kinds = [fd.kind for fd in test.metadata["screening"].findings]
    assert kinds.count("rounded") == 1 and "time" not in kinds
    assert "time" not in test.metadata.get("file_units", {})  # the [ms] beside a clock is not reported
