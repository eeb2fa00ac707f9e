"""Bingham, Dahl and hyperbolic-tangent models; the model-class contract for every registered model."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import ParameterError
from damper import simulate
from damper.models.base import DamperModel
from damper.models.bingham import Bingham
from damper.models.dahl import Dahl
from damper.models.hyperbolic_tangent import HyperbolicTangent
from damper.models.registry import MODELS, device_force
from damper.models.spencer import Spencer
from damper.models.virtual import VirtualBenchmarkDamper
from damper.models.voltage_laws import Polynomial

T = np.linspace(0.0, 2.0, 801)
X = 0.02 * np.sin(2 * np.pi * T)
XD = 0.02 * 2 * np.pi * np.cos(2 * np.pi * T)


def test_bingham_force_formula():
    model = Bingham(f_c=Polynomial((1e3, 4e3)), c0=2e4, f0=-50.0)
    response = simulate(model, T, X, XD, v=0.5)
    assert response.states.shape == (T.size, 0)
    expected = 3e3 * np.sign(XD) + 2e4 * XD - 50.0
    assert np.allclose(response.force, expected, rtol=1e-12, atol=1e-9)
    assert Bingham.spencer_1997().f_c == 670.0


def test_hyperbolic_tangent_force_formula():
    model = HyperbolicTangent(c=1e4, k=2e4, alpha=Polynomial((1e3, 1e3)), beta=50.0, delta=0.3, f0=10.0)
    response = simulate(model, T, X, XD, v=1.0)
    expected = 1e4 * XD + 2e4 * X + 2e3 * np.tanh(50.0 * XD + 0.3 * np.sign(X)) + 10.0
    assert np.allclose(response.force, expected, rtol=1e-12, atol=1e-9)
    assert np.allclose([model.force([], x, xd, 1.0) for x, xd in zip(X, XD)], expected)


def test_dahl_relaxes_exponentially_after_reversal():
    model = Dahl(kappa_x=0.0, kappa_xdot=1.0, kappa_w=1.0, rho=80.0)
    t = np.linspace(0.0, 1.0, 2001)
    x = 0.02 * np.sin(np.pi * t)  # out to 0.02 m at t = 0.5, then back to 0
    response = simulate(model, t, x)
    w = response.states[:, 0]
    up = t <= 0.5
    assert np.allclose(w[up], 1 - np.exp(-80.0 * x[up]), atol=1e-7)
    w_r = 1 - np.exp(-80.0 * 0.02)
    down = t > 0.5
    assert np.allclose(w[down], -1 + (1 + w_r) * np.exp(-80.0 * (0.02 - x[down])), atol=1e-7)
    bw = simulate(model.as_bouc_wen(), t, x).force
    assert np.array_equal(bw, response.force)


def test_classic_parameters_validated():
    with pytest.raises(ParameterError, match="f_c"):
        Bingham(f_c=-1.0, c0=1.0)
    with pytest.raises(ParameterError, match="beta"):
        HyperbolicTangent(c=1.0, k=0.0, alpha=1.0, beta=0.0)
    with pytest.raises(ParameterError, match="rho"):
        Dahl(kappa_x=0.0, kappa_xdot=1.0, kappa_w=1.0, rho=-2.0)


EXAMPLES = {
    "normalized_bouc_wen": lambda cls: cls(kappa_xdot=1e4, kappa_w=5e4, rho=100.0, sigma=1.0, n=1.5),
    "extended_bouc_wen": lambda cls: cls(kappa_x=2e5, kappa_xdot=1e5, kappa_w=5e4, rho=100.0, sigma=1.0, n=1.5),
    "spencer": lambda cls: Spencer.prototype_1997(),
    "virtual": lambda cls: VirtualBenchmarkDamper(),
    "series_dashpot_bouc_wen": lambda cls: cls(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 2e5)),
                                               kappa_w=Polynomial((5e4, 9e5)), rho=100.0, sigma=1.0,
                                               n=1.5, roll_off_velocity=0.02),
    "spencer_bouc_wen": lambda cls: cls(kappa_x=500.0, k0=4.7e3, kappa_xdot=Polynomial((2.1e3, 3.5e2)),
                                        kappa_w=Polynomial((1.4e4, 6.9e4)), c1=Polynomial((2.8e4, 3e2)),
                                        rho=300.0, sigma=1.0, n=2.0, field_lag=0.005,
                                        voltage_range=(0.0, 2.25)),
    "bingham": lambda cls: Bingham(f_c=1e3, c0=1e4),
    "dahl": lambda cls: Dahl.virtual_0V(),
    "hyperbolic_tangent": lambda cls: HyperbolicTangent.virtual_0V(),
    "with_force_terms": lambda cls: cls(VirtualBenchmarkDamper(), asymmetry=0.1, shear_thinning=5e3,
                                        quadratic_damping=1e4),
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_registered_model_follows_the_contract(name):
    cls = MODELS[name]
    model = EXAMPLES[name](cls)
    assert MODELS[name] is cls and model.name == name and isinstance(model, DamperModel)
    params = model.to_array()
    assert params.dtype == np.float64 and params.ndim == 1
    state = model.initial_state()
    assert state.shape == (model.n_states,)
    lo, hi = model.voltage_range
    assert lo < hi
    assert model.rates(state, 0.01, 0.1, lo).shape == (model.n_states,)
    # the kernel's force equals the plain-numpy force at the same state
    k_force = device_force(cls.kernel, params, state.copy(), 0.01, 0.1, lo)
    assert k_force == pytest.approx(model.force(state, 0.01, 0.1, lo), rel=1e-12, abs=1e-9)
    response = simulate(model, T, X, XD, v=hi)
    assert np.all(np.isfinite(response.force)) and response.states.shape == (T.size, model.n_states)
