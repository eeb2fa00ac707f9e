"""A diagnosed model's memoryless effects in the building: :mod:`damper.models.force_terms`.

The residual loop's effects ``asymmetry``, ``shear_thinning`` and ``quadratic_damping`` (and
``stiffness`` beside the factor) used to be left out of every building
run ("no kernel in the building"). They now run around the base model's kernel; these tests hold
that kernel to the augmented model the loop fitted (:mod:`damper.diagnosis.augmented`), check
what a model file's building model keeps and drops, and run the terms in the building against
the ``solve_ivp`` oracle (``tests/benchmark/test_oracle_nonlinear.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import ParameterError
from damper.diagnosis.augmented import AugmentedModel
from damper.diagnosis.effects import (Asymmetry, Direction, Fade, Inertia, Motion, Offset, QuadraticDamping,
                                      ShearThinning, Stiffness)
from damper.models.force_terms import REGULARIZATION_VELOCITY
from damper.io.model_file import read_model_file, write_model_file
from damper.models.bouc_wen import NormalizedBoucWen
from damper.models.force_terms import WithForceTerms
from damper.models.registry import device_force, device_tangent, kernel_id_of
from damper.models.response import simulate
from damper.models.series_dashpot import SpencerBoucWen
from damper.models.voltage_laws import Polynomial


def _normalized():
    return NormalizedBoucWen(kappa_xdot=Polynomial((1.5e4, 2.0e4)), kappa_w=Polynomial((300.0, 900.0)),
                             rho=400.0, sigma=2.0, n=1.5, voltage_range=(0.0, 1.0))


def _spencer():
    return SpencerBoucWen(2180.0, 890.0, 600.0, 650.0, 27700.0, 1.08e4, 0.67, 1.1, field_lag=0.0067,
                          voltage_range=(0.0, 2.3))


def _motion():
    t = np.linspace(0.0, 3.0, 3001)
    x = 0.008 * np.sin(2 * np.pi * 1.3 * t) + 0.003 * np.sin(2 * np.pi * 3.1 * t + 0.4)
    xd = np.gradient(x, t, edge_order=2)
    v = np.where(np.sin(2 * np.pi * 0.7 * t) > 0.0, 1.0, 0.2)
    return Motion(t, x, xd, np.gradient(xd, t, edge_order=2), v)


EFFECT_SETS = {
    "shear_thinning": (ShearThinning(500.0),),
    "quadratic_damping": (QuadraticDamping(4.0e4),),
    "asymmetry": (Asymmetry(0.15),),
    "all, stiffness beside the factor": (Asymmetry(-0.1), ShearThinning(300.0),
                                          QuadraticDamping(2.0e4), Stiffness(5.0e3)),
}


@pytest.mark.parametrize("base", [_normalized, _spencer], ids=["normalized", "spencer"])
@pytest.mark.parametrize("name", sorted(EFFECT_SETS))
def test_building_model_runs_the_augmented_models_force(tmp_path, base, name):
    """The model file's building model gives the fitted augmented model's force: the same base
    kernel on the same samples, the terms evaluated on the same velocity, so only the order of
    the floating-point operations differs (1e-12 of the force RMS)."""
    effects = EFFECT_SETS[name]
    if base is _spencer:  # its base has kappa_x x of its own
        effects = tuple(e for e in effects if e.name != "stiffness")
    aug = AugmentedModel(base(), effects)
    mf = read_model_file(write_model_file(tmp_path / "m.json", aug))
    model, dropped = mf.building_model()
    assert dropped == []
    assert isinstance(model, WithForceTerms)
    motion = _motion()
    expected = aug.force(motion)
    got = simulate(model, motion.t, motion.x, motion.xdot, motion.v).force
    scale = np.sqrt(np.mean(expected ** 2))
    assert np.max(np.abs(got - expected)) <= 1e-12 * scale * 10
    # and the terms matter: the base alone is far from it
    plain = simulate(mf.model, motion.t, motion.x, motion.xdot, motion.v).force
    assert np.sqrt(np.mean((plain - expected) ** 2)) > 0.01 * scale


def test_stiffness_without_a_factor_still_becomes_kappa_x(tmp_path):
    mf = read_model_file(write_model_file(tmp_path / "m.json",
                                          AugmentedModel(_normalized(), (Stiffness(5.0e3), ShearThinning(300.0)))))
    model, dropped = mf.building_model()
    assert dropped == [] and model.stiffness == 0.0 and model.shear_thinning == 300.0
    assert model.inner.kappa_x == pytest.approx(5.0e3)  # the extended model's spring, as before


def test_the_building_names_what_it_leaves_out_and_why(tmp_path):
    aug = AugmentedModel(_normalized(), (Offset(40.0), Inertia(3.0), Fade(-0.01), Direction(0.1), ShearThinning(300.0)))
    model, dropped = read_model_file(write_model_file(tmp_path / "m.json", aug)).building_model()
    assert isinstance(model, WithForceTerms) and model.terms == {"shear_thinning": 300.0}
    text = "\n".join(dropped)
    assert len(dropped) == 4
    assert "offset" in text and "at rest" in text
    assert "inertia" in text and "no mass" in text
    assert "fade" in text and "heating" in text
    assert "direction" in text and "reversal" in text


def test_a_model_with_terms_is_written_as_its_inner_model_and_effects(tmp_path):
    model = WithForceTerms(_spencer(), asymmetry=0.1, shear_thinning=250.0)
    mf = read_model_file(write_model_file(tmp_path / "m.json", model))
    assert mf.model_name == "spencer_bouc_wen" or type(mf.model) is SpencerBoucWen
    assert {e.name: e.value for e in mf.effects} == {"asymmetry": 0.1, "shear_thinning": 250.0}
    back, _ = mf.building_model()
    assert back.terms == model.terms


def test_scaling_a_file_scales_the_force_terms(tmp_path):
    mf = read_model_file(write_model_file(tmp_path / "m.json",
                                          AugmentedModel(_spencer(), (Asymmetry(0.1), ShearThinning(250.0),
                                                                      QuadraticDamping(1e4)))))
    big, _ = mf.scaled(100.0).building_model()
    assert big.shear_thinning == pytest.approx(25000.0) and big.quadratic_damping == pytest.approx(1e6)
    assert big.asymmetry == 0.1  # a ratio: unchanged by the force similitude


@pytest.mark.parametrize("kwargs, match", [
    ({"asymmetry": 0.95}, "asymmetry"),
    ({"asymmetry": -1.0}, "asymmetry"),
    ({"shear_thinning": -1.0}, "shear_thinning"),
    ({"quadratic_damping": float("nan")}, "quadratic_damping"),
    ({"stiffness": "stiff"}, "stiffness"),
])
def test_bad_terms_are_refused_in_one_line(kwargs, match):
    with pytest.raises(ParameterError, match=match) as info:
        WithForceTerms(_normalized(), **kwargs)
    assert "\n" not in str(info.value)


def test_terms_do_not_nest():
    with pytest.raises(ParameterError, match="inner"):
        WithForceTerms(WithForceTerms(_normalized(), shear_thinning=1.0))


def test_kernel_force_and_tangent_agree_with_the_python_model():
    model = WithForceTerms(_spencer(), asymmetry=0.1, stiffness=2e3, shear_thinning=250.0,
                           quadratic_damping=1e4)
    params = model.to_array()
    kid = kernel_id_of(model)
    rng = np.random.default_rng(3)
    for _ in range(20):
        state = rng.normal(size=model.n_states) * 1e-3
        x, xd, v = rng.normal() * 0.01, rng.normal() * 0.1, rng.uniform(0.0, 2.3)
        assert device_force(kid, params, state.copy(), x, xd, v) == pytest.approx(model.force(state, x, xd, v),
                                                                                 rel=1e-12, abs=1e-9)
        # the tangent in velocity: a central difference of the kernel's force with the states held
        h = 1e-7
        dfdxd = (device_force(kid, params, state.copy(), x, xd + h, v)
                 - device_force(kid, params, state.copy(), x, xd - h, v)) / (2 * h)
        _, kxd = device_tangent(kid, params, state.copy(), x, xd, v)
        inner_only = device_tangent(kernel_id_of(model.inner), model.inner.to_array(), state.copy(), x, xd, v)[1]
        if inner_only != 0.0:  # the Spencer-type kernel gives its tangent
            assert kxd == pytest.approx(dfdxd, rel=1e-4)



def test_shear_thinning_is_the_square_root_law_outside_its_band_and_linear_inside():
    """The term the building runs (and the loop fits): k sgn(v) |v|^0.5 for |v| >= 0.1 mm/s, a
    straight line through zero inside, continuous at the band's edges."""
    eps = REGULARIZATION_VELOCITY
    t = np.linspace(0.0, 1.0, 5)
    v = np.array([-0.3, -eps, 0.5 * eps, eps, 0.02])
    f = ShearThinning(200.0).force(Motion(t, np.zeros(5), v, np.zeros(5), np.zeros(5)))
    expected = 200.0 * np.array([-np.sqrt(0.3), -np.sqrt(eps), 0.5 * np.sqrt(eps), np.sqrt(eps), np.sqrt(0.02)])
    np.testing.assert_allclose(f, expected, rtol=1e-12)
