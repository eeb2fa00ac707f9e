"""The closed-form Park–Wen update (``integrator="closed-form"``) against solve_ivp and the RK4 path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from benchmark.simulator.isolation import FrictionPendulumBearing, LeadRubberBearing, bearing_total_force
from benchmark.simulator.isolation.park_wen import park_wen_chord
from benchmark.simulator.isolation.registry import bearing_step_closed_form
from benchmark.simulator.oracle import OracleModel
from benchmark.simulator.peaks import peaks_of
from benchmark.simulator.simulation import simulate
from records import load_benchmark_record

A, BETA, GAMMA = 1.0, 0.1, 0.9
# the bearings and orbits of test_isolation_bearings.py
BEARINGS = {"lead-rubber": LeadRubberBearing(k_initial=9.86e6, alpha=0.1, yield_force=1.227e5),
            "friction-pendulum": FrictionPendulumBearing(weight=2.2e6, radius=2.24, mu_max=0.06, mu_min=0.03,
                                                         rate_parameter=20.0)}
T_ORACLE = np.arange(0.0, 2.0 + 1e-12, 0.005)


def _orbit(a, period, kind):
    w = 2 * math.pi / period
    if kind == "circle":
        return (lambda t: np.array([a * np.sin(w * t), a * (1.0 - np.cos(w * t))]),
                lambda t: np.array([a * w * np.cos(w * t), a * w * np.sin(w * t)]))
    return (lambda t: np.array([a * np.sin(w * t), 0.5 * a * np.sin(2 * w * t)]),
            lambda t: np.array([a * w * np.cos(w * t), a * w * np.cos(2 * w * t)]))


MOTIONS = {"circle": _orbit(0.15, 2.0, "circle"), "figure-eight": _orbit(0.15, 2.0, "figure-eight")}


def run_oracle(bearing, u, v, t):
    """solve_ivp (DOP853, tight tolerances, bounded step) of the bearing's equations; force (n, 2)."""
    def rhs(tt, s):
        uu, vv = u(tt), v(tt)
        return bearing.rates(s, uu[0], uu[1], vv[0], vv[1])
    sol = solve_ivp(rhs, (t[0], t[-1]), bearing.initial_state(), method="DOP853", t_eval=t,
                    rtol=1e-10, atol=1e-12, max_step=5e-4)
    assert sol.success
    return np.array([bearing.force(sol.y[:, k], *u(tk), *v(tk)) for k, tk in enumerate(t)])


def rel_err(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


def _chord_ivp(z0, e, A=A, beta=BETA, gamma=GAMMA):
    def rhs(_s, z):
        gx = beta + gamma * np.sign(e[0] * z[0])
        gy = beta + gamma * np.sign(e[1] * z[1])
        p = gx * z[0] * e[0] + gy * z[1] * e[1]
        return A * e - z * p
    sol = solve_ivp(rhs, (0.0, 1.0), z0, method="DOP853", rtol=1e-11, atol=1e-13)
    return sol.y[:, -1]


def _random_chords(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        z0 = rng.uniform(-1.0, 1.0, 2)
        if np.hypot(*z0) > 1.0:
            z0 /= 1.0001 * np.hypot(*z0)
        # chords from 1e-3 Y (pre-sliding) to 20 Y (a fast step of a friction pendulum)
        e = rng.normal(size=2) * 10.0 ** rng.uniform(-3.0, 1.3)
        yield z0, e


def test_chord_update_is_the_exact_flow():
    # loading, unloading through zero in one or both components, pre-sliding and saturated
    worst = 0.0
    for z0, e in _random_chords(200, 2):
        z1 = np.array(park_wen_chord(z0[0], z0[1], e[0], e[1], A, BETA, GAMMA)[:2])
        worst = max(worst, np.abs(z1 - _chord_ivp(z0, e)).max())
    assert worst < 1e-7


def test_chord_update_other_shape_parameters():
    # A != beta + gamma (saturation radius sqrt(A / (beta + gamma))) and beta = gamma
    for a, b, g in ((1.5, 0.3, 0.7), (1.0, 0.5, 0.5), (0.6, 0.05, 0.95)):
        for z0, e in _random_chords(30, 5):
            z1 = np.array(park_wen_chord(z0[0], z0[1], e[0], e[1], a, b, g)[:2])
            assert np.abs(z1 - _chord_ivp(z0, e, a, b, g)).max() < 1e-7, (a, b, g, z0, e)


def test_chord_tangent_matches_finite_differences_when_loading():
    rng = np.random.default_rng(7)
    for _ in range(50):
        z0 = rng.uniform(0.05, 0.7, 2) * rng.choice([-1.0, 1.0], 2)
        e = np.sign(z0) * 10.0 ** rng.uniform(-1.0, 1.0, 2)   # both components loading
        out = park_wen_chord(z0[0], z0[1], e[0], e[1], A, BETA, GAMMA)
        J = np.array(out[2:]).reshape(2, 2)
        h = 1e-6
        fd = np.empty((2, 2))
        for j in range(2):
            ep, em = e.copy(), e.copy()
            ep[j] += h
            em[j] -= h
            fd[:, j] = (np.array(park_wen_chord(z0[0], z0[1], ep[0], ep[1], A, BETA, GAMMA)[:2])
                        - np.array(park_wen_chord(z0[0], z0[1], em[0], em[1], A, BETA, GAMMA)[:2])) / (2 * h)
        assert np.abs(J - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max()), (z0, e, J, fd)


def test_chord_update_is_stable_for_huge_steps():
    # 1e4 yield displacements in one step: no overflow, the state lands on the saturation circle
    zx, zy = park_wen_chord(0.3, -0.2, 8.0e3, 6.0e3, A, BETA, GAMMA)[:2]
    assert math.isfinite(zx) and math.isfinite(zy)
    assert zx == pytest.approx(0.8, abs=1e-6) and zy == pytest.approx(0.6, abs=1e-6)


def _run_closed_form(bearing, u, v, t):
    p = bearing.to_array()
    state = bearing.initial_state()
    hyst, total, tangent = np.zeros(2), np.zeros(2), np.zeros((2, 4))
    U = np.array([u(tk) for tk in t])
    V = np.array([v(tk) for tk in t])
    out = np.zeros((t.size, 2))
    out[0] = bearing.force(state, *U[0], *V[0])
    for k in range(1, t.size):
        bearing_step_closed_form(bearing.kernel, p, state, U[k - 1, 0], U[k - 1, 1], U[k, 0], U[k, 1],
                                 V[k - 1, 0], V[k - 1, 1], V[k, 0], V[k, 1], t[k] - t[k - 1], hyst, tangent)
        bearing_total_force(p, U[k, 0], U[k, 1], V[k, 0], V[k, 1], hyst, total)
        out[k] = total
    return out, U, V


@pytest.mark.parametrize("motion", sorted(MOTIONS))
@pytest.mark.parametrize("name", sorted(BEARINGS))
def test_closed_form_bearing_matches_solve_ivp_on_biaxial_orbits(name, motion):
    """Biaxial orbits at 5-ms steps: the chord replaces a curved path, so the hysteretic force
    is off by about half the path's turning angle per step (here 1-2 %: 0.16 m at a 2-s period),
    the total force far less."""
    bearing = BEARINGS[name]
    u, v = MOTIONS[motion]
    f_k, U, V = _run_closed_form(bearing, u, v, T_ORACLE)
    f_o = run_oracle(bearing, u, v, T_ORACLE)
    k, c = bearing.linear_part()
    h_k = f_k - k * U - c * V
    h_o = f_o - k * U - c * V
    assert rel_err(h_k, h_o) < 3e-2
    assert rel_err(f_k, f_o) < 1e-2


@pytest.mark.parametrize("name", sorted(BEARINGS))
def test_closed_form_bearing_is_exact_on_a_straight_path(name):
    """Along a straight line (any direction) every monotone piece is its own chord: the update
    is exact up to where the Hermite path places the reversals."""
    bearing = BEARINGS[name]
    w = 2 * math.pi / 1.5
    d = np.array([0.6, 0.8])

    def u(t):
        return d * 0.12 * math.sin(w * t)

    def v(t):
        return d * 0.12 * w * math.cos(w * t)
    t = T_ORACLE
    f_k, U, V = _run_closed_form(bearing, u, v, t)
    f_o = run_oracle(bearing, u, v, t)
    k, c = bearing.linear_part()
    assert rel_err(f_k - k * U - c * V, f_o - k * U - c * V) < 2e-3


def test_unknown_integrator_is_refused(shared_dir, records_dir):
    building = Building.default(isolation="linear", devices=None,
                                structure_path=shared_dir / "benchmark" / "structure.json")
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    with pytest.raises(InputError, match="integrator"):
        simulate(building, record, integrator="euler")


@pytest.mark.slow
@pytest.mark.parametrize("name,orientation,seconds", [("elcentro", "FN-x", 6.0), ("erzikan", "FP-x", 5.0)])
def test_closed_form_building_matches_solve_ivp(shared_dir, records_dir, name, orientation, seconds):
    """The building with the closed-form bearing updates against the solve_ivp oracle, at the
    oracle tests' tolerance (0.5 %; measured 0.27 % and 0.16 %, where RK4 gives 0.04 % and 0.006 %)."""
    building = Building.default(isolation="friction-lrb", devices=None,
                                structure_path=shared_dir / "benchmark" / "structure.json")
    full = load_benchmark_record(name, orientation, records_dir=records_dir)
    n = int(round(seconds / full.dt)) + 1
    record = full.replace(acceleration=np.ascontiguousarray(full.acceleration[:n]))
    result = simulate(building, record, integrator="closed-form")
    assert result.energy_balance_error() <= 1e-3
    oracle = OracleModel(building, record)
    ref = peaks_of(oracle.result(oracle.solve(n))).as_dict()
    mine = peaks_of(result).as_dict()
    for key in ref:
        assert mine[key] == pytest.approx(ref[key], rel=5e-3), key
