"""DamperTest: CSV round trip, malformed files with file:line messages, UTFSM adapter units."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError
from damper.io.data import DamperTest, parse_utfsm_name, read_csv, read_utfsm, utfsm_files, write_csv


def _test_record(**extra):
    t = np.linspace(0.0, 1.0, 101)
    return DamperTest(time=t, displacement=0.01 * np.sin(2 * np.pi * t),
                      velocity=0.02 * np.pi * np.cos(2 * np.pi * t), force=1e3 * np.cos(2 * np.pi * t),
                      name="unit test", source="synthetic", **extra)


def test_csv_round_trip(tmp_path):
    record = _test_record(voltage=0.5)
    path = write_csv(record, tmp_path / "out.csv")
    again = read_csv(path)
    assert again.name == "unit test"
    for name in ("time", "displacement", "velocity", "force", "voltage"):
        assert np.allclose(getattr(again, name), getattr(record, name), rtol=1e-9, atol=1e-12)
    assert again.current is None
    assert again.constant_voltage == pytest.approx(0.5)


def test_csv_without_velocity_and_with_constant_current(tmp_path):
    path = tmp_path / "min.csv"
    t = np.linspace(0, 1, 201)
    x = 0.01 * np.sin(2 * np.pi * t)
    lines = ["time [s],displacement [m],force [N]"] + [f"{a},{b},{c}" for a, b, c in zip(t, x, x * 1e5)]
    path.write_text("\n".join(lines) + "\n")
    record = read_csv(path, current=0.25)
    assert np.allclose(record.velocity, 0.02 * np.pi * np.cos(2 * np.pi * t), atol=2e-4)
    assert np.all(record.current == 0.25) and record.voltage is None


@pytest.mark.parametrize("content, match", [
    ("", "empty file"),
    ("time,displacement\n0,0\n1,1\n", r":1: header: missing column\(s\) force"),
    ("time,displacement,force,speed\n0,0,0,0\n", "at least 2 data lines"),  # speed: the velocity
    ("time,stroke_mm,temperature\n0,0,20\n1,1,21\n",
     r":1: header: missing column\(s\) force; .*\(not read: 'temperature'\)"),
    ("time,displacement,force,temp [C]\n0,0,0,20\n1,1\n", r":3: expected 4 values, got 2"),
    ("time,displacement [furlong],force\n0,0,0\n1,1,1\n",
     r":1: header: column 'displacement': unknown length unit 'furlong'; expected one of m, cm, mm, in"),
    ("time,displacement,force [N/m]\n0,0,0\n1,1,1\n", r":1: header: column 'force': unknown force unit"),
    ("t,x,displacement,force\n0,0,0,0\n1,1,1,1\n", r":1: header: columns 'x' and 'displacement' both name the displacement"),
    ("# name: x\ntime,displacement,force\n0,0,0\n1,abc,1\n", r":4: column 'displacement': expected a number, got 'abc'"),
    ("time,displacement,force\n0,0,0\n1,1\n", r":3: expected 3 values"),
    ("time,displacement,force\n0,0,0\n1,1,nan\n", r":3: column 'force': expected a finite"),
    ("time,displacement,force\n0,0,0\n1,1,1\n1,2,2\n", r":4: column 'time': expected strictly increasing"),
    ("time,displacement,force,voltage,current\n0,0,0,0,0\n", "not both"),
    ("time,displacement,force\n0,0,0\n", "at least 2 data lines"),
])
def test_malformed_csv_names_file_and_line(tmp_path, content, match):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(InputError, match=match) as info:
        read_csv(path)
    assert "bad.csv" in str(info.value)


def test_a_rigs_units_are_converted_to_si_on_reading(tmp_path):
    """A logger's mm, mm/s, kN, ms and mA (and its column names) read as the same test in SI."""
    t = np.linspace(0, 1, 201)
    x = 0.012 * np.sin(2 * np.pi * t)
    v = 0.024 * np.pi * np.cos(2 * np.pi * t)
    f = 1500.0 * np.tanh(v / 0.01) + 2e4 * x
    si = tmp_path / "si.csv"
    si.write_text("time [s],displacement [m],velocity [m/s],force [N],current [A]\n"
                  + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r},{float(d)!r},0.5\n" for a, b, c, d in zip(t, x, v, f)))
    rig = tmp_path / "rig.csv"
    rig.write_text("T (ms);Disp [mm];Vel [mm / s];Load [kN];Current [mA]\n"
                   + "".join(f"{float(a * 1e3)!r};{float(b * 1e3)!r};{float(c * 1e3)!r};{float(d / 1e3)!r};500\n"
                             for a, b, c, d in zip(t, x, v, f)))
    a, b = read_csv(si), read_csv(rig)
    for name in ("time", "displacement", "velocity", "force", "current"):
        # one multiplication by a power of ten each way: a few ulps
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-13, atol=1e-15, err_msg=name)
    assert b.metadata["file_units"] == {"time": "ms", "displacement": "mm", "velocity": "mm / s",
                                        "force": "kN", "current": "mA"}
    assert "file_units" not in a.metadata
    inches = tmp_path / "in.csv"
    inches.write_text("time,x [in],f [lbf]\n0,1,1\n1,2,-1\n2,3,1\n")
    c = read_csv(inches, voltage=0.0)
    np.testing.assert_allclose(c.displacement, [0.0254, 0.0508, 0.0762], rtol=1e-15)
    np.testing.assert_allclose(c.force, [4.4482216152605, -4.4482216152605, 4.4482216152605], rtol=1e-15)


def test_missing_file_and_bad_arrays(tmp_path):
    with pytest.raises(DataNotFoundError):
        read_csv(tmp_path / "absent.csv")
    with pytest.raises(InputError, match="force: expected 3 samples"):
        DamperTest(time=[0, 1, 2], displacement=[0, 1, 2], velocity=[0, 1, 2], force=[0, 1])
    with pytest.raises(InputError, match="not both"):
        _test_record(voltage=0.0, current=0.0)


def test_utfsm_name_parsing():
    assert parse_utfsm_name("25mm0x1Hz0x75A.txt") == pytest.approx(
        {"amplitude": 0.025, "frequency": 0.1, "current": 0.75})
    assert parse_utfsm_name("2mm5Hz1A.txt") == pytest.approx({"amplitude": 0.002, "frequency": 5.0, "current": 1.0})
    with pytest.raises(InputError, match="file name"):
        parse_utfsm_name("whatever.txt")


def test_utfsm_files_load_in_si_units(shared_dir):
    files = utfsm_files(shared_dir)
    assert len(files) == 30
    for path in files:
        record = read_utfsm(path)
        info = record.metadata
        # displacement amplitude in metres matches the name (mm); the press falls short of the
        # nominal stroke (2 mm at 5 Hz reaches 1.62 mm, 25 mm reaches 24.4 mm), never by 10x
        half_range = 0.5 * np.ptp(record.displacement)
        assert 0.75 * info["amplitude"] < half_range <= 1.02 * info["amplitude"], path.name
        assert np.all(record.current == info["current"])
        # velocity column (converted from mm/s) agrees with the derivative of the displacement
        slope = np.gradient(record.displacement, record.time)
        assert np.corrcoef(slope, record.velocity)[0, 1] > 0.95, path.name
        assert 10.0 < np.max(np.abs(record.force)) < 1e4, path.name  # a small damper: N


def test_utfsm_malformed(tmp_path):
    bad = tmp_path / "10mm1Hz0A.txt"
    bad.write_text("0 1 2 3\n0.001 1 2\n")
    with pytest.raises(InputError, match=r"10mm1Hz0A.txt:2: expected 4 columns"):
        read_utfsm(bad)


def test_fortran_d_exponents_are_read_in_csv_and_utfsm_files(tmp_path):
    """docs/troubleshooting.md: Fortran exponents (1.0D-03) are accepted by every reader."""
    t = np.linspace(0.0, 2.0, 201)
    x, f = 0.01 * np.sin(2 * np.pi * t), 1e3 * np.cos(2 * np.pi * t)
    csv = tmp_path / "d.csv"
    csv.write_text("time [s],displacement [m],force [N]\n" + "\n".join(
        f"{a:.6E},{b:.6E},{c:.6E}".replace("E", "D") for a, b, c in zip(t, x, f)) + "\n")
    got = read_csv(csv)
    np.testing.assert_allclose(got.force, f, rtol=1e-6, atol=1e-9)
    utfsm = tmp_path / "10mm1Hz0A.txt"
    utfsm.write_text("\n".join(f"{a:.6E} {1e3 * b:.6E} {2e3 * np.pi * 0.01 * np.cos(2 * np.pi * a):.6E} {c:.6E}"
                               .replace("E", "D") for a, b, c in zip(t, x, f)) + "\n")
    np.testing.assert_allclose(read_utfsm(utfsm).displacement, x, rtol=1e-6, atol=1e-12)


def test_rows_read_at_once_read_as_one_by_one():
    """damper/io/data.py parse_rows converts a logger's rows at once and falls back to parse_row
    row by row for anything numpy does not read as a finite number: the numbers are the same to
    the bit either way, a Fortran exponent still reads, a missing cell is NaN (or the error that
    names its line and column), an infinity and a short row are refused."""
    from damper.io.data import parse_row, parse_rows
    rng = np.random.default_rng(3)
    header = ["time", "displacement", "force"]
    rows = [[repr(float(a)), f"{b:.6e}", f" {c:.3f} "] for a, b, c in rng.normal(size=(500, 3)) * 1e3]
    lines = list(range(2, 502))
    expected = np.array([[float(c) for c in r] for r in rows])
    assert np.array_equal(parse_rows("f.csv", header, rows, lines), expected)
    fortran = [list(r) for r in rows]
    fortran[7][1] = "1.5D-03"
    got = parse_rows("f.csv", header, fortran, lines)
    assert got[7, 1] == 1.5e-3 and np.array_equal(np.delete(got, 7, 0), np.delete(expected, 7, 0))
    gap = [list(r) for r in rows]
    gap[9][2] = ""
    assert np.isnan(parse_rows("f.csv", header, gap, lines)[9, 2])
    with pytest.raises(InputError, match=r"f.csv:11: column 'force': expected a number"):
        parse_rows("f.csv", header, gap, lines, missing=False)
    bad = [list(r) for r in rows]
    bad[4][0] = "inf"
    with pytest.raises(InputError, match=r"f.csv:6: column 'time': expected a finite number"):
        parse_rows("f.csv", header, bad, lines)
    short = [list(r) for r in rows]
    short[5] = short[5][:2]
    with pytest.raises(InputError, match=r"f.csv:7: expected 3 values"):
        parse_rows("f.csv", header, short, lines)
    assert parse_row("f.csv", 2, header, rows[0]) == list(expected[0])


def test_a_rigs_other_channels_are_named_and_not_read(tmp_path):
    """A rig logs more than the damper test needs (a temperature, the command, an acceleration,
    a status word): those columns are not read (their cells may be anything), the report names
    them, and a unit written after an underscore (``force_kN``) is read like one in brackets."""
    from damper.io.screening import screening_lines, screening_summary
    t = np.arange(400) / 200.0
    x = 0.01 * np.sin(2 * np.pi * t)
    f = 800.0 * np.tanh(50.0 * np.gradient(x, t))
    lines = ["Time_s,Temperature [C],Disp_mm,Status,Force_kN,Cmd [V]"]
    lines += [f"{a!r},{20 + a:.3f},{1e3 * b!r},OK,{1e-3 * c!r},2.5" for a, b, c in zip(t.tolist(), x.tolist(), f.tolist())]
    path = tmp_path / "rig.csv"
    path.write_text("\n".join(lines) + "\n")
    test = read_csv(path)
    np.testing.assert_allclose(test.displacement, x, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(test.force, f, rtol=1e-12, atol=1e-9)
    assert test.voltage is None
    assert test.metadata["columns_ignored"] == ["Temperature [C]", "Status", "Cmd [V]"]
    assert test.metadata["file_units"] == {"displacement": "mm", "force": "kN"}
    assert any("column(s) not used: Temperature [C], Status, Cmd [V]" in line for line in screening_lines([test]))
    assert screening_summary([test])["rig.csv"]["columns_ignored"] == ["Temperature [C]", "Status", "Cmd [V]"]


def test_write_csv_keeps_a_loggers_absolute_time_stamps(tmp_path):
    """damper/io/data.py write_csv: 10 significant digits of 1.7e9 s are whole seconds; the time
    column keeps as many digits as its steps need (17 here), so the test reads back whole."""
    from damper.io.data import _time_digits
    t = 1.7e9 + np.arange(600) / 3004.8
    x = 0.005 * np.sin(2 * np.pi * 2.0 * (t - t[0]))
    test = DamperTest(time=t, displacement=x, velocity=np.gradient(x, t), force=1e3 * np.gradient(x, t),
                      voltage=np.full(t.size, 1.0), name="epoch")
    assert _time_digits(t) == 17 and _time_digits(t - t[0]) == 10
    back = read_csv(write_csv(test, tmp_path / "epoch.csv"))
    assert back.n_samples == t.size
    np.testing.assert_allclose(np.diff(back.time), np.diff(t), rtol=1e-6)
