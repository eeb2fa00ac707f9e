"""Tests of the compiled controller representation and its numba kernel."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from benchmark.foundation.errors import NumericalError, ParameterError
from controllers.compiled import (LAW_CLIPPED_OPTIMAL, LAW_LYAPUNOV, LAW_MODULATED, STATUS_NONFINITE,
                                  STATUS_OK, CompiledController, constant_voltage, controller_update,
                                  run_compiled)


def _gain_controller(law_id, gain, n_meas=3, n_dev=2, law_params=0.0, v_max=1.0, slew=np.inf, **kw):
    """Static controller f_c = gain * y[0] for every device."""
    Dc = np.zeros((n_dev, n_meas))
    Dc[:, 0] = gain
    return CompiledController(name="test", n_meas=n_meas, n_devices=n_dev, control_step=0.01,
                              law_id=law_id, law_params=law_params, v_max=v_max, slew_rate=slew,
                              Dc=Dc, **kw)


def test_constant_voltage_outputs_the_voltage_every_step():
    c = constant_voltage(4, 0.7, n_meas=5)
    y = np.random.default_rng(0).normal(size=(20, 5))
    v, fd, states = run_compiled(c, y)
    assert np.all(v == 0.7)
    assert np.all(fd == 0.0)
    assert states.shape == (21, 0)


def test_constant_voltage_per_device_and_slew_ramp():
    c = constant_voltage(2, [0.2, 1.0], n_meas=2, control_step=0.01, slew_rate=20.0)
    v, _, _ = run_compiled(c, np.zeros((10, 2)))
    # 0.2 V per step: device 0 reaches 0.2 at once, device 1 ramps 0.2, 0.4, ... 1.0
    np.testing.assert_allclose(v[:, 0], 0.2)
    np.testing.assert_allclose(v[:6, 1], [0.2, 0.4, 0.6, 0.8, 1.0, 1.0])


def test_clipped_optimal_truth_table():
    # f_c = y[0]; device force = last two measurements
    c = _gain_controller(LAW_CLIPPED_OPTIMAL, 1.0, v_max=2.0)
    cases = [  # (fc, f, expected v)
        (5.0, 2.0, 2.0),    # |fc| > |f|, same sign -> increase force
        (1.0, 2.0, 0.0),    # |fc| < |f| -> release
        (-5.0, 2.0, 0.0),   # opposite sign -> release
        (-5.0, -2.0, 2.0),
        (-1.0, -2.0, 0.0),
        (5.0, 0.0, 0.0),    # H(0) = 0
    ]
    for fc, f, expected in cases:
        v, fd, _ = run_compiled(c, np.array([[fc, f, f]]))
        assert fd[0, 0] == fc
        assert np.all(v[0] == expected), (fc, f, v)


def test_modulated_law_scales_with_desired_force_and_saturates():
    c = _gain_controller(LAW_MODULATED, 1.0, v_max=1.0, law_params=[10.0, 20.0])
    v, _, _ = run_compiled(c, np.array([[5.0, 1.0, 1.0], [50.0, 1.0, 1.0], [0.5, 1.0, 1.0]]))
    np.testing.assert_allclose(v[0], [0.5, 0.25])
    np.testing.assert_allclose(v[1], [1.0, 1.0])
    np.testing.assert_allclose(v[2], [0.0, 0.0])


def test_lyapunov_law_uses_sign_term():
    c = _gain_controller(LAW_LYAPUNOV, 1.0, v_max=1.5)
    v, _, _ = run_compiled(c, np.array([[1.0, -3.0, 3.0]]))
    np.testing.assert_allclose(v[0], [1.5, 0.0])


def test_linear_dynamics_match_numpy_recursion():
    rng = np.random.default_rng(1)
    n_c, n_meas, n_dev, n = 4, 6, 3, 50
    Ac = 0.5 * rng.normal(size=(n_c, n_c)) / np.sqrt(n_c)
    Bc, Cc, Dc = rng.normal(size=(n_c, n_meas)), rng.normal(size=(n_dev, n_c)), rng.normal(size=(n_dev, n_meas))
    xc0 = rng.normal(size=n_c)
    c = CompiledController(name="lin", n_meas=n_meas, n_devices=n_dev, control_step=0.005,
                           law_id=LAW_CLIPPED_OPTIMAL, law_params=0.0, v_max=1.0, slew_rate=np.inf,
                           Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc, xc0=xc0)
    y = rng.normal(size=(n, n_meas))
    v, fd, states = run_compiled(c, y)
    x = xc0.copy()
    for k in range(n):
        np.testing.assert_allclose(fd[k], Cc @ x + Dc @ y[k], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(states[k], x, rtol=1e-12, atol=1e-12)
        f = y[k, -n_dev:]
        np.testing.assert_array_equal(v[k], np.where((fd[k] - f) * f > 0, 1.0, 0.0))
        x = Ac @ x + Bc @ y[k]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=30),
       st.floats(0.1, 5.0), st.floats(1.0, 500.0))
def test_voltage_always_within_limits_and_slew(values, v_max, slew):
    c = _gain_controller(LAW_CLIPPED_OPTIMAL, 1.0, n_meas=2, n_dev=1, v_max=v_max, slew=slew)
    y = np.array([[val, 1.0 if i % 2 else -1.0] for i, val in enumerate(values)])
    v, _, _ = run_compiled(c, y)
    assert np.all(v >= 0.0) and np.all(v <= v_max)
    dv = np.diff(np.concatenate([[0.0], v[:, 0]]))
    assert np.all(np.abs(dv) <= slew * 0.01 + 1e-12)


def test_nonfinite_state_is_reported():
    c = _gain_controller(LAW_CLIPPED_OPTIMAL, 1.0)
    args = c.kernel_arguments()
    xc, v = c.initial_state()
    fd = np.empty(2)
    status = controller_update(*args, np.array([np.nan, 0.0, 0.0]), np.zeros(2), xc, v, fd)
    assert status == STATUS_NONFINITE
    status = controller_update(*args, np.array([1.0, 0.0, 0.0]), np.zeros(2), xc, v, fd)
    assert status == STATUS_OK
    with pytest.raises(NumericalError, match="not finite"):
        run_compiled(c, np.array([[0.0, 1.0, 1.0], [np.inf, 1.0, 1.0]]))


@pytest.mark.parametrize("kwargs, match", [
    (dict(law_id=9), "law_id 9 unknown"),
    (dict(v_max=[1.0, 1.0, 1.0]), "v_max has shape"),
    (dict(Dc=np.zeros((2, 4))), "Dc has shape"),
    (dict(Ac=np.eye(2), Bc=np.zeros((2, 3)), Cc=np.zeros((3, 2))), "Cc has shape"),
    (dict(law_id=0, law_params=2.0), "constant voltages must lie"),
    (dict(law_id=2, law_params=0.0), "force capacity"),
    (dict(slew_rate=0.0), "slew_rate"),
    (dict(control_step=-1.0), "control_step"),
    (dict(Dc=np.full((2, 3), np.nan)), "NaN"),
])
def test_bad_parameters_raise_parameter_error_naming_the_field(kwargs, match):
    base = dict(name="bad", n_meas=3, n_devices=2, control_step=0.01, law_id=1, law_params=0.0,
                v_max=1.0, slew_rate=np.inf)
    base.update(kwargs)
    with pytest.raises(ParameterError, match=match):
        CompiledController(**base)


def test_arrays_are_read_only():
    c = constant_voltage(2, 1.0)
    with pytest.raises(ValueError):
        c.v_max[0] = 3.0
