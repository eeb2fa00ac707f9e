"""Normalized/extended Bouc-Wen: admissible class, kernel vs solve_ivp, convergence,
limit-cycle peak (DOMAIN.md §4) and the standard <-> normalized conversion."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper import ExtendedBoucWen, NormalizedBoucWen, StandardBoucWen, simulate
from damper.models.bouc_wen import limit_cycle_peak, limit_cycle_psi
from damper.models.registry import device_step, get_model_class
from damper.models.voltage_laws import Exponential, Polynomial


def _oracle(model, t, x_fun, xd_fun, v=0.0):
    """Force from solve_ivp(Radau) on the model's plain-numpy rates."""
    sol = solve_ivp(lambda tt, s: model.rates(s, x_fun(tt), xd_fun(tt), v), (t[0], t[-1]),
                    model.initial_state(), method="Radau", t_eval=t, rtol=1e-10, atol=1e-12,
                    max_step=1e-3)
    assert sol.success
    return np.array([model.force(sol.y[:, k], x_fun(tk), xd_fun(tk), v) for k, tk in enumerate(t)])


def _sine(amplitude, frequency):
    w = 2 * np.pi * frequency
    return (lambda tt: amplitude * np.sin(w * tt)), (lambda tt: amplitude * w * np.cos(w * tt))


@pytest.mark.parametrize("params", [
    dict(kappa_x=207e3, kappa_xdot=100e3, kappa_w=300e3, rho=40.0, sigma=0.8, n=1.0),
    dict(kappa_x=0.0, kappa_xdot=2e3, kappa_w=1e3, rho=300.0, sigma=3.0, n=2.0),
    dict(kappa_x=5e4, kappa_xdot=1e4, kappa_w=8e4, rho=25.0, sigma=0.5, n=1.7),
])
def test_kernel_matches_solve_ivp_under_sinusoid(params):
    model = ExtendedBoucWen(**params)
    x_fun, xd_fun = _sine(0.05, 1.3)
    t = np.arange(0.0, 2.0 + 1e-12, 0.005)
    reference = _oracle(model, t, x_fun, xd_fun)
    response = simulate(model, t, x_fun(t), xd_fun(t))
    error = np.max(np.abs(response.force - reference)) / np.max(np.abs(reference))
    assert error < 2e-4, error


def test_error_decreases_as_tolerance_tightens():
    base = dict(kappa_x=1e4, kappa_xdot=1e4, kappa_w=1e5, rho=200.0, sigma=2.0, n=1.5)
    x_fun, xd_fun = _sine(0.03, 2.0)
    t = np.arange(0.0, 1.0 + 1e-12, 0.01)
    reference = _oracle(ExtendedBoucWen(**base), t, x_fun, xd_fun)
    errors = []
    for tol in (0.8, 0.2, 0.05):
        response = simulate(ExtendedBoucWen(**base, substep_tolerance=tol), t, x_fun(t), xd_fun(t))
        errors.append(np.max(np.abs(response.force - reference)) / np.max(np.abs(reference)))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-3


@pytest.mark.parametrize("sigma, n", [(0.5, 1.0), (1.0, 2.0), (2.0, 1.5)])
@pytest.mark.parametrize("rho_dx", [2.0, 6.0])
def test_limit_cycle_peak_matches_psi_relation(sigma, n, rho_dx):
    amplitude = 0.02
    rho = rho_dx / (2 * amplitude)
    model = NormalizedBoucWen(kappa_xdot=1.0, kappa_w=1.0, rho=rho, sigma=sigma, n=n)
    t = np.linspace(0.0, 8.0, 16001)
    response = simulate(model, t, amplitude * np.sin(2 * np.pi * t))
    last_cycle = t >= 7.0
    w_peak = response.states[last_cycle, 0].max()
    w0 = limit_cycle_peak(rho * 2 * amplitude, sigma, n)
    assert w_peak == pytest.approx(w0, abs=2e-4)
    assert limit_cycle_psi(w0, sigma, n) == pytest.approx(rho_dx, rel=1e-8)


def test_limit_cycle_values_from_domain_notes():
    # n = 1, sigma = 1/2: w0 = 0.72 at rho dX = 2, 0.95 at 4, 0.993 at 6 (DOMAIN.md §4)
    for rho_dx, expected in ((2, 0.72), (4, 0.95), (6, 0.993)):
        assert limit_cycle_peak(rho_dx, 0.5, 1.0) == pytest.approx(expected, abs=3e-3)


def test_standard_normalized_conversion_keeps_the_loop():
    standard = StandardBoucWen(c0=3e3, k0=2e3, alpha=5e4, A=2.0, beta=300.0, gamma=100.0, n=2.0, D=1.5)
    normalized = standard.to_normalized()
    assert normalized.sigma == pytest.approx(0.75)
    x_fun, xd_fun = _sine(0.02, 1.0)
    t = np.arange(0.0, 2.0 + 1e-12, 0.002)
    sol = solve_ivp(lambda tt, s: standard.rates(s, x_fun(tt), xd_fun(tt)), (0, 2), [0.0],
                    method="Radau", t_eval=t, rtol=1e-10, atol=1e-13, max_step=1e-3)
    f_standard = np.array([standard.force(sol.y[:, k], x_fun(tk), xd_fun(tk)) for k, tk in enumerate(t)])
    f_normalized = simulate(normalized, t, x_fun(t), xd_fun(t)).force
    assert np.max(np.abs(f_standard - f_normalized)) < 1e-4 * np.max(np.abs(f_standard))
    # and back: another standard form (different A, D) gives the same normalized model
    again = normalized.to_standard(A=0.3, D=4.0).to_normalized()
    for name in normalized.parameter_names:
        assert getattr(again, name) == pytest.approx(getattr(normalized, name), rel=1e-12)


@pytest.mark.parametrize("field, value, match", [
    ("kappa_xdot", 0.0, "kappa_xdot"), ("kappa_w", -1.0, "kappa_w"), ("rho", 0.0, "rho"),
    ("sigma", 0.49, "sigma"), ("n", 0.9, "n"), ("kappa_x", -1.0, "kappa_x"),
    ("kappa_w", float("nan"), "kappa_w"), ("rho", "abc", "rho"),
])
def test_inadmissible_parameters_raise(field, value, match):
    params = dict(kappa_x=1.0, kappa_xdot=1.0, kappa_w=1.0, rho=1.0, sigma=1.0, n=1.0)
    params[field] = value
    with pytest.raises(ParameterError, match=match):
        ExtendedBoucWen(**params)


def test_voltage_law_checked_over_the_whole_range():
    # sigma = 0.6 - 0.2 v drops below 1/2 at v = 0.5 V
    with pytest.raises(ParameterError, match=r"sigma.*coil input 0\.5"):
        NormalizedBoucWen(kappa_xdot=1.0, kappa_w=1.0, rho=1.0, sigma=Polynomial((0.6, -0.2)), n=1.0)
    NormalizedBoucWen(kappa_xdot=1.0, kappa_w=1.0, rho=1.0, sigma=Polynomial((0.6, -0.2)), n=1.0,
                      voltage_range=(0.0, 0.4))


def test_standard_form_outside_admissible_class_raises():
    with pytest.raises(ParameterError, match="beta >= gamma"):
        StandardBoucWen(c0=1.0, k0=0.0, alpha=1.0, A=1.0, beta=0.1, gamma=0.9, n=1.0)


def test_voltage_dependent_model_and_voltage_out_of_range():
    model = ExtendedBoucWen(kappa_x=207e3, kappa_xdot=Polynomial((1e5, 5e4)),
                            kappa_w=Polynomial((5e4, 9.5e5)), rho=Exponential(30.0, 20.0, 14.0),
                            sigma=Exponential(0.8, 0.5, 14.0), n=Exponential(1.2, 0.5, 13.0))
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.02 * np.sin(2 * np.pi * t)
    f0 = simulate(model, t, x, v=0.0).force
    f1 = simulate(model, t, x, v=1.0).force
    assert np.ptp(f1) > 5 * np.ptp(f0)
    # the kernel at v equals the frozen model at v
    frozen = simulate(model.at_voltage(0.37), t, x, v=0.0).force
    assert np.allclose(simulate(model, t, x, v=0.37).force, frozen, rtol=0, atol=1e-6 * np.ptp(frozen))
    with pytest.raises(InputError, match="voltages in"):
        simulate(model, t, x, v=1.2)


def test_device_step_advances_state_in_place():
    model = NormalizedBoucWen(kappa_xdot=1e3, kappa_w=1e4, rho=50.0, sigma=1.0, n=1.0)
    state = model.initial_state()
    f = device_step(model.kernel, model.to_array(), state, 0.0, 0.01, 0.5, 0.5, 0.0, 0.02)
    # n = 1, sigma = 1 on loading from w = 0: w = 1 - exp(-rho x) exactly
    assert state[0] == pytest.approx(1 - np.exp(-0.5), rel=1e-7)
    assert f == pytest.approx(1e3 * 0.5 + 1e4 * state[0], rel=1e-12)


def test_registry_and_bad_motion():
    assert get_model_class("extended_bouc_wen") is ExtendedBoucWen
    with pytest.raises(InputError, match="unknown name"):
        get_model_class("nope")
    model = NormalizedBoucWen(kappa_xdot=1.0, kappa_w=1.0, rho=1.0, sigma=1.0, n=1.0)
    with pytest.raises(InputError, match="strictly increasing"):
        simulate(model, [0.0, 1.0, 1.0], [0.0, 0.1, 0.2])
    with pytest.raises(InputError, match="samples"):
        simulate(model, [0.0, 1.0, 2.0], [0.0, 0.1])
    with pytest.raises(InputError, match="finite"):
        simulate(model, [0.0, 1.0, 2.0], [0.0, np.nan, 0.1])


@pytest.mark.parametrize("n", [1.0, 1.4, 2.5])
def test_saturated_strokes_match_the_branch_solution(n):
    """Long strokes (rho X = 150) spend most of their travel saturated, where the kernel replaces
    the RK4 sub-steps by the branch's closed form; the state still follows dw/dx = rho d (1 - |w|^n)."""
    rho, sigma = 3000.0, 0.7
    model = NormalizedBoucWen(kappa_xdot=1.0, kappa_w=1.0, rho=rho, sigma=sigma, n=n)
    t = np.linspace(0.0, 1.0, 201)
    x = 0.05 * np.sin(2 * np.pi * t)  # up to 0.05, down to -0.05: saturated in both directions
    w = simulate(model, t, x, 0.1 * np.pi * np.cos(2 * np.pi * t)).states[:, 0]

    def dw_dx(_, s, d):  # the branch in displacement (rate-independent model)
        return [rho * (d - sigma * abs(s[0]) ** (n - 1.0) * s[0] + (sigma - 1.0) * d * abs(s[0]) ** n)]

    # reference: integrate in displacement along the monotone pieces up to the end of each step
    ref = np.empty_like(w)
    state = 0.0
    ref[0] = 0.0
    for k in range(t.size - 1):
        d = 1.0 if x[k + 1] > x[k] else -1.0
        # the motion reverses at t = 0.25 and 0.75 inside a step: split there
        turns = [s for s in (0.25, 0.75) if t[k] < s < t[k + 1]]
        points = [x[k]] + [0.05 * np.sin(2 * np.pi * s) for s in turns] + [x[k + 1]]
        for a, b in zip(points[:-1], points[1:]):
            if a == b:
                continue
            d = 1.0 if b > a else -1.0
            sol = solve_ivp(dw_dx, (0.0, abs(b - a)), [state], args=(d,), method="Radau",
                            rtol=1e-12, atol=1e-14)
            state = float(sol.y[0, -1])
        ref[k + 1] = state
    assert np.max(np.abs(w)) == pytest.approx(1.0, abs=1e-9)
    assert np.max(np.abs(w - ref)) < 1e-6
