"""Controllers inside the stepping loop: compiled and pure-Python paths, measurements, noise, errors."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.foundation.errors import InputError, NumericalError
from benchmark.simulator.linear_model import linear_model
from benchmark.simulator.sensors import measurement_slices, n_measurements
from benchmark.simulator.simulation import simulate
from controllers.noise import MeasurementNoise
from controllers.registry import get_controller
from records import Record, load_benchmark_record


def _first_seconds(record: Record, seconds: float) -> Record:
    n = int(round(seconds / record.dt)) + 1
    return Record(name=record.name, dt=record.dt, acceleration=np.array(record.acceleration[:n]),
                  labels=record.labels, source=record.source, synthetic=record.synthetic,
                  metadata=dict(record.metadata))


@pytest.fixture(scope="module")
def building(shared_dir):
    return Building.default(isolation="friction-lrb", structure_path=shared_dir / "benchmark" / "structure.json")


@pytest.fixture(scope="module")
def record(records_dir):
    return _first_seconds(load_benchmark_record("sylmar", "FN-x", records_dir=records_dir), 8.0)


class PythonOnly:
    """Runs a built-in controller from Python (no compiled form exposed to the simulation)."""

    def __init__(self, inner):
        self.inner = inner
        self.name = f"python({inner.name})"

    def reset(self, context):
        self.inner.reset(context)

    def step(self, measurements):
        return self.inner.step(measurements)


def test_python_and_compiled_paths_agree(building, record):
    noise = MeasurementNoise(acceleration_rms=0.05, displacement_rms=1e-3, force_rms=1e3)
    compiled = simulate(building, record, controller=get_controller("clipped-optimal"), noise=noise, seed=7)
    python = simulate(building, record, controller=PythonOnly(get_controller("clipped-optimal")),
                      noise=noise, seed=7)
    assert compiled.info["controller"] == "clipped-optimal"
    np.testing.assert_array_equal(python.measurements, compiled.measurements)
    np.testing.assert_array_equal(python.voltage, compiled.voltage)
    np.testing.assert_array_equal(python.base_displacement, compiled.base_displacement)
    # The controller really switched.
    assert 0 < np.mean(compiled.voltage > 0) < 1


def test_noise_is_seeded_and_reproducible(building, record):
    noise = MeasurementNoise(acceleration_rms=0.1, displacement_rms=2e-3, force_rms=5e3)
    a = simulate(building, record, controller="clipped-optimal", noise=noise, seed=1)
    b = simulate(building, record, controller="clipped-optimal", noise=noise, seed=1)
    c = simulate(building, record, controller="clipped-optimal", noise=noise, seed=2)
    np.testing.assert_array_equal(a.measurements, b.measurements)
    np.testing.assert_array_equal(a.base_displacement, b.base_displacement)
    assert not np.array_equal(a.measurements, c.measurements)


def test_measurements_match_the_linear_model(shared_dir, records_dir):
    # Linear isolation: the kernel's measurement vector equals C z + D F of linear_model.
    building = Building.default(isolation="linear", structure_path=shared_dir / "benchmark" / "structure.json")
    record = _first_seconds(load_benchmark_record("elcentro", "FN-x", records_dir=records_dir), 5.0)
    result = simulate(building, record, controller="passive-on", control_step=0.01)
    lm = linear_model(building, isolation="linear-part")
    ratio = 2
    z = result.state[::ratio]
    f = result.device_force[::ratio]
    expected = z @ lm.C.T + f @ lm.D.T + result.ground_acceleration[::ratio] @ lm.D_g.T
    assert result.measurements.shape == (len(z), n_measurements(16))
    scale = np.abs(expected).max(axis=0) + 1e-12
    assert np.all(np.abs(result.measurements - expected) <= 1e-9 * scale)
    s = measurement_slices(16)
    np.testing.assert_allclose(result.measurements[:, s["base_displacement"]], result.base_displacement[::ratio])
    np.testing.assert_allclose(result.measurements[:, s["device_displacement"]], result.device_displacement[::ratio])
    np.testing.assert_allclose(result.measurements[:, s["floor_acceleration"]],
                               result.floor_acceleration_absolute[::ratio].reshape(-1, 24), rtol=1e-9, atol=1e-9)
    # Voltages are held over each control step (zero-order hold).
    assert np.all(result.voltage[0:-1:2] == result.voltage[1::2])


def test_linear_model_state_space_reproduces_the_kernel(shared_dir, records_dir):
    # The continuous (A, B, E) of linear_model, discretised here, reproduces a passive run's
    # base displacement when the device forces the kernel computed are fed back in as inputs.
    import scipy.signal

    building = Building.default(isolation="linear", structure_path=shared_dir / "benchmark" / "structure.json")
    record = _first_seconds(load_benchmark_record("kobe", "FN-x", records_dir=records_dir), 6.0)
    result = simulate(building, record, controller="passive-on")
    lm = linear_model(building, isolation="linear-part")
    nz = lm.n_states
    sys = (lm.A, np.hstack([lm.B, lm.E]), np.eye(nz), np.zeros((nz, lm.n_devices + 2)))
    Ad, Bd, Cd, Dd, _ = scipy.signal.cont2discrete(sys, record.dt, method="foh")
    u = np.hstack([result.device_force, result.ground_acceleration])
    x0 = -Dd @ u[0]
    _, y, _ = scipy.signal.dlsim((Ad, Bd, Cd, Dd, record.dt), u, x0=x0)
    rows = lm.base_rows()["displacement"]
    np.testing.assert_allclose(y[:, rows], result.base_displacement,
                               atol=1e-3 * np.abs(result.base_displacement).max())


def test_controller_output_errors(building, record):
    short = _first_seconds(record, 0.5)

    class WrongSize:
        name = "wrong-size"

        def step(self, y):
            return np.zeros(3)

    class NotFinite:
        name = "nan"

        def step(self, y):
            return np.full(16, np.nan)

    with pytest.raises(InputError, match="wrong-size"):
        simulate(building, short, controller=WrongSize())
    with pytest.raises(NumericalError, match="nan"):
        simulate(building, short, controller=NotFinite())


def test_python_controller_voltages_are_applied_and_saturated(building, record):
    short = _first_seconds(record, 2.0)
    calls = []

    def half_then_too_much(y):
        calls.append(y.copy())
        return np.full(16, 0.5 if len(calls) < 100 else 5.0)

    result = simulate(building, short, controller=half_then_too_much, control_step=0.01)
    assert len(calls) == result.measurements.shape[0] == (len(short.acceleration) - 1) // 2 + 1
    assert np.all(result.voltage[:198] == 0.5)
    assert np.all(result.voltage[200:] == 1.0)  # saturated at the damper's 1 V
    assert np.all(np.isnan(result.desired_force))


def test_a_slow_python_controller_is_named_with_its_time(building, record):
    """A controller called from Python whose step() is most of the run's time is named in the run's
    notes with its time per control step; a fast one, and a compiled one, are not."""
    import time

    from benchmark.simulator.simulation import SLOW_CONTROLLER_SECONDS, slow_controller_note

    class Sleepy:
        name = "sleepy"

        def reset(self, context):
            self.n = context.n_devices

        def step(self, measurements):
            time.sleep(0.004)
            return np.zeros(self.n)

    short = _first_seconds(record, 3.0)  # 601 control steps: about 2.4 s asleep
    slow = simulate(building, short, controller=Sleepy())
    assert slow.info["controller_calls"] == 601 and slow.info["controller_s"] > SLOW_CONTROLLER_SECONDS
    (note,) = [n for n in slow.info["notes"] if "sleepy" in n]
    assert "ms per control step, 601 steps" in note and "compiled.py" in note
    fast = simulate(building, short, controller=PythonOnly(get_controller("passive-on")))
    compiled = simulate(building, short, controller="clipped-optimal")
    assert not any("per control step" in n for run in (fast, compiled) for n in run.info["notes"])
    assert compiled.info["controller_calls"] == 0
    # the rule itself: at least SLOW_CONTROLLER_SECONDS and half of the run
    assert slow_controller_note("c", 3.0, 4.0, 600) is not None
    assert slow_controller_note("c", 3.0, 7.0, 600) is None
    assert slow_controller_note("c", 1.0, 1.2, 600) is None
