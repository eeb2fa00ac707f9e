"""The kernel seam (issue 14/15): one measurement layout, structured kernel arguments, the linear
floor, optional per-bearing histories and the Newton iteration on the base."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator import sensors
from benchmark.simulator.building import Building
from benchmark.foundation.errors import InputError
from benchmark.applications.linear_floor import linear_floor_inputs, linear_floor_steps
from controllers.measurements import measurement_layout
from benchmark.simulator.simulation import _discrete_system, _ground_acceleration, simulate
from records import Record
from records.synthetic import benchmark_like


def _record(seconds: float) -> Record:
    rec = benchmark_like("kobe", "FN-x", seed=3)
    n = int(round(seconds / rec.dt))
    return rec.replace(acceleration=np.ascontiguousarray(rec.acceleration[:n]))


@pytest.fixture(scope="module")
def building(shared_dir):
    return Building.default()


def test_measurement_layout_is_the_one_sensors_controllers_and_plant_use(building):
    from benchmark.simulator.linear_model import linear_model
    from controllers.base import measurement_slices, n_measurements

    lay = measurement_layout(16)
    assert (lay.n_accelerations, lay.base_displacement, lay.device_displacement, lay.device_force,
            lay.n_measurements) == (27, 27, 30, 46, 62)
    assert sensors.measurement_slices(16) == lay.slices() == measurement_slices(16)
    assert sensors.n_measurements(5) == n_measurements(5) == measurement_layout(5).n_measurements == 40
    assert len(sensors.measurement_names(16)) == lay.n_measurements
    lm = linear_model(building)
    nq = building.superstructure.n_q
    s = lay.slices()
    # base displacement rows read the base states; device force rows are the identity on the forces
    np.testing.assert_array_equal(lm.C[s["base_displacement"], nq:nq + 3], np.eye(3))
    np.testing.assert_array_equal(lm.D[s["device_force"]], np.eye(16))
    with pytest.raises(InputError, match="n_devices"):
        measurement_layout(-1)


def test_linear_floor_is_the_exact_linear_run(building):
    # The floor loop with no nonlinear force is the linear building's run itself.
    linear = building.with_isolation("linear").without_devices()
    rec = _record(4.0)
    plant = _discrete_system(linear, rec.dt)[3]
    w = linear_floor_inputs(_ground_acceleration(rec))
    z = np.zeros((w.shape[0], plant.Phi.shape[0]))
    linear_floor_steps(plant.Phi, plant.G0, plant.G1, w, z)
    run = simulate(linear, rec, None, bearing_histories=False)
    assert np.max(np.abs(z)) > 1e-3
    np.testing.assert_allclose(z, run.state, rtol=0, atol=1e-12 * np.max(np.abs(z)))
    assert run.info["max_iterations_used"] == 1


def test_bearing_histories_are_optional_and_change_nothing_else(building):
    rec = _record(3.0)
    full = simulate(building.without_devices(), rec, None)
    lean = simulate(building.without_devices(), rec, None, bearing_histories=False)
    assert lean.bearing_force is None and lean.bearing_state is None
    assert full.bearing_force.shape == (rec.acceleration.shape[0], 92, 2)
    for name in ("base_displacement", "base_shear", "floor_acceleration_absolute"):
        np.testing.assert_array_equal(getattr(full, name), getattr(lean, name))
    for term in full.energy:
        np.testing.assert_array_equal(full.energy[term], lean.energy[term])
    # the per-bearing forces resolve to the isolation force at the base centre of mass
    xy = building.superstructure.bearing_xy
    f = full.bearing_force
    resolved = np.stack([f[..., 0].sum(1), f[..., 1].sum(1),
                         (-xy[None, :, 1] * f[..., 0] + xy[None, :, 0] * f[..., 1]).sum(1)], axis=1)
    np.testing.assert_allclose(resolved, full.isolation_force, rtol=1e-9,
                               atol=1e-9 * np.max(np.abs(full.isolation_force)))
    assert np.all(np.abs(full.bearing_state).max(axis=(0, 2)) > 0.5)  # every bearing's states written


def test_newton_iteration_reaches_the_same_fixed_point_in_fewer_iterations(building):
    rec = _record(4.0)
    runs = {nw: simulate(building, rec, "clipped-optimal", bearing_histories=False, newton=nw)
            for nw in (False, True)}
    fp, nw = runs[False], runs[True]
    assert nw.info["mean_iterations"] < fp.info["mean_iterations"]
    for name in ("base_displacement", "base_velocity", "base_shear", "device_force"):
        a, b = getattr(nw, name), getattr(fp, name)
        # both stop at a relative change of 1e-6 of the base's motion; the voltages may switch one
        # control step apart where the clipped-optimal law sits on its threshold
        assert np.max(np.abs(a - b)) <= 2e-3 * np.max(np.abs(b)), name
    assert abs(nw.energy_balance_error() - fp.energy_balance_error()) < 1e-3


def test_derived_histories_are_built_on_first_access_and_survive_pickling(building):
    """A result derives its accelerations, floor responses, shears and energies on first access
    (issue 14: a run whose caller reads few histories does not pay for the rest); the values do
    not depend on the order of access, and pickling (worker processes) derives them first."""
    import dataclasses
    import pickle

    rec = _record(3.0)
    a = simulate(building, rec, controller="passive-on", bearing_histories=False)
    b = simulate(building, rec, controller="passive-on", bearing_histories=False)
    assert "base_shear" not in a.__dict__ and "energy" not in a.__dict__
    shear = a.base_shear                        # derives its group, not the energies
    assert "drift_ratio" in a.__dict__ and "energy" not in a.__dict__
    assert a.energy_balance_error() < 1e-2
    b.materialize()
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y), f.name
    assert np.array_equal(shear, a.isolation_force + a.device_force_total)
    c = simulate(building, rec, controller="passive-on", bearing_histories=False)
    back = pickle.loads(pickle.dumps(c))
    assert "_pending" not in back.__dict__
    assert np.array_equal(back.floor_acceleration_absolute, a.floor_acceleration_absolute)
    assert back.energy.keys() == a.energy.keys()
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        a.nonsense
    d = simulate(building, rec, controller="passive-on", bearing_histories=False)
    d.base_shear = np.zeros(3)                  # set before its group was derived: kept
    assert d.drift_ratio.shape == a.drift_ratio.shape and np.array_equal(d.base_shear, np.zeros(3))
