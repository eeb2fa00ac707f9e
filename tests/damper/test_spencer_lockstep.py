"""The Spencer-type devices advanced in lock-step give each device's own update.

:func:`damper.models.spencer.spencer_type_lockstep` takes sub-step *k* of every device together
(their RK4 chains overlap in the processor) and leaves to the per-device update the devices it
cannot take (sigma > 1, more sub-steps than the memo holds). Each device must come out as
:func:`damper.models.spencer.spencer_type_step_memo` leaves it: the same arithmetic on the same
inputs in another order of devices. Compared to 1e-12 relative, not bit for bit, for the reason
``tests/damper/test_spencer_memo.py`` gives (separately compiled code may differ in the last
digit); a wrong node law, sub-step count or stage moves the force by 1e-6 or more.
"""

from __future__ import annotations

import numpy as np

from damper.models.base import KERNEL_BOUC_WEN, KERNEL_SPENCER_TYPE
from damper.models.bouc_wen import NormalizedBoucWen
from damper.models.registry import devices_step_memo, devices_workspace, device_step_memo
from damper.models.spencer import (LOCKSTEP_MAX_SUBSTEPS, LOCKSTEP_NODE_COLUMNS, MEMO_LENGTH, SPENCER_LOCKSTEP_ROWS,
                                   spencer_type_lockstep, spencer_type_step_memo)
from damper.models.virtual import VirtualBenchmarkDamper


def _devices():
    """Devices of one kernel with different shapes: the benchmark's, a stiffer field, n = 1 and 2,
    sigma > 1 (the per-device update's loading-first path), a fast field."""
    models = [VirtualBenchmarkDamper(), VirtualBenchmarkDamper(rho=300.0), VirtualBenchmarkDamper(n=1.0),
              VirtualBenchmarkDamper(n=2.0, sigma=0.6), VirtualBenchmarkDamper(sigma=3.0),
              VirtualBenchmarkDamper(eta=200.0), VirtualBenchmarkDamper(substep_tolerance=0.01)]
    models = (models * 3)[:16]
    arrays = [m.to_array() for m in models]
    width = max(a.size for a in arrays)
    params = np.zeros((len(arrays), width))
    for j, a in enumerate(arrays):
        params[j, :a.size] = a
    return params


def _paths(rng, n_dev, n_steps, dt):
    """Random motions, some fast enough to need more sub-steps than the lock-step takes."""
    t = np.arange(n_steps + 1) * dt
    x = np.empty((n_dev, t.size))
    xd = np.empty((n_dev, t.size))
    for j in range(n_dev):
        amp = rng.uniform(0.01, 0.3) if j % 5 else 1.5  # every fifth device far beyond the cap
        f = rng.uniform(0.3, 3.0)
        ph = rng.uniform(0, 2 * np.pi)
        x[j] = amp / (2 * np.pi * f) * np.sin(2 * np.pi * f * t + ph)
        xd[j] = amp * np.cos(2 * np.pi * f * t + ph)
    return x, xd


def test_lockstep_equals_each_device_on_its_own():
    rng = np.random.default_rng(7)
    params = _devices()
    n_dev = params.shape[0]
    dt = 0.005
    x, xd = _paths(rng, n_dev, 400, dt)
    # commands switching at random (the field moving most of the time) and some held (settled)
    volts = (rng.uniform(size=(n_dev, 400)) < 0.1).cumsum(axis=1) % 2 * 1.0
    volts[::4] = 0.7
    state_a = np.zeros((n_dev, 3))
    state_b = np.zeros((n_dev, 3))
    memo_a = np.full((n_dev, MEMO_LENGTH), np.nan)
    memo_b = np.full((n_dev, MEMO_LENGTH), np.nan)
    lock = np.ones(n_dev, dtype=np.bool_)
    ws = np.empty((SPENCER_LOCKSTEP_ROWS, n_dev))
    nodes = np.empty((n_dev, LOCKSTEP_NODE_COLUMNS))
    order = np.empty(n_dev, dtype=np.int64)
    n_subs = np.empty(n_dev, dtype=np.int64)
    fa = np.empty(n_dev)
    fb = np.empty(n_dev)
    for k in range(400):
        start_a = state_a.copy()
        start_b = state_b.copy()
        for it in range(3):  # the building's iterations: the same step again from its start
            state_a[:] = start_a
            state_b[:] = start_b
            x1 = x[:, k + 1] * (1.0 + 1e-3 * it)
            spencer_type_lockstep(params, state_a, memo_a, lock, x[:, k], x1, xd[:, k], xd[:, k + 1],
                                  volts[:, k], dt, ws, nodes, order, n_subs, fa)
            for j in range(n_dev):
                fb[j] = spencer_type_step_memo(params[j], state_b[j], x[j, k], x1[j], xd[j, k], xd[j, k + 1],
                                               volts[j, k], dt, memo_b[j])
            np.testing.assert_allclose(fa, fb, rtol=1e-12, atol=1e-12 * np.abs(fb).max())
            np.testing.assert_allclose(state_a, state_b, rtol=1e-12, atol=1e-15)
    # the devices the lock-step leaves to the per-device update were among them: sigma > 1, and
    # every fifth device at 1.5 m/s, which needs 120 x 1.4 x 1.5 x 0.005 / 0.05 = 25 sub-steps
    assert LOCKSTEP_MAX_SUBSTEPS < 25 and (params[:, 6] > 1.0).any()
    assert np.isfinite(fa).all()


def test_a_mixed_set_of_devices_through_the_registry():
    """Spencer-type devices in lock-step beside a device of another kernel, which keeps its own
    update; without lock-step (the reference path) the same forces."""
    rng = np.random.default_rng(3)
    spencer = [VirtualBenchmarkDamper().to_array(), VirtualBenchmarkDamper(rho=200.0).to_array()]
    other = NormalizedBoucWen(kappa_xdot=2.0e5, kappa_w=4.0e5, rho=150.0, sigma=0.8, n=1.5).to_array()
    arrays = spencer + [other]
    ids = np.array([KERNEL_SPENCER_TYPE] * len(spencer) + [KERNEL_BOUC_WEN], dtype=np.int64)
    width = max(a.size for a in arrays)
    params = np.zeros((len(arrays), width))
    for j, a in enumerate(arrays):
        params[j, :a.size] = a
    n = len(arrays)
    dt = 0.005
    x, xd = _paths(rng, n, 200, dt)
    states = [np.zeros((n, 4)), np.zeros((n, 4))]
    forces = [np.empty(n), np.empty(n)]
    works = [devices_workspace(ids, True), devices_workspace(ids, False)]
    assert works[0].lock.tolist() == [True] * len(spencer) + [False] * (n - len(spencer))
    assert not works[1].lock.any()
    v = np.full(n, 0.6)
    for k in range(200):
        v[:] = 1.0 if k % 50 < 20 else 0.2
        for st, f, ws in zip(states, forces, works):
            ws.x0[:] = x[:, k]
            ws.x1[:] = x[:, k + 1]
            ws.xd0[:] = xd[:, k]
            ws.xd1[:] = xd[:, k + 1]
            devices_step_memo(ids, params, st, v, dt, ws, f)
        np.testing.assert_allclose(forces[0], forces[1], rtol=1e-12, atol=1e-9)
    # and each equals device_step_memo on its own
    st = np.zeros((n, 4))
    memo = np.full((n, MEMO_LENGTH), np.nan)
    f = np.empty(n)
    for k in range(200):
        for j in range(n):
            f[j] = device_step_memo(ids[j], params[j], st[j], x[j, k], x[j, k + 1], xd[j, k], xd[j, k + 1],
                                    1.0 if k % 50 < 20 else 0.2, dt, memo[j])
    np.testing.assert_allclose(forces[0], f, rtol=1e-12, atol=1e-9)


def test_a_step_no_tolerance_can_follow_poisons_only_its_device():
    params = _devices()[:3]
    params[1, 0] = 1e-12  # a sub-step tolerance no step can meet
    n = 3
    state = np.zeros((n, 3))
    memo = np.full((n, MEMO_LENGTH), np.nan)
    f = np.empty(n)
    spencer_type_lockstep(params, state, memo, np.ones(n, dtype=np.bool_), np.zeros(n), np.full(n, 1e-3),
                          np.full(n, 0.2), np.full(n, 0.2), np.ones(n), 0.005,
                          np.empty((SPENCER_LOCKSTEP_ROWS, n)), np.empty((n, LOCKSTEP_NODE_COLUMNS)),
                          np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), f)
    assert np.isnan(f[1]) and np.isnan(state[1]).all()
    assert np.isfinite(f[[0, 2]]).all() and np.isfinite(state[[0, 2]]).all()
