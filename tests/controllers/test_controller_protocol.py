"""Tests of the controller protocol, passive controllers, output validation and noise."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from controllers.base import (Controller, ControlContext, ControllerSession, FunctionController,
                              as_controller, check_voltages, measurement_slices, n_measurements)
from controllers.noise import MeasurementNoise
from controllers.passive import ConstantVoltage, PassiveOff, PassiveOn


@pytest.fixture
def context():
    return ControlContext(n_devices=4, control_step=0.01, voltage_max=[1.0, 1.0, 2.0, 2.0])


def test_measurement_layout_is_contiguous_and_complete():
    s = measurement_slices(5)
    covered = np.concatenate([np.arange(40)[sl] for sl in s.values()])
    np.testing.assert_array_equal(covered, np.arange(n_measurements(5)))


def test_passive_controllers_compiled_and_python_paths_agree(context):
    y = np.zeros(context.n_measurements)
    off, on = PassiveOff(), PassiveOn()
    for controller, expected in ((off, np.zeros(4)), (on, context.voltage_max)):
        session = ControllerSession(controller, context)
        assert session.compiled is not None
        np.testing.assert_array_equal(session.step(y), expected)
        np.testing.assert_array_equal(session.compiled.law_params, expected)


def test_constant_voltage_above_device_maximum_is_rejected(context):
    with pytest.raises(ParameterError, match="exceeds"):
        ConstantVoltage(1.5).reset(context)


class _WrongSize(Controller):
    name = "wrong-size"

    def step(self, measurements):
        return np.zeros(3)


class _NaNAtSecondStep(Controller):
    name = "nan-later"

    def reset(self, context):
        super().reset(context)
        self.k = 0

    def step(self, measurements):
        self.k += 1
        return np.full(self.context.n_devices, np.nan if self.k == 2 else 0.5)


def test_wrong_sized_output_stops_with_input_error_naming_controller(context):
    session = ControllerSession(_WrongSize(), context)
    with pytest.raises(InputError, match=r"'wrong-size' returned voltages of shape \(3,\) at t = 0 s"):
        session.step(np.zeros(context.n_measurements))


def test_nan_output_stops_with_numerical_error_naming_time(context):
    session = ControllerSession(_NaNAtSecondStep(), context)
    session.step(np.zeros(context.n_measurements))
    with pytest.raises(NumericalError, match=r"'nan-later'.*non-finite.*t = 0.01 s"):
        session.step(np.zeros(context.n_measurements))


def test_non_numeric_output_is_input_error():
    with pytest.raises(InputError, match="expected 2 voltages"):
        check_voltages("abc", 2, "bad", 0.0)


def test_python_controller_is_saturated_and_slew_limited():
    ctx = ControlContext(n_devices=2, control_step=0.01, voltage_max=1.0, slew_rate=30.0)
    session = ControllerSession(lambda y: np.array([5.0, -1.0]), ctx)
    assert session.compiled is None
    v1 = session.step(np.zeros(ctx.n_measurements))
    v2 = session.step(np.zeros(ctx.n_measurements))
    np.testing.assert_allclose(v1, [0.3, 0.0])
    np.testing.assert_allclose(v2, [0.6, 0.0])


def test_function_controller_with_time(context):
    times = []
    fc = FunctionController(lambda t, y: (times.append(t), np.zeros(4))[1], with_time=True, name="f")
    session = ControllerSession(fc, context)
    for _ in range(3):
        session.step(np.zeros(context.n_measurements))
    np.testing.assert_allclose(times, [0.0, 0.01, 0.02])


def test_as_controller_rejects_non_controllers():
    with pytest.raises(InputError, match="no step"):
        as_controller(42)


def test_context_validation():
    with pytest.raises(ParameterError, match="voltage_max"):
        ControlContext(n_devices=2, control_step=0.01, voltage_max=[1.0])
    with pytest.raises(ParameterError, match="control_step"):
        ControlContext(n_devices=2, control_step=0.0, voltage_max=1.0)


def test_noise_is_seeded_and_has_requested_rms():
    noise = MeasurementNoise(acceleration_rms=0.1, displacement_rms=1e-3, force_rms=100.0, seed=7)
    a = noise.sample(20000, 3)
    b = MeasurementNoise(acceleration_rms=0.1, displacement_rms=1e-3, force_rms=100.0, seed=7).sample(20000, 3)
    np.testing.assert_array_equal(a, b)
    s = measurement_slices(3)
    rms = np.sqrt(np.mean(a ** 2, axis=0))
    np.testing.assert_allclose(rms[s["floor_acceleration"]][0::3], 0.1, rtol=0.05)
    np.testing.assert_allclose(rms[s["device_force"]], 100.0, rtol=0.05)
    np.testing.assert_allclose(rms[s["device_displacement"]], 1e-3, rtol=0.05)
    assert not np.array_equal(a, MeasurementNoise(acceleration_rms=0.1, seed=8).sample(20000, 3))


def test_noise_sensor_range_clips():
    noise = MeasurementNoise(force_range=10.0)
    y = np.full(n_measurements(1), 50.0)
    out = noise.apply(y, None, 1)
    assert out[-1] == 10.0 and out[0] == 50.0


def test_noise_rejects_negative_rms():
    with pytest.raises(ParameterError, match="force_rms"):
        MeasurementNoise(force_rms=-1.0)
