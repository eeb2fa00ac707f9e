"""The Spencer-type kernel's per-device memo changes the cost of a step, never its result.

The building's fixed-point iteration advances every damper several times from the same state
(:mod:`benchmark.simulator.stepping`), and consecutive steps start where the last one ended:
:func:`damper.models.spencer.spencer_type_step_memo` keeps the voltage laws' values for both
(docs/performance.md). Its results must be those of the plain
:func:`damper.models.spencer.spencer_type_step`: the same arithmetic on the same inputs, only
fewer evaluations. Not bit for bit: the two are compiled separately and the last digits follow
the compiled code's shape (a fresh clone's compilation differed from another in the 16th digit),
so they are compared to 1e-12 relative, 10 000 times the rounding of one step and far below
what a stale memo entry moves (the laws at another field value: the field changes by ~14 % of its
gap per step, the laws by 1e-3 or more).
"""

from __future__ import annotations

import numpy as np
import pytest

from damper.models.spencer import MEMO_LENGTH, spencer_type_step, spencer_type_step_memo
from damper.models.virtual import VirtualBenchmarkDamper
from damper.models.voltage_laws import Polynomial, Saturating, Tabulated, law_value, law_value_pair, law_value_triple


def _packed(*laws):
    """Two or more laws packed one after the other, and their offsets."""
    arrays = [np.asarray(law.to_array(), dtype=np.float64) for law in laws]
    offsets = np.cumsum([0] + [a.size for a in arrays[:-1]])
    return np.concatenate(arrays), [int(o) for o in offsets]


@pytest.mark.parametrize("first, second", [
    (Saturating(100.0e3, 150.0e3, 0.5, 1.0), Saturating(5.0e6, 25.0e6, 0.5, 1.0)),   # one tanh shared
    (Saturating(1.0, 2.0, 0.55, 1.3), Saturating(3.0, -4.0, 0.55, 1.3)),             # shared, with pow
    (Saturating(1.0, 2.0, 0.5, 1.0), Saturating(3.0, 4.0, 0.6, 1.0)),                # different c
    (Saturating(1.0, 2.0, 0.5, 1.0), Saturating(3.0, 4.0, 0.5, 1.2)),                # different e
    (Polynomial((2.0, 3.0)), Saturating(3.0, 4.0, 0.5, 1.0)),                        # other kinds
    (Saturating(3.0, 4.0, 0.5, 1.0), Polynomial((2.0, 3.0, -1.0))),
])
def test_law_pair_is_two_law_values(first, second):
    params, (o0, o1) = _packed(first, second)
    for v in (-0.3, 0.0, 1e-300, 1e-9, 0.1, 0.37, 0.5, 1.0, 3.0, 10.0, 40.0):
        pair = law_value_pair(params, o0, o1, v)
        assert pair == pytest.approx((law_value(params, o0, v), law_value(params, o1, v)), rel=1e-14), v



_NODES3 = (0.0, 1.1, 2.25)


@pytest.mark.parametrize("laws", [
    # the residual loop's Spencer-type base: three laws on the same nodes share the basis
    (Tabulated(_NODES3, (338.0, 562.0, 799.0)), Tabulated(_NODES3, (1.9e3, 1.0e5, 9.4e4)),
     Tabulated(_NODES3, (1.8e3, 2.8e3, 2.7e3))),
    (Tabulated((0.0, 2.25), (300.0, 800.0)), Tabulated((0.0, 2.25), (2e3, 9e4)),
     Tabulated((0.0, 2.25), (1e3, 3e3))),
    (Tabulated((0.0, 0.5, 1.0, 1.5, 2.0), (1.0, 4.0, 2.0, 5.0, 3.0)),
     Tabulated((0.0, 0.5, 1.0, 1.5, 2.0), (0.0, -1.0, 1.0, -1.0, 0.0)),
     Tabulated((0.0, 0.5, 1.0, 1.5, 2.0), (7.0, 7.0, 8.0, 9.0, 9.5))),
    # not shared: other nodes, other node counts, other kinds (the plain evaluations)
    (Tabulated(_NODES3, (1.0, 2.0, 3.0)), Tabulated((0.0, 1.2, 2.25), (1.0, 2.0, 3.0)),
     Tabulated(_NODES3, (3.0, 2.0, 1.0))),
    (Tabulated(_NODES3, (1.0, 2.0, 3.0)), Tabulated((0.0, 2.25), (1.0, 3.0)),
     Tabulated(_NODES3, (3.0, 2.0, 1.0))),
    (Tabulated(_NODES3, (1.0, 2.0, 3.0)), Saturating(3.0, 4.0, 0.5, 1.0), Saturating(5.0, 6.0, 0.5, 1.0)),
    (Polynomial((2.0, 3.0)), Tabulated(_NODES3, (1.0, 2.0, 3.0)), Tabulated(_NODES3, (3.0, 2.0, 1.0))),
])
def test_law_triple_is_three_law_values(laws):
    # The same arithmetic as three law_value calls, its shared part done once; compared to
    # 1e-14 relative rather than bit for bit because the two are compiled separately (see the
    # module docstring). A wrong interval, node or slope moves a value by 1e-3 or more.
    params, offsets = _packed(*laws)
    for v in (-0.5, 0.0, 1e-9, 0.3, 0.5, 0.77, 1.0, 1.1, 1.1000001, 1.7, 2.0, 2.2, 2.25, 2.5, 10.0):
        triple = law_value_triple(params, *offsets, v)
        expected = tuple(law_value(params, o, v) for o in offsets)
        assert triple == pytest.approx(expected, rel=1e-14, abs=1e-300), v

def _voltages(n: int, rng) -> np.ndarray:
    """A bang-bang command with holds of 1-40 steps (the field moving) and a few of 250 (the
    field settles: eta = 30/s takes ~0.9 s to within 1e-12)."""
    v = np.empty(n)
    k = 0
    level = 0.0
    while k < n:
        hold = int(rng.integers(1, 40)) if rng.random() < 0.9 else 250
        v[k:k + hold] = level
        level = 1.0 - level if rng.random() < 0.8 else level
        k += hold
    return v


@pytest.mark.parametrize("fill", [np.nan, 0.0])
def test_memo_step_equals_plain_step_through_iterations_and_switching(fill):
    model = VirtualBenchmarkDamper()
    params = np.ascontiguousarray(model.to_array(), dtype=np.float64)
    rng = np.random.default_rng(7)
    dt = 0.005
    n = 1200
    t = np.arange(n + 1) * dt
    x = 0.02 * np.sin(2 * np.pi * 1.3 * t) + 0.004 * np.sin(2 * np.pi * 4.1 * t)
    xd = 0.02 * 2 * np.pi * 1.3 * np.cos(2 * np.pi * 1.3 * t) + 0.004 * 2 * np.pi * 4.1 * np.cos(2 * np.pi * 4.1 * t)
    volts = _voltages(n, rng)
    plain = np.array(model.initial_state(), dtype=np.float64)
    memo_state = plain.copy()
    memo = np.full(MEMO_LENGTH, fill)
    for k in range(n):
        if k == n // 2:
            # a new run from rest with the same memo (its entries are then another field's)
            plain[:] = model.initial_state()
            memo_state[:] = plain
        # the building's iteration: guesses of the step's end first, then the accepted end, all
        # from the same start state
        start = memo_state.copy()
        for guess in range(int(rng.integers(0, 3))):
            trial = start.copy()
            spencer_type_step_memo(params, trial, x[k], x[k + 1] * (1 + 0.01 * (guess + 1)), xd[k],
                                   xd[k + 1] * (1 - 0.02 * (guess + 1)), volts[k], dt, memo)
        memo_state[:] = start
        f_memo = spencer_type_step_memo(params, memo_state, x[k], x[k + 1], xd[k], xd[k + 1], volts[k], dt, memo)
        f_plain = spencer_type_step(params, plain, x[k], x[k + 1], xd[k], xd[k + 1], volts[k], dt)
        assert f_memo == pytest.approx(f_plain, rel=1e-12, abs=1e-9), k
        np.testing.assert_allclose(memo_state, plain, rtol=1e-12, atol=1e-15, err_msg=str(k))
