"""The solve_ivp reference (benchmark.simulator.oracle) with a controller: measurements, voltages held
over control steps, and agreement with the compiled kernel on a strong-motion window."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.simulator.oracle import OracleModel, simulate_oracle
from benchmark.simulator.sensors import n_measurements
from benchmark.simulator.simulation import simulate
from records import load_benchmark_record


@pytest.fixture(scope="module")
def building(shared_dir):
    return Building.default(structure_path=shared_dir / "benchmark" / "structure.json")


def _window(records_dir, start: float | None, seconds: float):
    """``seconds`` of Kobe FN-x from ``start`` (None: from 0.4 s before the peak acceleration)."""
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    if start is None:
        start = np.argmax(np.abs(rec.acceleration).max(axis=1)) * rec.dt - 0.4
    k0, n = int(round(start / rec.dt)), int(round(seconds / rec.dt)) + 1
    return rec.replace(acceleration=np.ascontiguousarray(rec.acceleration[k0:k0 + n]))


def test_measurement_vector_layout_and_rest(building, records_dir):
    record = _window(records_dir, 0.0, 0.1)
    model = OracleModel(building, record, voltage=0.0)
    x = model.initial_state()
    y = model.measurement(0.0, x)
    assert y.shape == (n_measurements(building.n_devices),)
    # at rest: accelerations are minus nothing but the ground's (absolute = 0 + ... ), displacements 0
    assert np.allclose(y[27:], 0.0)
    # absolute base acceleration at rest equals the base's inertial reaction to the ground: the
    # relative acceleration is -ag, so the absolute one is 0
    assert np.allclose(y[:3], 0.0, atol=1e-12)
    # a base displacement appears in the measurement and in the device displacements
    x[model.nq] = 0.01
    y = model.measurement(0.0, x)
    assert y[27] == 0.01
    assert np.allclose(y[30:30 + building.n_devices], building.devices.influence() @ np.array([0.01, 0, 0]))


def test_controller_path_with_constant_voltage_matches_kernel(building, records_dir):
    """Through the controller path (session, held voltages, restarts) with a smooth law the two
    integrators agree as tightly as the constant-voltage oracle test requires."""
    record = _window(records_dir, None, 0.4)
    kernel = simulate(building, record, controller="passive-on")
    ref = simulate_oracle(building, record, controller="passive-on")
    assert np.array_equal(kernel.voltage, ref.voltage)
    mine = kernel.peaks.as_dict()  # the same function (peaks_of) on both sides
    assert mine["single_device_force"] > 1e4
    for name, value in ref.peaks.as_dict().items():
        assert mine[name] == pytest.approx(value, rel=2e-3), name


@pytest.mark.slow
def test_clipped_optimal_matches_kernel_on_strong_motion(building, records_dir):
    """Bang-bang control: where (f_desired - f) f is within ~1e-4 of zero the two integrators can
    switch a device one control step apart, so a few voltage samples differ and the peaks agree
    to about 1 % rather than 0.1 % (tightening either integrator does not change this)."""
    record = _window(records_dir, None, 0.6)
    kernel = simulate(building, record, controller="clipped-optimal")
    ref = simulate_oracle(building, record, controller="clipped-optimal")
    agreement = np.mean(kernel.voltage == ref.voltage)
    assert agreement > 0.95, agreement
    mine = kernel.peaks.as_dict()
    assert mine["base_displacement"] > 1e-3  # the window really shakes the building
    for name, value in ref.peaks.as_dict().items():
        assert mine[name] == pytest.approx(value, rel=1e-2), name
    # the devices were switched: the controller did something
    assert 0 < np.mean(ref.voltage > 0) < 1
