"""Every library effect alone at three strengths, with and without noise, and in pairs (issue 13, item 5).

A device is the base model with the effect(s); its strength is the RMS of the force the effect
changes over the RMS of the device's force (:func:`_share`), set by bisection on the effect's
parameter. Where an effect is at least 5 % of the force, the loop must name it and its held-out
error must fall at least by half (the error above the noise floor: a 2 % noise stays in any
model's error). The default suite runs one strength with noise for the effects
the issue found missed (acceleration, direction of motion) and a voltage lag; the whole matrix
is marked slow.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import NormalizedBoucWen
from damper.diagnosis import diagnose
from damper.diagnosis.synthetic import PlayDevice, sinusoidal_tests, step_voltage_tests
from damper.diagnosis.effects import EFFECT_NAMES, Motion, get_effect
from damper.models.voltage_laws import Polynomial

BASE = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5)
#: a base whose force depends on the voltage, so that a voltage lag shows
BASE_V = NormalizedBoucWen(Polynomial((1000.0, 3000.0)), Polynomial((200.0, 1500.0)), 400.0, 1.0, 1.5)
STRENGTHS = (0.03, 0.08, 0.2)
NOISES = (0.0, 0.02)


def _tests(effects, noise, seed=5, steps=False):
    names = {e.name for e in effects}
    if steps or "voltage_lag" in names:
        return step_voltage_tests(AugmentedModel(BASE_V, effects), samples_per_cycle=200,
                                  noise=noise, seed=seed)
    return sinusoidal_tests(AugmentedModel(BASE, effects), noise=noise, seed=seed)


def _share(effect) -> float:
    """RMS of the force change the effect makes, over the RMS of the device's force."""
    base = BASE_V if effect.name == "voltage_lag" else BASE
    clean = _tests((), 0.0, steps=effect.name == "voltage_lag")
    num = den = 0.0
    for t in clean:
        v = t.voltage if effect.name == "voltage_lag" else 0.0
        m = Motion(t.time, t.displacement, t.velocity, np.gradient(t.velocity, t.time), v)
        f0 = AugmentedModel(base).force(m)
        f1 = AugmentedModel(base, (effect,)).force(m)
        num += float(np.sum((f1 - f0) ** 2))
        den += float(np.sum(f1 ** 2))
    return math.sqrt(num / den)


def _effect_at(name: str, share: float):
    """The effect whose share of the force is ``share`` (bisection on its parameter)."""
    cls = get_effect(name)
    sign = -1.0 if name == "fade" else 1.0  # a fading force (the physical direction)
    lo, hi = 0.0, 1.0
    scale = {"stiffness": 1e5, "offset": 1e3, "inertia": 1e3, "quadratic_damping": 1e6,
             "asymmetry": 0.9, "direction": 0.9, "fade": 0.09, "voltage_lag": 0.3,
             "roll_off": 1.0, "shear_thinning": 1e4}[name]
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if _share(cls(cls.neutral + sign * mid * scale)) < share:
            lo = mid
        else:
            hi = mid
    return cls(cls.neutral + sign * 0.5 * (lo + hi) * scale)


def _check(effects, noise, min_share):
    d = diagnose(_tests(effects, noise))
    if min_share >= 0.05:
        for e in effects:
            assert e.name in d.effects, (e, d.effects, d.error_before, d.error_after)
        # the measurement noise stays in any model's error: what must halve is the rest
        floor = noise / math.sqrt(1.0 + noise ** 2)
        before = math.sqrt(max(d.error_before ** 2 - floor ** 2, 0.0))
        after = math.sqrt(max(d.error_after ** 2 - floor ** 2, 0.0))
        assert after <= 0.5 * before, (d.effects, d.error_before, d.error_after)
    else:
        assert d.error_after <= d.error_before + 1e-12
    return d


_CACHE: dict = {}


def _effect(name, share):
    key = (name, share)
    if key not in _CACHE:
        _CACHE[key] = _effect_at(name, share)
    return _CACHE[key]


def test_share_bisection_hits_the_target():
    e = _effect("inertia", 0.08)
    assert _share(e) == pytest.approx(0.08, rel=0.02)


@pytest.mark.parametrize("name", ["inertia", "direction", "voltage_lag"])
def test_effect_alone_default(name):
    _check((_effect(name, 0.08),), 0.02, 0.08)


@pytest.mark.slow
@pytest.mark.parametrize("noise", NOISES)
@pytest.mark.parametrize("strength", STRENGTHS)
@pytest.mark.parametrize("name", EFFECT_NAMES)
def test_effect_alone_matrix(name, strength, noise):
    _check((_effect(name, strength),), noise, strength)


#: Pairs whose sum the base model itself carries: a convex (quadratic) and a concave
#: (shear-thinning) viscous term at equal shares add up to nearly a linear viscous force over
#: the tests' velocities, which the base's kappa_xdot absorbs (checked below).
_CANCELLING = ({"quadratic_damping", "shear_thinning"},)
_PAIRS = [p for p in itertools.combinations(EFFECT_NAMES, 2)
          if "voltage_lag" not in p and {"asymmetry", "direction"} != set(p)
          and set(p) not in _CANCELLING]


@pytest.mark.slow
@pytest.mark.parametrize("pair", _PAIRS, ids=["+".join(p) for p in _PAIRS])
def test_pairs_matrix(pair):
    _check(tuple(_effect(n, 0.1) for n in pair), 0.02, 0.1)


@pytest.mark.slow
def test_opposite_curvatures_cancel_into_the_base_model():
    d = diagnose(_tests(tuple(_effect(n, 0.1) for n in ("quadratic_damping", "shear_thinning")), 0.02))
    assert d.error_before <= 1.2 * 0.02, d.error_before  # at the noise floor: nothing to find


def test_a_term_that_pays_only_once_another_is_in():
    """Unequal convex and concave viscous terms (quadratic damping 15 %, shear thinning 8 % of
    the force) on another base, three sinusoids up to 7 Hz at 1 kHz: in round 1 shear
    thinning's joint refit goes to k = 0 (the quadratic term is still missing), and it pays
    only in round 2. The loop kept a memory of such failures and never retried it, adding a
    near-neutral roll_off instead (a review of unseen devices, 2026-11-26: its one miss in 20).
    Values: the effects at those shares, set by bisection as ``_effect_at`` does."""
    base = NormalizedBoucWen(1000.0, 700.0, 500.0, 1.0, 1.5)
    effects = (get_effect("quadratic_damping")(24959.69), get_effect("shear_thinning")(251.80))
    tests = []
    for i, (a, f) in enumerate(((0.01, 1.0), (0.004, 3.0), (0.003, 7.0))):
        tests += sinusoidal_tests(AugmentedModel(base, effects), motions=((a, f),),
                                  samples_per_cycle=int(round(1000.0 / f)), noise=0.015, seed=300 + i)
    d = diagnose(tests)
    assert set(d.effects) == {"quadratic_damping", "shear_thinning"}, (d.effects, d.error_after)
    floor = 0.015 / math.sqrt(1.0 + 0.015 ** 2)
    excess = [math.sqrt(max(e ** 2 - floor ** 2, 0.0)) for e in (d.error_before, d.error_after)]
    assert excess[1] <= 0.5 * excess[0], (d.error_before, d.error_after)


def test_effect_outside_the_library_is_reported_with_where_it_lives():
    d = diagnose(sinusoidal_tests(PlayDevice(AugmentedModel(BASE), gap=0.0008), noise=0.01, seed=1))
    assert d.unexplained
    assert {v for v, _, _ in d.unexplained_in} & {"loop", "displacement", "velocity", "sign"}
