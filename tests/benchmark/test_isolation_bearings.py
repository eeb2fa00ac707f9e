"""Bearing kernels against a solve_ivp oracle under prescribed biaxial motions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import ParameterError
from benchmark.simulator.isolation import (FrictionPendulumBearing, LeadRubberBearing, LinearBearing,
                                 bearing_step, bearing_total_force, bearing_type, linear_part)
from benchmark.simulator.isolation.park_wen import park_wen_substeps

W = 2.2e6


def lrb(**kw):
    base = dict(k_initial=9.86e6, alpha=0.1, yield_force=1.227e5)
    base.update(kw)
    return LeadRubberBearing(**base)


def fp(**kw):
    base = dict(weight=W, radius=2.24, mu_max=0.06, mu_min=0.03, rate_parameter=20.0)
    base.update(kw)
    return FrictionPendulumBearing(**base)


def circle(a, period):
    w = 2 * math.pi / period

    def u(t):
        return np.array([a * np.sin(w * t), a * (1.0 - np.cos(w * t))])

    def v(t):
        return np.array([a * w * np.cos(w * t), a * w * np.sin(w * t)])
    return u, v


def figure_eight(a, period):
    w = 2 * math.pi / period

    def u(t):
        return np.array([a * np.sin(w * t), 0.5 * a * np.sin(2 * w * t)])

    def v(t):
        return np.array([a * w * np.cos(w * t), a * w * np.cos(2 * w * t)])
    return u, v


def run_kernel(bearing, u, v, t):
    """Step the numba kernel along samples of the motion; total force (n, 2)."""
    p = bearing.to_array()
    state = bearing.initial_state()
    hyst = np.zeros(2)
    total = np.zeros(2)
    out = np.zeros((t.size, 2))
    states = np.zeros((t.size, bearing.n_states))
    U = np.array([u(tk) for tk in t])
    V = np.array([v(tk) for tk in t])
    fx, fy = bearing.force(state, *U[0], *V[0])
    out[0] = fx, fy
    for k in range(1, t.size):
        bearing_step(bearing.kernel, p, state, U[k - 1, 0], U[k - 1, 1], U[k, 0], U[k, 1],
                     V[k - 1, 0], V[k - 1, 1], V[k, 0], V[k, 1], t[k] - t[k - 1], hyst)
        bearing_total_force(p, U[k, 0], U[k, 1], V[k, 0], V[k, 1], hyst, total)
        out[k] = total
        states[k] = state
    return out, states


def run_oracle(bearing, u, v, t):
    """solve_ivp (DOP853, tight tolerances, bounded step) of the same equations; force (n, 2)."""
    def rhs(tt, s):
        uu, vv = u(tt), v(tt)
        return bearing.rates(s, uu[0], uu[1], vv[0], vv[1])
    sol = solve_ivp(rhs, (t[0], t[-1]), bearing.initial_state(), method="DOP853", t_eval=t,
                    rtol=1e-10, atol=1e-12, max_step=5e-4)
    assert sol.success
    f = np.array([bearing.force(sol.y[:, k], *u(tk), *v(tk)) for k, tk in enumerate(t)])
    return f, sol.y.T


def rel_err(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


MOTIONS = {"circle": circle(0.15, 2.0), "figure-eight": figure_eight(0.15, 2.0)}
BEARINGS = {"lead-rubber": lrb(), "friction-pendulum": fp()}
T_ORACLE = np.arange(0.0, 2.0 + 1e-12, 0.005)
_ORACLE_CACHE: dict = {}


def oracle(name, motion):
    """The solve_ivp reference for a bearing and motion on T_ORACLE (computed once)."""
    if (name, motion) not in _ORACLE_CACHE:
        _ORACLE_CACHE[name, motion] = run_oracle(BEARINGS[name], *MOTIONS[motion], T_ORACLE)
    return _ORACLE_CACHE[name, motion]


@pytest.mark.parametrize("motion", sorted(MOTIONS))
@pytest.mark.parametrize("name", sorted(BEARINGS))
def test_kernel_matches_solve_ivp_oracle(name, motion):
    bearing = BEARINGS[name]
    u, v = MOTIONS[motion]
    t = T_ORACLE
    f_k, _ = run_kernel(bearing, u, v, t)
    f_o, _ = oracle(name, motion)
    # the hysteretic part alone (the linear part is identical by construction)
    k, c = bearing.linear_part()
    U = np.array([u(tk) for tk in t])
    V = np.array([v(tk) for tk in t])
    h_k = f_k - k * U - c * V
    h_o = f_o - k * U - c * V
    assert rel_err(h_k, h_o) < 3e-4
    assert rel_err(f_k, f_o) < 1e-4


@pytest.mark.parametrize("name", sorted(BEARINGS))
def test_kernel_converges_as_tolerance_tightens(name):
    u, v = MOTIONS["figure-eight"]
    t = T_ORACLE
    base = BEARINGS[name]
    import dataclasses
    f_o, _ = oracle(name, "figure-eight")
    errors = []
    for tol in (1.5, 0.5, 0.1):
        f_k, _ = run_kernel(dataclasses.replace(base, substep_tolerance=tol), u, v, t)
        errors.append(rel_err(f_k, f_o))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-3


@pytest.mark.parametrize("name", sorted(BEARINGS))
def test_circular_orbit_resultant_saturates_at_yield_not_sqrt2(name):
    bearing = BEARINGS[name]
    u, v = circle(0.2, 4.0)  # speed 0.31 m/s, far beyond yield
    t = np.arange(0.0, 4.0 + 1e-12, 0.005)
    _, states = run_kernel(bearing, u, v, t)
    z_norm = np.hypot(states[:, 0], states[:, 1])
    late = z_norm[t > 1.0]
    assert np.all(np.abs(late - 1.0) < 1e-3)  # |z| = 1: resultant force = Q_d or mu W, not sqrt(2) times
    # and the hysteretic force opposes... follows the velocity direction once sliding
    V = np.array([v(tk) for tk in t])
    cosang = (states[:, 0] * V[:, 0] + states[:, 1] * V[:, 1]) / (z_norm * np.hypot(V[:, 0], V[:, 1]) + 1e-300)
    assert np.all(cosang[t > 1.0] > 0.9)


def test_friction_force_follows_velocity_dependent_coefficient():
    bearing = fp()
    # straight-line sliding at constant speed 0.5 m/s: force -> W/R u + mu(0.5) W
    speed = 0.5
    t = np.arange(0.0, 0.4 + 1e-12, 0.005)
    f, _ = run_kernel(bearing, lambda tt: np.array([speed * tt, 0.0]), lambda tt: np.array([speed, 0.0]), t)
    mu = 0.06 - 0.03 * math.exp(-20.0 * speed)
    expected = W / 2.24 * speed * t[-1] + mu * W
    assert f[-1, 0] == pytest.approx(expected, rel=1e-6)
    assert abs(f[-1, 1]) < 1e-6 * W


def test_lead_rubber_initial_stiffness_and_post_yield_branch():
    b = lrb()
    # tiny motion: initial stiffness k_initial
    t = np.linspace(0.0, 1.0, 201)
    d = 1e-6
    f, _ = run_kernel(b, lambda tt: np.array([d * tt, 0.0]), lambda tt: np.array([d, 0.0]), t)
    assert f[-1, 0] / d == pytest.approx(b.k_initial, rel=1e-3)
    # large monotonic motion: post-yield branch alpha k u + Q_d
    big = 0.3
    f, _ = run_kernel(b, lambda tt: np.array([big * tt, 0.0]), lambda tt: np.array([big, 0.0]), t)
    assert f[-1, 0] == pytest.approx(b.post_yield_stiffness * big + b.characteristic_strength, rel=1e-4)


def test_linear_bearing_kernel_returns_zero_hysteretic_force():
    b = LinearBearing(919.422e3, 27.717e3)
    out = np.full(2, 7.0)
    bearing_step(b.kernel, b.to_array(), np.zeros(0), 0.0, 0.0, 0.01, 0.02, 0.0, 0.0, 1.0, 2.0, 0.005, out)
    assert np.all(out == 0.0)
    assert linear_part(b.kernel, b.to_array()) == (919.422e3, 27.717e3)
    assert b.force(np.zeros(0), 0.1, 0.2, 1.0, 0.0) == pytest.approx((919.422e3 * 0.1 + 27.717e3, 919.422e3 * 0.2))


def test_linear_part_convention_every_type():
    assert lrb().linear_part() == pytest.approx((0.1 * 9.86e6, 0.0))
    assert fp(c=5.0).linear_part() == pytest.approx((W / 2.24, 5.0))


def test_unknown_type_id_gives_nan_and_python_lookup_raises():
    out = np.zeros(2)
    bearing_step(99, np.zeros(11), np.zeros(2), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.005, out)
    assert np.all(np.isnan(out))
    with pytest.raises(ParameterError, match="unknown"):
        bearing_type(99)
    with pytest.raises(ParameterError, match="friction-pendulum"):
        bearing_type("teflon")


@pytest.mark.parametrize("factory, field, value", [
    (lrb, "alpha", 1.0), (lrb, "k_initial", -1.0), (lrb, "yield_force", float("nan")),
    (lrb, "beta", 2.0), (fp, "radius", 0.0), (fp, "mu_min", 0.2), (fp, "mu_max", 1.5),
    (fp, "rate_parameter", -1.0), (fp, "substep_tolerance", 0.0),
])
def test_invalid_parameters_raise_parameter_error_naming_the_field(factory, field, value):
    with pytest.raises(ParameterError, match=field):
        factory(**{field: value})


def test_substep_rule_scales_with_displacement_and_survives_nan():
    n1 = park_wen_substeps(0.0, 0.0, 1e-3, 0.0, 0.0, 0.0, 0.2, 0.0, 0.005, 5e-4, 1.0, 0.1, 0.9, 0.1)
    n2 = park_wen_substeps(0.0, 0.0, 2e-3, 0.0, 0.0, 0.0, 0.4, 0.0, 0.005, 5e-4, 1.0, 0.1, 0.9, 0.1)
    assert n1 == math.ceil(2.0 / 5e-4 * 1e-3 / 0.1)
    assert n2 == pytest.approx(2 * n1, abs=1)
    n_nan = park_wen_substeps(0.0, 0.0, float("nan"), 0.0, 0.0, 0.0, 0.0, 0.0, 0.005, 5e-4, 1.0, 0.1, 0.9, 0.1)
    assert n_nan >= 1


from hypothesis import given, settings, strategies as st  # noqa: E402


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), amplitude=st.floats(1e-4, 0.5), tol=st.sampled_from([0.1, 0.5, 1.0]))
def test_hysteretic_state_stays_bounded_on_random_biaxial_paths(seed, amplitude, tol):
    """With A = beta + gamma = 1 the resultant |z| never exceeds 1 (up to the RK4 error)."""
    rng = np.random.default_rng(seed)
    n = 200
    dt = 0.005
    u = amplitude * np.cumsum(rng.standard_normal((n, 2)), axis=0) / np.sqrt(n)
    v = np.gradient(u, dt, axis=0)
    p = fp(substep_tolerance=tol).to_array()
    state = np.zeros(2)
    out = np.zeros(2)
    zmax = 0.0
    for k in range(1, n):
        bearing_step(2, p, state, u[k - 1, 0], u[k - 1, 1], u[k, 0], u[k, 1],
                     v[k - 1, 0], v[k - 1, 1], v[k, 0], v[k, 1], dt, out)
        zmax = max(zmax, math.hypot(state[0], state[1]))
    assert np.all(np.isfinite(state))
    assert zmax <= 1.0 + 1e-3
    assert math.hypot(*out) <= 0.06 * W * (1.0 + 1e-3)
