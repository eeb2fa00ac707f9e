"""Identification of the hysteretic oscillator: recovery of known parameters, uncertainty, errors."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError, NumericalError
from damper.hysteresis import noel_schoukens as hb
from damper.hysteresis.oscillator import HystereticOscillator
from damper.hysteresis.identification import identify_hysteretic, linear_start

# A variant of the benchmark on the other (saturating) branch, with nu != 1 and other m, c, k.
VARIANT = HystereticOscillator.from_standard(mass=1.5, damping=6.0, stiffness=3e4, alpha=4e4,
                                             beta=2e3, gamma=0.6, delta=0.3, nu=1.5)
NAMES = ("mass", "damping", "stiffness", "kappa_w", "rho", "sigma", "n")


def _data(system, rms, noise=0.0, n=2048, periods=3, seed=11):
    u, y = hb.synthesize(system, np.tile(hb.multisine(n=n, rms=rms, seed=seed), periods),
                         decimate=False)
    if noise:
        y = y + noise * np.std(y) * np.random.default_rng(0).standard_normal(y.size)
    return u, y


def test_linear_start_reads_the_mass():
    u, y = _data(hb.true_system(), 50.0)
    lin = linear_start(u, y, hb.FS)
    assert lin["mass"] == pytest.approx(2.0, rel=0.1)
    assert 30 < lin["natural_frequency"] < 45


def test_recovers_benchmark_parameters_without_noise():
    u, y = _data(hb.true_system(), 50.0)
    fit = identify_hysteretic(u, y, hb.FS)
    got = fit.model.to_standard(beta=hb.TRUE_PARAMETERS["beta"])
    for k in ("mass", "damping", "stiffness", "alpha", "gamma", "delta", "nu"):
        assert got[k] == pytest.approx(hb.TRUE_PARAMETERS[k], rel=1e-4), k
    assert fit.rms_error < 1e-5 * fit.rms_displacement
    assert fit.model.branch == -1


@pytest.mark.parametrize("system, rms", [(hb.true_system(), 20.0), (VARIANT, 30.0)],
                         ids=["benchmark-20N", "saturating-variant"])
def test_recovers_parameters_with_noise_within_their_uncertainty(system, rms):
    u, y = _data(system, rms, noise=0.01)
    fit = identify_hysteretic(u, y, hb.FS)
    truth = system.parameters()
    for k in NAMES:
        se = fit.standard_error[k]
        err = getattr(fit.model, k) - truth[k]
        if k == "n" and fit.model.n == 1.0 and truth["n"] == 1.0:
            continue                      # at its bound: exact
        assert se > 0, k
        assert abs(err) < 5 * se, (k, err, se)
    assert fit.model.mass == pytest.approx(system.mass, rel=2e-3)
    assert fit.model.stiffness == pytest.approx(system.stiffness, rel=1e-2)
    # The residual is the noise (1 % of the response RMS), not model error.
    assert fit.rms_error < 0.0105 * np.std(y)
    assert fit.model.branch == system.branch


def test_identification_input_errors():
    u, y = _data(hb.true_system(), 50.0, n=256, periods=2)
    with pytest.raises(InputError, match="at least"):
        identify_hysteretic(u[:100], y[:100], hb.FS)
    bad = y.copy()
    bad[7] = np.nan
    with pytest.raises(InputError, match="sample 7"):
        identify_hysteretic(u, bad, hb.FS)
    with pytest.raises(InputError, match="constant"):
        identify_hysteretic(u, np.zeros_like(y), hb.FS)
    with pytest.raises(InputError, match="equal length"):
        identify_hysteretic(u, y[:-1], hb.FS)
    # a --skip past a quarter of the record had been cut to a quarter without a word
    with pytest.raises(InputError, match="more than a quarter of the fitted record"):
        identify_hysteretic(u, y, hb.FS, skip=0.5 * u.size / hb.FS)


def test_data_that_are_not_an_oscillator_raise_numerical_error():
    rng = np.random.default_rng(1)
    u = rng.standard_normal(4096)
    y = rng.standard_normal(4096) * 1e-3          # unrelated to the force
    with pytest.raises(NumericalError):
        identify_hysteretic(u, y, hb.FS)
