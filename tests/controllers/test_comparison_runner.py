"""The comparison runner on the real simulator: a short record, a user controller, the CLI."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

import damper
from benchmark.foundation.errors import InputError, NumericalError
from controllers.base import Controller
from benchmark.applications.comparison import compare, parse_list


def _model():
    return damper.ExtendedBoucWen(kappa_x=207e3, kappa_xdot=damper.Polynomial((100e3, 200e3)),
                                  kappa_w=damper.Polynomial((50e3, 950e3)), rho=40.0, sigma=1.0, n=1.5)


@pytest.fixture(scope="module")
def building(shared_dir):
    from benchmark.simulator.building import Building

    return Building.default(damper_model=_model(), isolation="linear")


class HalfVoltage(Controller):
    """A user's pure-Python controller: half voltage while the base moves more than 1 cm."""

    name = "half-when-moving"

    def step(self, measurements):
        ub = measurements[self.context.slices["base_displacement"]]
        on = np.hypot(ub[0], ub[1]) > 0.01
        return np.full(self.context.n_devices, 0.5 if on else 0.0)


class BadSize(Controller):
    name = "bad-size"

    def step(self, measurements):
        return np.zeros(3)


class NaNVoltage(Controller):
    name = "nan-voltage"

    def step(self, measurements):
        return np.full(self.context.n_devices, np.nan)


def _short_record():
    from records.record import Record

    dt = 0.005
    t = np.arange(0.0, 6.0, dt)
    acc = np.column_stack([3.0 * np.sin(2 * np.pi * 0.5 * t) * np.exp(-0.3 * t),
                           2.0 * np.sin(2 * np.pi * 0.7 * t) * np.exp(-0.3 * t)])
    return Record(name="pulse", dt=dt, acceleration=acc, labels=("x", "y"), source="synthetic: test pulse",
                  synthetic=True, metadata={})


def test_parse_list_checks_names():
    assert parse_list("all", ("a", "b"), "records") == ["a", "b"]
    assert parse_list("B", ("a", "b"), "records") == ["b"]
    with pytest.raises(InputError, match="--records: 'c' unknown"):
        parse_list("a,c", ("a", "b"), "records")
    # FN-x,FN-x had run twice and counted twice in the mean and max over the runs
    with pytest.raises(InputError, match="--orientations: 'fn-x' given twice"):
        parse_list("FN-x,fn-x", ("FN-x", "FP-x"), "orientations")


def test_user_controller_runs_and_bad_controllers_stop_with_clear_errors(building):
    from benchmark.simulator.simulation import simulate

    record = _short_record()
    result = simulate(building, record, HalfVoltage())
    assert set(np.unique(result.voltage)) <= {0.0, 0.5}
    assert np.any(result.voltage == 0.5)
    with pytest.raises(InputError, match="'bad-size' returned voltages of shape"):
        simulate(building, record, BadSize())
    with pytest.raises(NumericalError, match="'nan-voltage' returned non-finite"):
        simulate(building, record, NaNVoltage())


def test_compare_one_record_writes_table_json_hdf5_and_plots(building, records_dir, tmp_path):
    result = compare(records="elcentro", orientations="FN-x", controllers=["passive-off", HalfVoltage()],
                     records_dir=str(records_dir), jobs=1, building=building, progress=False)
    assert [r.controller for r in result.runs] == ["passive-off", "half-when-moving"]
    for run in result.runs:
        assert set(run.J) == {f"J{i}" for i in range(1, 10)}
        assert run.peaks["peak_base_displacement"] > 0  # ComparisonRun.peaks: the file record (peak_* names)
    table = result.table()
    assert "passive-off" in table and "mean" in table
    doc = json.loads(json.dumps(result.to_json()))
    assert doc["runs"][0]["record"] == "elcentro" and "J" in doc["runs"][0]
    path = result.write_hdf5(tmp_path / "cmp.h5")
    with h5py.File(path) as h5:
        g = h5["runs/elcentro/FN-x/passive-off"]
        assert np.isclose(g.attrs["J3"], result.runs[0].J["J3"])
        assert g["base_displacement"].shape[1] == 2
        # every history says its units (a probe found none in comparison files)
        assert g["base_displacement"].attrs["units"] == "m (x, y)" and g["t"].attrs["units"] == "s"
        assert g["voltage"].attrs["units"] == "V"
        ref = h5["reference/elcentro/FN-x"]
        assert all(ref[k].attrs["units"] for k in ref)
    paths = result.plot(tmp_path / "plots")
    assert all(p.stat().st_size > 10_000 for p in paths)
