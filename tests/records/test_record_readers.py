"""Readers: the four formats, unit conversion, auto-detection, and one-line errors naming file and line."""

from __future__ import annotations

import re

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError
from records import STANDARD_GRAVITY, Record, load_record, write_csv
from records.readers import (detect_format, read_at2, read_benchmark, read_csv, read_single_column,
                             unit_factor)

G = STANDARD_GRAVITY


def _write(tmp_path, name, text, newline="\n"):
    path = tmp_path / name
    path.write_bytes(text.replace("\n", newline).encode("latin-1"))
    return path


# --------------------------------------------------------------------------- benchmark two-column
def test_benchmark_file_crlf_tabs_header_dt_units(tmp_path):
    path = _write(tmp_path, "quake.txt",
                  "%Some quake. First column FN\n%Acc. in cm/sec^2 and dt=0.01 sec.\n"
                  "0.00E+00\t\t0.00E+00\n1.5E+02\t-2.0E+01\n  -3.0e+002  4.0e+001\n\n", newline="\r\n")
    rec = read_benchmark(path)
    assert rec.dt == 0.01 and rec.n_samples == 3
    assert np.allclose(rec.acceleration, [[0, 0], [1.5, -0.2], [-3.0, 0.4]])  # cm/s² → m/s²
    assert rec.metadata["dt_from"] == "header" and rec.metadata["units_in_file"] == "cm/s2"
    assert rec.name == "quake" and rec.labels == ("column 1", "column 2")


def test_benchmark_file_without_dt_uses_the_benchmark_step(tmp_path):
    # read as the benchmark's format (read_benchmark, or --format benchmark): its step
    path = _write(tmp_path, "nodt.txt", "%Newhall-like header without dt\n1 2\n3 4\n")
    rec = read_benchmark(path)
    assert rec.dt == 0.005 and "default" in rec.metadata["dt_from"]
    assert np.allclose(rec.acceleration, [[0.01, 0.02], [0.03, 0.04]])
    # taken for it from two columns of numbers, the step is not guessed (a file at 0.01 s had run
    # twice as fast, with nothing on screen)
    with pytest.raises(InputError, match="no time step.*give --dt"):
        load_record(path)
    assert load_record(path, format="benchmark").dt == 0.005 and load_record(path, dt=0.01).dt == 0.01


def test_benchmark_header_conflicts_are_errors(tmp_path):
    path = _write(tmp_path, "q.txt", "%Acc. in cm/sec^2 and dt=0.005 sec.\n1 2\n3 4\n")
    with pytest.raises(InputError, match="dt = 0.01 s given but the header says dt = 0.005 s"):
        read_benchmark(path, dt=0.01)
    with pytest.raises(InputError, match="units 'g' given but the header says"):
        read_benchmark(path, units="g")
    assert read_benchmark(path, dt=0.005, units="gal").dt == 0.005


# --------------------------------------------------------------------------- malformed files
MALFORMED = {
    "empty": ("", "file is empty"),
    "blank": ("\n  \n", "file is empty"),
    "only header": ("%header\n%more\n", "no data rows"),
    "text": ("%h\n1 2\n3 abc\n", r":3: 'abc' is not a number"),
    "nan": ("%h\n1 2\nnan 4\n", r":3: 'nan' is not finite"),
    "inf": ("%h\n1 2\n3 -inf\n", r":3: '-inf' is not finite"),
    "ragged": ("%h\n1 2\n3 4 5\n", r":3: row has 3 values, expected 2"),
    "one column": ("%h\n1\n2\n", r":2: row has 1 values, expected 2"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_benchmark_files_name_file_and_line(tmp_path, case):
    text, message = MALFORMED[case]
    path = _write(tmp_path, "bad.txt", text)
    with pytest.raises(InputError, match=message) as err:
        read_benchmark(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), float("inf"), "abc"])
def test_bad_time_steps_are_rejected(tmp_path, dt):
    path = _write(tmp_path, "one.txt", "0.1\n0.2\n0.3\n")
    with pytest.raises(InputError, match="dt"):
        read_single_column(path, dt=dt)
    with pytest.raises(InputError, match="dt"):
        load_record(path, format="single", dt=dt)


def test_missing_file_and_binary_file(tmp_path):
    with pytest.raises(DataNotFoundError, match="nope.txt: record file not found"):
        load_record(tmp_path / "nope.txt")
    path = tmp_path / "bin.dat"
    path.write_bytes(b"\x00\x01\x02garbage")
    with pytest.raises(InputError, match="binary"):
        load_record(path)
    with pytest.raises(InputError, match="not a regular file"):
        load_record(tmp_path)


# --------------------------------------------------------------------------- PEER .AT2
AT2_NEW = """PEER NGA STRONG MOTION DATABASE RECORD
IMPERIAL VALLEY 5/19/40, EL CENTRO ARRAY #9, 180
ACCELERATION TIME HISTORY IN UNITS OF G
NPTS=    7, DT=   .0100 SEC
  .1000000E-01  .2000000E-01 -.3000000E-01  .4000000E-01  .5000000E-01
 -.6000000E-01  .7000000E-01
"""
AT2_OLD = """PACIFIC ENGINEERING AND ANALYSIS STRONG-MOTION DATA
 KOBE 01/16/95 2046, KJMA, 000
 ACCELERATION TIME HISTORY IN UNITS OF G
     5    .0200    NPTS, DT
   .1000E-01   .2000E-01   .3000E-01
   .4000E-01   .5000E-01
"""


def test_at2_new_and_old_headers(tmp_path):
    new = read_at2(_write(tmp_path, "ELC180.AT2", AT2_NEW))
    assert new.dt == 0.01 and new.n_samples == 7 and new.labels == ("180",)
    assert new.acceleration[2, 0] == pytest.approx(-0.03 * G)
    old = load_record(_write(tmp_path, "KJM000.at2", AT2_OLD))
    assert old.dt == 0.02 and old.n_samples == 5 and old.labels == ("000",)
    assert old.pga[0] == pytest.approx(0.05 * G)
    assert old.metadata["format"] == "at2"
    west2 = AT2_NEW.replace("NPTS=    7, DT=   .0100 SEC", "NPTS=  7 DT= 0.0100 SEC,")
    assert read_at2(_write(tmp_path, "w2.AT2", west2)).dt == 0.01


def test_at2_errors(tmp_path):
    short = AT2_NEW.replace("NPTS=    7", "NPTS=    8")
    with pytest.raises(InputError, match="header says NPTS = 8 but the file holds 7 values"):
        read_at2(_write(tmp_path, "a.AT2", short))
    with pytest.raises(InputError, match=r"a\.AT2:4: .*DT in seconds|a\.AT2:4: time step"):
        read_at2(_write(tmp_path, "a.AT2", AT2_NEW.replace("DT=   .0100", "DT=   -.0100")))
    with pytest.raises(InputError, match=r":4: expected 'NPTS= n, DT= dt SEC'"):
        read_at2(_write(tmp_path, "a.AT2", AT2_NEW.replace("NPTS=    7, DT=   .0100 SEC", "garbage")))
    with pytest.raises(InputError, match=r":6: 'x' is not a number"):
        read_at2(_write(tmp_path, "a.AT2", AT2_NEW.replace("-.6000000E-01", "x")))
    with pytest.raises(InputError, match="units 'cm/s2' given but the header says 'g'"):
        read_at2(_write(tmp_path, "a.AT2", AT2_NEW), units="cm/s2")
    with pytest.raises(InputError, match="header says DT = 0.01"):
        load_record(_write(tmp_path, "a.AT2", AT2_NEW), dt=0.02)


# --------------------------------------------------------------------------- single column
def test_single_column_needs_dt_and_reads_g(tmp_path):
    path = _write(tmp_path, "ELC-180", "0.01\n-0.02\n\n0.5\n")
    with pytest.raises(InputError, match="holds no time step; give dt"):
        load_record(path)
    rec = load_record(path, dt=0.02)
    assert detect_format(path) == "single"
    assert rec.dt == 0.02 and np.allclose(rec.acceleration[:, 0], np.array([0.01, -0.02, 0.5]) * G)
    assert np.allclose(load_record(path, dt=0.02, units="m/s2").acceleration[:, 0], [0.01, -0.02, 0.5])
    with pytest.raises(InputError, match=r":2: row has 2 values, expected 1"):
        read_single_column(_write(tmp_path, "two", "1\n2 3\n"), dt=0.01)


def _slammer_table(shared_dir):
    text = (shared_dir / "records" / "raw" / "SOURCES.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| `(SLAMMER/[^`]+)` \| [^|]+\| ([0-9.]+) \| (\d+) \| [0-9.]+ \| ([0-9.]+) \|", text, re.M)
    return [(path, float(dt), int(npts), float(pga)) for path, dt, npts, pga in rows]


def test_every_slammer_file_loads_with_its_dt(shared_dir):
    table = _slammer_table(shared_dir)
    assert len(table) == 14
    for rel, dt, npts, pga in table:
        rec = load_record(shared_dir / "records" / "raw" / rel, dt=dt)   # auto → single column, g
        assert rec.dt == dt and rec.n_samples == npts, rel
        assert rec.pga_g[0] == pytest.approx(pga, abs=6e-5), rel


# --------------------------------------------------------------------------- CSV
def test_csv_with_header_units_and_round_trip(tmp_path):
    t = np.arange(100) * 0.01
    acc = np.column_stack([np.sin(t), np.cos(t)])
    rec = Record("kobe-like", 0.01, acc, labels=("N-S (FN)", "E-W (FP)"), synthetic=True, source="synthetic: test")
    path = write_csv(rec, tmp_path / "r.csv")
    back = load_record(path)
    assert back.labels == ("N-S (FN)", "E-W (FP)")   # a label in parentheses is not a unit
    assert back.dt == pytest.approx(0.01, rel=1e-12)
    assert np.allclose(back.acceleration, acc, rtol=1e-9, atol=1e-12)
    assert "SYNTHETIC" in path.read_text().splitlines()[0]
    in_g = write_csv(rec, tmp_path / "g.csv", units="g")
    assert np.allclose(load_record(in_g).acceleration, acc, rtol=1e-9, atol=1e-12)
    assert "[g]" in in_g.read_text().splitlines()[1]


def test_csv_variants(tmp_path):
    semi = _write(tmp_path, "semi.csv", "# units: g\ntime;ax\n0;0.1\n0.02;0.2\n0.04;-0.1\n")
    rec = read_csv(semi)
    assert rec.dt == pytest.approx(0.02) and rec.acceleration[1, 0] == pytest.approx(0.2 * G)
    plain = _write(tmp_path, "plain.dat", "1.0 0.5\n1.005 0.25\n1.01 0.0\n1.015 -0.5\n")
    assert detect_format(plain) == "csv"
    rec = load_record(plain)
    assert rec.dt == pytest.approx(0.005) and rec.metadata["time_start_s"] == 1.0
    assert rec.metadata["units_from"].startswith("default")
    ms = _write(tmp_path, "ms.csv", "time (ms), a (cm/s2)\n0, 100\n10, 200\n20, 300\n")
    rec = read_csv(ms)
    assert rec.dt == pytest.approx(0.01) and rec.acceleration[2, 0] == pytest.approx(3.0)
    assert rec.labels == ("a",)


@pytest.mark.parametrize("text, message", [
    ("time,ax\n0,1\n0.01,2\n0.01,3\n", r":4: time 0.01 s does not increase"),
    ("time,ax\n0,1\n0.01,2\n0.005,3\n", r":4: time 0.005 s does not increase"),
    ("time,ax\n0,1\n0.01,2\n0.03,3\n0.04,1\n", r":4: time step 0.02 s differs"),
    ("time,ax\n0,1\n0.01,2,3\n", r":3: row has 3 values, expected 2"),
    ("time,ax\n0,1\n0.01,NaN\n", r":3: 'NaN' is not finite"),
    ("time,ax\n0,1\n0.01,one\n", r":3: 'one' is not a number"),
    ("time\n0\n1\n", r"1 column; expected time and at least one"),
    ("time,ax\n", "header row only"),
    ("ax,ay\n0,1\n1,2\n", "first column is 'ax'; expected the time column"),
    ("time,ax [furlongs]\n0,1\n1,2\n", "unknown acceleration unit 'furlongs'"),
    ("time,ax [g],ay [m/s2]\n0,1,1\n1,2,2\n", "different units"),
    ("time [h],ax\n0,1\n1,2\n", "time column unit 'h'"),
])
def test_malformed_csv_files(tmp_path, text, message):
    path = _write(tmp_path, "bad.csv", text)
    with pytest.raises(InputError, match=message) as err:
        read_csv(path)
    assert "bad.csv" in str(err.value)


def test_csv_units_and_dt_conflicts(tmp_path):
    path = _write(tmp_path, "u.csv", "time,ax [g]\n0,1\n0.01,2\n")
    with pytest.raises(InputError, match="units 'm/s2' given but the file says 'g'"):
        read_csv(path, units="m/s2")
    with pytest.raises(InputError, match="dt = 0.02 s given but the time column has step 0.01"):
        read_csv(path, dt=0.02)


# --------------------------------------------------------------------------- units, detection, dispatch
def test_units():
    assert unit_factor("g") == G
    assert unit_factor("cm/s^2") == unit_factor("GAL") == unit_factor("cm/sec^2") == 0.01
    assert unit_factor("m/s²") == 1.0 and unit_factor("mm/s2") == 0.001
    with pytest.raises(InputError, match="unknown acceleration unit 'ft/s2'"):
        unit_factor("ft/s2")


def test_detection_and_unknown_format(tmp_path):
    assert detect_format(_write(tmp_path, "a.txt", "%h\n1 2\n")) == "benchmark"
    assert detect_format(_write(tmp_path, "b.txt", "3 1\n-2 5\n7 1\n")) == "benchmark"   # not a time axis
    assert detect_format(_write(tmp_path, "c.txt", AT2_NEW)) == "at2"
    with pytest.raises(InputError, match="format 'xlsx' is not known"):
        load_record(tmp_path / "a.txt", format="xlsx")


def test_benchmark_files_load_with_catalogue_pgas(records_dir):
    expected = {"newhall": (0.736, 0.656), "sylmar": (0.875, 0.605), "elcentro": (0.313, 0.215),
                "rinaldi": (0.840, 0.476), "kobe": (0.841, 0.631), "jiji": (0.512, 0.369),
                "erzikan": (0.515, 0.496)}
    for name, pga in expected.items():
        path = records_dir / f"{name}.txt"
        if name == "newhall":  # its header states no step: not guessed from two columns of numbers
            with pytest.raises(InputError, match="no time step"):
                load_record(path)
            rec = load_record(path, format="benchmark")
        else:
            rec = load_record(path)   # auto-detected as the benchmark format
        assert rec.metadata["format"] == "benchmark" and rec.dt == 0.005
        assert np.allclose(rec.pga_g, pga, atol=6e-4), name


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from hypothesis.extra.numpy import arrays  # noqa: E402


@settings(max_examples=25, deadline=None)
@given(acc=arrays(np.float64, st.tuples(st.integers(2, 40), st.integers(1, 3)),
                  elements=st.floats(-50, 50, allow_nan=False, width=64)),
       dt=st.sampled_from([0.001, 0.005, 0.01, 0.02]))
def test_csv_round_trip_property(tmp_path_factory, acc, dt):
    rec = Record("r", dt, acc)
    path = write_csv(rec, tmp_path_factory.mktemp("csv") / "r.csv")
    back = load_record(path)
    assert back.n_components == rec.n_components and back.dt == pytest.approx(dt, rel=1e-9)
    assert np.allclose(back.acceleration, acc, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("header, columns, want, note", [
    ("time [s], ay [g], ax [g]", (0.1, 0.3), (0.3, 0.1), "header names: ax, ay"),
    ("t, FP, FN", (0.1, 0.3), (0.3, 0.1), "header names: FN, FP"),
    ("time, az, acc_x, acc_y", (0.5, 0.3, 0.1), (0.3, 0.1), "vertical column az not used"),
    ("time, ax, ay, UP", (0.3, 0.1, 0.5), (0.3, 0.1), "vertical column UP not used"),
    ("time, ax, ay", (0.3, 0.1), (0.3, 0.1), None),
    ("time, H1, H2", (0.1, 0.3), (0.1, 0.3), None),  # no direction in the names: the file's order
])
def test_csv_components_follow_the_header_names(tmp_path, header, columns, want, note):
    """A header that names the directions is followed, not the columns' positions; a vertical
    column is left out and said so (a run would have taken it for a horizontal one)."""
    t = np.arange(200) * 0.01
    rows = "\n".join(", ".join([f"{ti:.2f}"] + [f"{a * np.sin(7 * ti):.6f}" for a in columns]) for ti in t)
    path = tmp_path / "rec.csv"
    path.write_text(header + "\n" + rows + "\n")
    rec = read_csv(path, units="g")
    assert rec.n_components == len(want)
    peaks = np.max(np.abs(rec.acceleration), axis=0) / STANDARD_GRAVITY
    np.testing.assert_allclose(peaks, want, rtol=1e-3)
    if note is None:
        assert "columns" not in rec.metadata
    else:
        assert note in rec.metadata["columns"]


@pytest.mark.parametrize("header, message", [
    ("time, ax, acc_x", "name the same direction"),
    ("time, az", "only vertical acceleration"),
])
def test_csv_header_names_that_cannot_be_followed_are_refused(tmp_path, header, message):
    path = tmp_path / "rec.csv"
    n = header.count(",")
    path.write_text(header + "\n" + "\n".join(", ".join([f"{0.01 * i:.2f}"] + ["0.1"] * n) for i in range(50)) + "\n")
    with pytest.raises(InputError, match=message):
        read_csv(path, units="g")


def test_oriented_csv_record_names_the_file_column_it_took(tmp_path):
    from records.resolve import resolve_record
    path = tmp_path / "rec.csv"
    path.write_text("time, ay [g], ax [g]\n" + "\n".join(f"{0.01 * i:.2f}, 0.1, {0.3 * np.sin(i):.5f}"
                                                         for i in range(100)) + "\n")
    fn, fp = resolve_record(path, orientation="FN-x"), resolve_record(path, orientation="FP-x")
    assert (fn.metadata["x_file_column"], fn.metadata["y_file_column"]) == (2, 1)
    assert (fp.metadata["x_file_column"], fp.metadata["y_file_column"]) == (1, 2)
    assert fn.labels == ("ax", "ay") and fp.labels == ("ay", "ax")


@pytest.mark.parametrize("sep, header", [(", ", "time [s], ax [g]"), ("  ", ""), ("; ", "time;ax [g]")])
def test_fortran_d_exponents_read_in_every_text_layout(tmp_path, sep, header):
    """docs/troubleshooting.md: Fortran exponents (1.0D-03) are accepted, in any layout."""
    rows = [f"{0.01 * i:.2f}".replace("e", "D") + sep + f"{0.1 * np.sin(i):.6E}".replace("E", "D") for i in range(60)]
    path = tmp_path / "rec.csv"
    path.write_text((header + "\n" if header else "") + "\n".join(rows) + "\n")
    rec = load_record(path, units="g")
    assert rec.acceleration.shape[0] == 60
    np.testing.assert_allclose(rec.acceleration[:, 0] / STANDARD_GRAVITY, 0.1 * np.sin(np.arange(60)), atol=1e-6)
