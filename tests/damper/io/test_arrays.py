"""Damper tests in MATLAB and HDF5 files (damper/io/arrays.py): named vectors, units from the
names or the datasets' ``units`` attributes, the rest named and not read, one-line refusals."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
import scipy.io as sio

from benchmark.foundation.errors import InputError
from damper.io.reader import read_test, read_tests
from damper.io.screening import screening_lines, screening_summary


def _motion():
    t = np.arange(2000) / 500.0
    x = 0.01 * np.sin(2 * np.pi * t)
    return t, x, 900.0 * np.tanh(40.0 * np.gradient(x, t))


def test_a_matlab_workspace_of_named_vectors_reads_in_si(tmp_path):
    """Loggers' names with a unit after an underscore, a scalar current as the constant coil
    input, Simulink's ``tout``; text and a matrix are named in the report and not read."""
    t, x, f = _motion()
    path = tmp_path / "rig.mat"
    sio.savemat(path, {"tout": t, "disp_mm": 1e3 * x, "Force_kN": 1e-3 * f, "current": 0.5,
                       "notes": "rig 3", "raw": np.zeros((3, 4))})
    test = read_test(path)
    np.testing.assert_allclose(test.displacement, x, rtol=0, atol=1e-15)
    np.testing.assert_allclose(test.force, f, rtol=1e-12, atol=1e-9)
    assert np.all(test.current == 0.5) and test.voltage is None
    assert test.metadata["file_units"] == {"displacement": "mm", "force": "kN"}
    lines = screening_lines([test])
    assert any("column(s) not used: notes (scalar), raw (3x4)" in line for line in lines)
    assert screening_summary([test])["rig.mat"]["columns_ignored"] == ["notes (scalar)", "raw (3x4)"]


def test_an_hdf5_file_with_units_attributes_reads_in_si(tmp_path):
    """The project's own result files write a ``units`` attribute on each dataset; a vector
    stored as 1 x n (as MATLAB 7.3 writes it) is a vector."""
    t, x, f = _motion()
    path = tmp_path / "rig.h5"
    with h5py.File(path, "w") as h5:
        h5["t"] = t[None, :]
        h5["stroke"] = 1e3 * x
        h5["stroke"].attrs["units"] = "mm"
        h5["load"] = 1e-3 * f
        h5["load"].attrs["units"] = b"kN"
        h5["voltage"] = np.full(t.size, 1.0)
        h5["temperature"] = 20.0 + t
    (test,) = read_tests(path)
    np.testing.assert_allclose(test.displacement, x, rtol=0, atol=1e-15)
    np.testing.assert_allclose(test.force, f, rtol=1e-12, atol=1e-9)
    assert np.all(test.voltage == 1.0)
    assert test.metadata["columns_ignored"] == ["temperature (2000)"]
    assert not test.metadata["screening"].findings  # a clean test: nothing found


@pytest.mark.parametrize("content, match", [
    ({"x_F": np.zeros((10, 3)), "Tout": np.arange(10.0)},
     r"missing vector\(s\) displacement, force; .*the file holds: x_F \(10x3\), Tout \(10\)"),
    ({"time": np.arange(10.0), "x": np.zeros(10), "force": np.zeros(9)},
     r"the vectors differ in length \(time 10, x 10, force 9\)"),
    ({"time": np.arange(10.0), "x": np.zeros(10), "disp": np.zeros(10), "force": np.zeros(10)},
     r"variables 'x' and 'disp' both name the displacement"),
    ({"time": np.arange(10.0), "x": np.zeros(10), "force": np.zeros(10), "voltage": 1.0, "current": 0.5},
     "a voltage or a current, not both"),
])
def test_a_matlab_file_that_is_no_test_is_refused_in_one_line(tmp_path, content, match):
    path = tmp_path / "bad.mat"
    sio.savemat(path, content)
    with pytest.raises(InputError, match=match) as info:
        read_test(path)
    assert "\n" not in str(info.value)


def test_an_unknown_unit_and_a_file_that_is_not_one_are_refused(tmp_path):
    t, x, f = _motion()
    path = tmp_path / "unit.h5"
    with h5py.File(path, "w") as h5:
        h5["time"] = t
        h5["displacement"] = x
        h5["force"] = f
        h5["force"].attrs["units"] = "furlong"
    with pytest.raises(InputError, match=r"variable 'force': column 'force': unknown force unit 'furlong'"):
        read_test(path)
    fake = tmp_path / "fake.mat"
    fake.write_text("time,displacement,force\n0,0,0\n")
    with pytest.raises(InputError, match="not a MATLAB file that can be read"):
        read_test(fake)
    fake_h5 = tmp_path / "fake.h5"
    fake_h5.write_text("not hdf5")
    with pytest.raises(InputError, match="not an HDF5 file that can be read"):
        read_test(fake_h5)


def test_a_workspaces_other_names_are_not_read(tmp_path):
    """MATLAB's ``y`` or ``V`` (the CSV reader's Dyke letters), a dataset named with spaces and
    symbols, a temperature with its own unit: named in the report, the test read."""
    t, x, f = _motion()
    path = tmp_path / "ws.h5"
    with h5py.File(path, "w") as h5:
        for key, value in (("time", t), ("displacement", x), ("force", f), ("y", x), ("V", x),
                           ("Sensor #2 (raw)", f), ("temp", 20.0 + t)):
            h5[key] = value
        h5["temp"].attrs["units"] = "degC"
    test = read_test(path)
    assert sorted(test.metadata["columns_ignored"]) == sorted(
        ["y (2000)", "V (2000)", "Sensor #2 (raw) (2000)", "temp (2000)"])
