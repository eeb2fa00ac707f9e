"""Effect library and the augmented model: neutral values, terms, composition, joint refit."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError, ParameterError
from damper.diagnosis.augmented import AugmentedModel, Parametrization, refit
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.diagnosis.effects import (EFFECT_NAMES, EFFECTS, Asymmetry, Fade, Inertia, Motion, Offset,
                                      QuadraticDamping, Stiffness, VoltageLag, get_effect)
from damper.models.field_filter import first_order_filter
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial

BASE = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5)


def _motion(freq=1.0, amp=0.01, n=801, v=0.0):
    t = np.linspace(0.0, 3.0 / freq, n)
    w = 2 * np.pi * freq
    return Motion(t, amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t), v,
                  name="sine")


def test_library_names_are_the_issue_names():
    assert EFFECT_NAMES == ("stiffness", "offset", "inertia", "voltage_lag", "quadratic_damping",
                            "shear_thinning", "asymmetry", "direction", "fade", "roll_off")
    with pytest.raises(InputError, match="unknown name 'friction'"):
        get_effect("friction")


@pytest.mark.parametrize("name", EFFECT_NAMES)
def test_neutral_effect_reproduces_the_base_model(name):
    m = _motion()
    base_force = simulate(BASE, m.t, m.x, m.xdot, 0.0).force
    force = AugmentedModel(BASE, (EFFECTS[name].off(),)).force(m)
    np.testing.assert_allclose(force, base_force, rtol=0, atol=1e-9)


def test_additive_and_factor_terms_follow_their_equations():
    m = _motion()
    fb = simulate(BASE, m.t, m.x, m.xdot, 0.0).force
    model = AugmentedModel(BASE, (Stiffness(3e4), Offset(50.0), Inertia(20.0), QuadraticDamping(1e4),
                                  Asymmetry(0.2), Fade(-0.05)))
    expected = (fb * (1 + 0.2 * np.sign(fb)) * (1 - 0.05 * m.elapsed) + 3e4 * m.x + 50.0
                + 20.0 * m.xddot + 1e4 * m.xdot * np.abs(m.xdot))
    np.testing.assert_allclose(model.force(m), expected, rtol=1e-12, atol=1e-9)
    # composition order: the factors before the additive terms, whatever the given order
    assert model.effect_names == ("asymmetry", "fade", "stiffness", "offset", "inertia",
                                  "quadratic_damping")


def test_stiffness_on_normalized_equals_extended_model():
    m = _motion()
    ext = ExtendedBoucWen(3e4, 2000.0, 800.0, 400.0, 1.0, 1.5)
    np.testing.assert_allclose(AugmentedModel(BASE, (Stiffness(3e4),)).force(m),
                               simulate(ext, m.t, m.x, m.xdot, 0.0).force, rtol=1e-12, atol=1e-9)
    with pytest.raises(ParameterError, match="already has kappa_x"):
        AugmentedModel(ext, (Stiffness(1.0),))


def test_first_order_filter_is_exact_for_a_ramp_and_identity_at_zero():
    t = np.linspace(0.0, 1.0, 11)
    v = 2.0 * t
    tau = 0.1
    u = first_order_filter(t, v, tau)
    # tau u' = v - u with u(0) = 0 and v = 2t:  u = 2(t - tau (1 - exp(-t/tau)))
    np.testing.assert_allclose(u, 2 * (t - tau * (1 - np.exp(-t / tau))), rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(first_order_filter(t, v, 0.0), v)
    with pytest.raises(ParameterError):
        first_order_filter(t, v, -1.0)


def test_voltage_lag_delays_the_response_to_a_voltage_step():
    base = NormalizedBoucWen(Polynomial((1000.0, 3000.0)), Polynomial((200.0, 1500.0)), 400.0, 1.0, 1.5)
    t = np.linspace(0.0, 2.0, 2001)
    v = (t >= 1.0).astype(float)
    m = Motion(t, 0.01 * np.sin(2 * np.pi * t), 0.02 * np.pi * np.cos(2 * np.pi * t), 0.0, v)
    r = AugmentedModel(base, (VoltageLag(0.05),)).response(m)
    k = np.searchsorted(t, 1.05)
    assert r.model_input[k] == pytest.approx(1 - np.exp(-1.0), abs=0.02)
    assert r.model_input.min() >= 0.0 and r.model_input.max() <= 1.0


@pytest.mark.parametrize("cls,bad", [(Stiffness, -1.0), (Inertia, -0.1), (QuadraticDamping, -1.0),
                                     (VoltageLag, -0.01), (Asymmetry, 1.5), (Offset, float("nan"))])
def test_inadmissible_parameters_are_refused(cls, bad):
    with pytest.raises(ParameterError, match=cls.parameter_name):
        cls(bad)


def test_fade_refuses_a_rate_that_kills_the_force():
    with pytest.raises(ParameterError, match="fade.rate"):
        AugmentedModel(BASE, (Fade(-1.0),)).force(_motion())


def test_parametrization_roundtrip_with_voltage_nodes():
    model = AugmentedModel(BASE, (Offset(10.0), Asymmetry(0.1)))
    par = Parametrization(model, nodes=[0.0, 0.5, 1.0])
    vec = par.vector(model)
    assert len(vec) == 5 * 3 + 2 and par.names[-2:] == ("asymmetry.ratio", "offset.f0")
    again = par.model(vec)
    m = _motion()
    np.testing.assert_allclose(again.force(m), model.force(m), rtol=1e-12, atol=1e-9)


def test_joint_refit_recovers_base_and_effect_parameters():
    m1, m2 = _motion(1.0, 0.01), _motion(3.0, 0.004)
    truth = AugmentedModel(BASE, (Stiffness(3e4), Asymmetry(0.1)))
    forces = [truth.force(m1), truth.force(m2)]
    start = AugmentedModel(NormalizedBoucWen(1500.0, 600.0, 300.0, 1.5, 1.2), (Stiffness(1e4),
                                                                               Asymmetry(0.0)))
    fit = refit(start, [m1, m2], forces, scales={"stiffness": 3e4, "asymmetry": 0.1})
    assert fit.relative_rms_error < 1e-6
    assert fit.model.effect("stiffness").kappa_x == pytest.approx(3e4, rel=1e-4)
    assert fit.model.effect("asymmetry").ratio == pytest.approx(0.1, rel=1e-4)
    assert fit.model.base.rho == pytest.approx(400.0, rel=1e-3)


def test_direction_scales_the_force_by_the_direction_of_motion():
    from damper.diagnosis.effects import Direction
    m = _motion()
    base = AugmentedModel(BASE).force(m)
    force = AugmentedModel(BASE, (Direction(0.2),)).force(m)
    up, down = m.xdot > 0, m.xdot < 0
    np.testing.assert_allclose(force[up], 1.2 * base[up])
    np.testing.assert_allclose(force[down], 0.8 * base[down])
    with pytest.raises(ParameterError):
        Direction(1.5)


def test_every_effect_names_the_trace_variables_it_shows_in():
    from damper.diagnosis.trace import TRACE_VARIABLES
    covered = set()
    for cls in EFFECTS.values():
        assert cls.traces, cls.name
        assert set(cls.traces) <= set(TRACE_VARIABLES) | {"mean"}
        covered |= set(cls.traces)
    assert covered == set(TRACE_VARIABLES) | {"mean"}


def test_pchip_slopes_match_scipy():
    from scipy.interpolate import PchipInterpolator
    from damper.models.voltage_laws import pchip_slopes
    rng = np.random.default_rng(3)
    for n in (2, 3, 4, 6):
        for _ in range(50):
            x = np.cumsum(rng.uniform(0.1, 1.0, n))
            y = rng.normal(size=n) * (rng.random(n) < 0.8)
            np.testing.assert_allclose(pchip_slopes(x, y), PchipInterpolator(x, y).derivative()(x),
                                       rtol=1e-10, atol=1e-12)


def test_base_force_memo_returns_the_kernel_history_and_only_for_the_same_base_and_input():
    """The refit's memo (BaseForceMemo) hands back a base force only when everything the kernel
    reads is the same: parameters, initial state and input; the refit's result is bit for bit
    the one without it, with fewer simulations (the effects' Jacobian columns reuse the centre)."""
    from damper.diagnosis import augmented
    from damper.diagnosis.augmented import BaseForceMemo
    m = _motion(v=0.0)
    memo = BaseForceMemo(size=2)
    f0 = memo.base_force(BASE, m, 0.0)
    np.testing.assert_array_equal(f0, simulate(BASE, m.t, m.x, m.xdot, 0.0).force)
    assert memo.base_force(BASE, m, np.zeros(m.t.size)) is not f0       # another input shape
    assert memo.base_force(BASE, m, 0.0) is f0 and memo.hits == 1
    other = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5 + 1e-12)
    assert memo.base_force(other, m, 0.0) is not f0                     # a last-digit change
    memo.base_force(NormalizedBoucWen(2000.0, 800.0, 410.0, 1.0, 1.5), m, 0.0)
    assert memo.base_force(BASE, m, 0.0) is not f0                      # evicted (size 2)
    with pytest.raises(ValueError):
        f0[0] = 1.0                                                     # read-only: shared

    m1, m2 = _motion(1.0, 0.01), _motion(2.5, 0.004)
    truth = AugmentedModel(NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5), (Stiffness(3e4), Offset(40.0)))
    forces = [truth.force(m1), truth.force(m2)]
    start = AugmentedModel(NormalizedBoucWen(1500.0, 600.0, 300.0, 1.5, 1.2), (Stiffness(1e4), Offset(0.0)))
    calls = {"n": 0}
    plain_simulate = augmented.simulate

    def counted(*args, **kwargs):
        calls["n"] += 1
        return plain_simulate(*args, **kwargs)

    fits = {}
    for use_memo in (True, False):
        calls["n"] = 0
        patch = pytest.MonkeyPatch()
        patch.setattr(augmented, "simulate", counted)
        if not use_memo:
            patch.setattr(BaseForceMemo, "base_force",
                          lambda self, base, motion, u: counted(base, motion.t, motion.x, motion.xdot, u).force)
        try:
            fits[use_memo] = (refit(start, [m1, m2], forces, scales={"stiffness": 3e4, "offset": 50.0}),
                              calls["n"])
        finally:
            patch.undo()
    (with_memo, n_memo), (without, n_plain) = fits[True], fits[False]
    # The κ columns read off a held state history differ from a simulation by rounding (1e-16
    # of the force), i.e. 1e-10 of a Jacobian column with a step of 1e-6: the trust region's
    # path is the same to far better than its own tolerance (1e-10 here).
    assert with_memo.relative_rms_error == pytest.approx(without.relative_rms_error, rel=1e-6)
    for name, value in with_memo.model.base_parameters().items():
        assert value == pytest.approx(without.model.base_parameters()[name], rel=1e-6), name
    assert n_memo < 0.6 * n_plain, (n_memo, n_plain)


@pytest.mark.parametrize("kind", ["normalized", "extended"])
def test_base_force_memo_reads_a_force_parameter_change_off_the_held_state(kind):
    """A base that differs only in κ_x, κ_ẋ or κ_w (at any voltage node) follows the held state
    history: the memo returns its force without a simulation, equal to the kernel's to rounding;
    a change of ρ, σ, n or of the input is simulated."""
    from damper.diagnosis.augmented import BaseForceMemo, make_base
    from damper.models.voltage_laws import Tabulated
    nodes = (0.0, 0.5, 1.0)
    law = lambda *values: Tabulated(nodes, values)
    params = {"kappa_x": law(1e4, 2e4, 2.5e4), "kappa_xdot": law(2000.0, 2600.0, 3000.0),
              "kappa_w": law(800.0, 1500.0, 1900.0), "rho": law(400.0, 420.0, 450.0), "sigma": 1.0, "n": 1.5}
    base = make_base(kind, params)
    v = np.clip(0.5 + 0.5 * np.sin(np.linspace(0.0, 7.0, 801)), 0.0, 1.0)
    m = _motion(v=v)
    memo = BaseForceMemo(size=4)
    memo.base_force(base, m, m.v)
    for name in ("kappa_xdot", "kappa_w") + (("kappa_x",) if kind == "extended" else ()):
        changed = make_base(kind, params | {name: law(*(params[name].values * (1.0 + 1e-6 * np.arange(1, 4))))})
        got = memo.base_force(changed, m, m.v)
        want = simulate(changed, m.t, m.x, m.xdot, m.v).force
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)), err_msg=name)
        with pytest.raises(ValueError):
            got[0] = 1.0                                                # read-only like the others
    assert (memo.misses, memo.reads) == (1, 2 if kind == "normalized" else 3)
    memo.base_force(make_base(kind, params | {"rho": law(400.0, 420.0, 450.0 + 1e-9)}), m, m.v)
    memo.base_force(base, m, 0.0)                                       # another input
    assert memo.misses == 3
