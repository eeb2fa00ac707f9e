"""Tests of the LQG machinery on a small base-isolated shear building assembled here."""

from __future__ import annotations

import numpy as np
import pytest

from controllers.compiled import LAW_CLIPPED_OPTIMAL, CompiledController, run_compiled
from controllers.lqg import (LinearPlant, estimator_fit, kalman_design, lqr_design, modal_reduction,
                             observer_controller, simulate_linear)

DT = 0.005


def shear_building(n_floors: int = 3) -> LinearPlant:
    """Base (index 0) + n floors, relative-to-ground coordinates; one device resisting base motion.

    Measurement vector: absolute accelerations (n+1), base displacement (1), device force (1).
    """
    n = n_floors + 1
    m = np.array([4000.0] + [1000.0] * n_floors)
    k = np.array([4000.0 * (2 * np.pi / 2.5) ** 2 * 1.6] + [2.0e6] * n_floors)  # isolation ~ 2.5 s
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    M = np.diag(m)
    Minv = np.diag(1 / m)
    Cdamp = 0.01 * K + 0.05 * M
    b = np.zeros((n, 1))
    b[0, 0] = -1.0   # the device's resisting force acts on the base with a minus sign
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ Cdamp]])
    B = np.vstack([np.zeros((n, 1)), Minv @ b])
    E = np.vstack([np.zeros((n, 1)), -np.ones((n, 1))])
    C = np.vstack([np.hstack([-Minv @ K, -Minv @ Cdamp]),
                   np.hstack([np.eye(n)[:1], np.zeros((1, n))]),
                   np.zeros((1, 2 * n))])
    D = np.vstack([Minv @ b, np.zeros((1, 1)), np.ones((1, 1))])
    return LinearPlant(A=A, B=B, E=E, C=C, D=D)


def _ground(n=2000, seed=3):
    rng = np.random.default_rng(seed)
    g = np.convolve(rng.normal(size=n), np.ones(10) / 10, mode="same") * 3.0
    return g[:, None]


@pytest.fixture(scope="module")
def plant():
    return shear_building()


def _design(plant, reduced=None):
    p = reduced.plant if reduced is not None else plant
    n = p.n_states
    sensor_rows = np.arange(5)  # 4 accelerations + base displacement
    Cz = np.vstack([p.C[4:5], p.C[0:4]])
    Dz = np.vstack([p.D[4:5], p.D[0:4]])
    Wz = np.diag([1 / 0.05 ** 2] + [1 / 1.0 ** 2] * 4)
    lqr = lqr_design(p.A, p.B, Cz, Dz, Wz, np.eye(1) / 1e5 ** 2)
    Ad, Bd, Ed = p.discretise(DT)
    V = np.diag([0.05 ** 2] * 4 + [1e-4 ** 2])
    kf = kalman_design(Ad, Ed, p.C[sensor_rows], np.eye(1), V)
    mats = observer_controller(Ad, Bd, p.C[sensor_rows], p.D[sensor_rows], kf["M"], -lqr["K"],
                               sensor_rows, np.array([5]), 6)
    return lqr, kf, mats


def test_riccati_residuals_are_small_and_loops_stable(plant):
    lqr, kf, _ = _design(plant)
    assert lqr["riccati_residual"] < 1e-8
    assert kf["riccati_residual"] < 1e-8
    assert np.all(lqr["closed_loop_poles"].real < 0)
    assert np.all(np.abs(kf["poles"]) < 1)


def test_estimator_tracks_true_states_noise_free(plant):
    """Open-loop run with a known force input: the compiled observer's state x̂[k|k-1] follows x."""
    _, _, (Ac, Bc, Cc, Dc) = _design(plant)
    ground = _ground()
    force = 2e4 * np.sin(2 * np.pi * 0.7 * np.arange(ground.shape[0]) * DT)[:, None]
    x, y = simulate_linear(plant, DT, ground, force)
    compiled = CompiledController(name="lqg", n_meas=6, n_devices=1, control_step=DT,
                                  law_id=LAW_CLIPPED_OPTIMAL, law_params=0.0, v_max=1.0,
                                  slew_rate=np.inf, Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)
    _, desired, states = run_compiled(compiled, y)
    fit = estimator_fit(x[500:], states[500:-1])
    assert np.all(fit > 97.0), fit  # ignoring the force input gives ~93 %
    # The desired force is -K x̂[k|k]; compare with -K x (true state).
    lqr, _, _ = _design(plant)
    true_desired = x @ (-lqr["K"]).T
    assert estimator_fit(true_desired[500:], desired[500:])[0] > 95.0


def test_modal_reduction_keeps_static_gain_and_slow_modes(plant):
    full = modal_reduction(plant, plant.n_states // 2)
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(full.plant.A)),
                               np.sort_complex(np.linalg.eigvals(plant.A)), rtol=1e-8)
    red = modal_reduction(plant, 2)
    assert red.plant.n_states == 4
    # Static gain from f to y is preserved by the static correction.
    g_full = plant.D - plant.C @ np.linalg.solve(plant.A, plant.B)
    g_red = red.plant.D - red.plant.C @ np.linalg.solve(red.plant.A, red.plant.B)
    np.testing.assert_allclose(g_red, g_full, rtol=1e-6, atol=1e-12)
    slowest = np.sort(np.abs(np.linalg.eigvals(plant.A)))[:4]
    np.testing.assert_allclose(np.sort(np.abs(red.eigenvalues.repeat(2))), slowest, rtol=1e-8)


def test_reduced_design_estimator_tracks_projected_states(plant):
    red = modal_reduction(plant, 2)
    _, _, (Ac, Bc, Cc, Dc) = _design(plant, red)
    ground = _ground(seed=5)
    x, y = simulate_linear(plant, DT, ground)
    compiled = CompiledController(name="lqg-red", n_meas=6, n_devices=1, control_step=DT,
                                  law_id=LAW_CLIPPED_OPTIMAL, law_params=0.0, v_max=1.0,
                                  slew_rate=np.inf, Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)
    _, _, states = run_compiled(compiled, y)
    base_disp_true = x[:, 0]
    base_disp_est = states[:-1] @ red.plant.C[4]
    assert estimator_fit(base_disp_true[500:, None], base_disp_est[500:, None])[0] > 90.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_riccati_designs_are_python_controls_bit_for_bit(seed):
    """controllers.lqg solves the two AREs with scipy operation for operation as python-control
    0.10 does (without importing it in every worker: it loads matplotlib); python-control is the oracle."""
    ct = pytest.importorskip("control")
    from controllers.lqg import _dlqe, _lqr
    rng = np.random.default_rng(seed)
    n, m, p = 18, 2, 6
    A = rng.normal(size=(n, n)) - 3 * np.eye(n)
    B = rng.normal(size=(n, m))
    Q = rng.normal(size=(n, n))
    Q = Q @ Q.T
    R = np.diag([2.0, 3.0])
    N = 0.01 * rng.normal(size=(n, m))
    for ours, theirs in zip(_lqr(A, B, Q, R, N), ct.lqr(A, B, Q, R, N)):
        np.testing.assert_array_equal(np.sort_complex(np.ravel(ours)) if np.iscomplexobj(ours) else ours,
                                      np.sort_complex(np.ravel(theirs)) if np.iscomplexobj(theirs) else theirs)
    Ad = np.eye(n) + 0.01 * A
    C = rng.normal(size=(p, n))
    W = 0.1 * np.eye(n)
    V = 0.01 * np.eye(p)
    for ours, theirs in zip(_dlqe(Ad, np.eye(n), C, W, V), ct.dlqe(Ad, np.eye(n), C, W, V)):
        np.testing.assert_array_equal(ours, theirs)


def test_the_building_design_imports_no_plotting_library():
    """A process that designs the clipped-optimal LQG (every suite worker) need not load
    matplotlib or python-control (~60-120 MB of resident memory each)."""
    import subprocess
    import sys
    code = ("import sys\n"
            "from benchmark.simulator.building import Building\n"
            "from benchmark.simulator.control import control_context\n"
            "from controllers.registry import get_controller\n"
            "c = get_controller('clipped-optimal')\n"
            "c.build(control_context(Building.default(), 0.005))\n"
            "assert c.design is not None\n"
            "print(sorted(m for m in ('matplotlib', 'control') if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "[]"
