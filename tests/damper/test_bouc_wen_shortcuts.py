"""The Bouc-Wen kernel's shortcuts give the plain kernel's results.

* :func:`damper.models.bouc_wen.bouc_wen_step_memo` keeps the coefficients at the step's voltage;
  it does the same arithmetic on the same values as :func:`~damper.models.bouc_wen.bouc_wen_step`.
  Compared at 1e-12 relative, not bit for bit: numba compiles the two call paths separately and
  the code's shape (inlining, the host CPU) can move the last digits, as a fresh clone's
  `make test` showed; a stale memo (the coefficients of another voltage, tens of percent apart)
  moves the force by 1e-2 or more.
* :func:`~damper.models.bouc_wen.bouc_wen_piece` skips the return distance's quadrature when a
  lower bound of it exceeds the piece; the bound must hold for every admissible state.
"""

from __future__ import annotations

import numpy as np
import pytest

from damper.models.bouc_wen import (BOUC_WEN_MEMO_LENGTH, ExtendedBoucWen, _distance_to_zero,
                                    bouc_wen_step, bouc_wen_step_memo)
from damper.models.response import simulate
from damper.models.voltage_laws import Tabulated

MODEL = ExtendedBoucWen(kappa_x=2.0e5,
                        kappa_xdot=Tabulated((0.0, 0.5, 1.0), (9.0e4, 2.0e5, 2.5e5)),
                        kappa_w=Tabulated((0.0, 0.5, 1.0), (6.0e4, 7.5e5, 1.0e6)),
                        rho=120.0, sigma=0.94, n=1.39)


#: Force scale of MODEL [N] (kappa_w at 1 V), for the absolute part of the tolerances.
SCALE = 1.0e6


def _motion(n=3000, dt=0.005, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    x = 0.15 * np.sin(2 * np.pi * 0.4 * t) + 0.01 * np.sin(2 * np.pi * 3.1 * t) + 1e-4 * rng.normal(size=n)
    return t, x, np.gradient(x, t)


def test_memo_step_equals_plain_step_under_switching_voltage():
    t, x, xd = _motion()
    v = np.where(np.sin(2 * np.pi * 1.7 * t) > 0, 1.0, 0.0)
    v[1000:1200] = 0.37  # a held intermediate level, then back to bang-bang
    params = MODEL.to_array()
    plain, memo_state = MODEL.initial_state().copy(), MODEL.initial_state().copy()
    memo = np.full(BOUC_WEN_MEMO_LENGTH, np.nan)
    for k in range(t.size - 1):
        args = (x[k], x[k + 1], xd[k], xd[k + 1], v[k], t[k + 1] - t[k])
        f_plain = bouc_wen_step(params, plain, *args)
        f_memo = bouc_wen_step_memo(params, memo_state, *args, memo)
        assert f_memo == pytest.approx(f_plain, rel=1e-12, abs=1e-12 * SCALE), k
        assert memo_state[0] == pytest.approx(plain[0], rel=1e-12, abs=1e-15), k


def test_simulate_through_the_memo_gives_the_plain_steps_forces():
    t, x, xd = _motion(seed=1)
    v = np.where(np.sin(2 * np.pi * 0.9 * t) > 0, 0.8, 0.1)
    params = MODEL.to_array()
    state = MODEL.initial_state().copy()
    expected = [MODEL.force(state, x[0], xd[0], v[0])]
    for k in range(t.size - 1):
        expected.append(bouc_wen_step(params, state, x[k], x[k + 1], xd[k], xd[k + 1], v[k], t[k + 1] - t[k]))
    force = simulate(MODEL, t, x, xd, v=v).force
    np.testing.assert_allclose(force[1:], np.array(expected[1:]), rtol=1e-12, atol=1e-12 * SCALE)


@pytest.mark.parametrize("sigma", [0.5, 0.94, 3.0, 40.0])
@pytest.mark.parametrize("n", [1.0, 1.39, 2.0, 4.5])
def test_return_distance_is_at_least_its_bound(sigma, n):
    """The shortcut's premise: the quadrature of the return distance is never below
    |w| / (rho (1 + (2 sigma - 1) |w|^n)), so skipping it when that bound exceeds the piece
    takes the same branch as computing it."""
    rho = 120.0
    for aw in np.linspace(1e-6, 1.0, 101):
        bound = aw / (rho * (1.0 + (2.0 * sigma - 1.0) * aw ** n))
        assert _distance_to_zero(aw, rho, sigma, n) >= bound * (1.0 - 1e-15)

