"""Closed-form identification steps on loops from a private reference integration (solve_ivp).

The reference here integrates the extended normalized Bouc-Wen model with LSODA at tight
tolerances, independently of the package's kernels, so these tests check the identification
algorithm and not the simulator it is later refined with.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from benchmark.foundation.errors import InputError
from damper.identification.closed_form import closed_form
from damper.models.bouc_wen import g_integral, h_integral, limit_cycle_peak, limit_cycle_psi
from damper.identification.cycles import (ExcitationWarning, average_branches, check_excitation,
                                          detect_cycles, steady_cycles)

TRUE = dict(kappa_x=2.0e5, kappa_xdot=1.0e5, kappa_w=1.0e5, rho=150.0, sigma=0.8, n=1.5)


def reference_loop(p: dict, amplitude: float = 0.1, frequency: float = 0.5, cycles: int = 4,
                   dt: float = 1e-3) -> tuple[np.ndarray, ...]:
    """Sinusoidal test of the extended model by solve_ivp (LSODA, rtol 1e-10)."""
    t = np.arange(0.0, cycles / frequency, dt)
    om = 2 * np.pi * frequency
    x = amplitude * np.sin(om * t)
    xd = amplitude * om * np.cos(om * t)

    def rhs(tt, w):
        v = amplitude * om * math.cos(om * tt)
        ww = w[0]
        aw = abs(ww)
        return [p["rho"] * (v - p["sigma"] * abs(v) * aw ** (p["n"] - 1) * ww
                            + (p["sigma"] - 1) * v * aw ** p["n"])]

    sol = solve_ivp(rhs, (t[0], t[-1]), [0.0], t_eval=t, method="LSODA", rtol=1e-10, atol=1e-12,
                    max_step=5 * dt)
    w = sol.y[0]
    force = p["kappa_x"] * x + p["kappa_xdot"] * xd + p["kappa_w"] * w
    return t, x, xd, force


@pytest.fixture(scope="module")
def loop():
    return reference_loop(TRUE)


def test_detect_cycles_finds_every_full_period_despite_noise():
    rng = np.random.default_rng(1)
    t = np.arange(0, 5.3, 1e-3)
    x = 0.02 * np.sin(2 * np.pi * t) + 0.0005 * rng.standard_normal(t.size)
    cycles = detect_cycles(x)
    # Minima of sin(2 pi t) at t = 0.75, 1.75, ...; the record ends at 5.3 s (partial cycle dropped).
    assert len(cycles) == 4
    for k, c in enumerate(cycles):
        assert abs(t[c.start] - (0.75 + k)) < 0.05
        assert abs(t[c.peak] - (1.25 + k)) < 0.05
        assert abs(t[c.end] - (1.75 + k)) < 0.05


def test_detect_cycles_rejects_constant_and_too_short_records():
    with pytest.raises(InputError, match="no stroke"):
        detect_cycles(np.zeros(100))
    with pytest.raises(InputError, match="no complete cycle"):
        detect_cycles(np.sin(np.linspace(0, 3.0, 200)))
    with pytest.raises(InputError, match="non-finite"):
        detect_cycles(np.array([0.0, 1.0, np.nan]))


def test_integrals_match_quadrature():
    for n in (1.0, 1.5, 3.0):
        for w in (0.2, 0.7, 0.95):
            assert g_integral(w, n) == pytest.approx(quad(lambda m: 1 / (1 - m ** n), 0, w)[0], rel=1e-10)
            for s in (0.5, 0.8, 3.0):
                ref = quad(lambda m: 1 / (1 + (2 * s - 1) * m ** n), 0, w)[0]
                assert h_integral(w, s, n) == pytest.approx(ref, rel=1e-10)


def test_limit_cycle_peak_matches_domain_values_and_quadrature():
    # DOMAIN.md §4, n = 1, sigma = 1/2: w0 = 0.72 at 2, 0.95 at 4, 0.993 at 6.
    assert limit_cycle_peak(2.0, 0.5, 1.0) == pytest.approx(0.72, abs=0.01)
    assert limit_cycle_peak(4.0, 0.5, 1.0) == pytest.approx(0.95, abs=0.01)
    assert limit_cycle_peak(6.0, 0.5, 1.0) == pytest.approx(0.993, abs=0.001)
    assert limit_cycle_peak(0.0, 0.5, 1.0) == 0.0
    # The closed forms (hypergeometric) against direct quadrature of the two integrals.
    from scipy.integrate import quad
    for sigma, n, rho_stroke in ((0.8, 1.5, 75.0), (2.0, 2.0, 3.0), (0.5, 1.0, 2.0), (1.0, 2.5, 5.0)):
        w0 = limit_cycle_peak(rho_stroke, sigma, n)
        if w0 > 0.999999:
            continue
        g = quad(lambda m: 1.0 / (1.0 - m ** n), 0.0, w0, limit=400)[0]
        h = quad(lambda m: 1.0 / (1.0 + (2.0 * sigma - 1.0) * m ** n), 0.0, w0, limit=400)[0]
        assert limit_cycle_psi(w0, sigma, n) == pytest.approx(g + h, rel=1e-9)
        assert g + h == pytest.approx(rho_stroke, rel=1e-8)


def test_reference_loop_reaches_its_predicted_limit_cycle_peak(loop):
    t, x, xd, force = loop
    w = (force - TRUE["kappa_x"] * x - TRUE["kappa_xdot"] * xd) / TRUE["kappa_w"]
    w0 = limit_cycle_peak(TRUE["rho"] * 0.2, TRUE["sigma"], TRUE["n"])
    assert np.max(w[t > 2.0]) == pytest.approx(w0, abs=1e-6)


@pytest.mark.parametrize("n_method", ["integral", "derivative"])
def test_closed_form_extended_is_a_good_start(loop, n_method):
    t, x, xd, force = loop
    cycles = detect_cycles(x)
    kept, deviation = steady_cycles(x, force, cycles)
    assert len(kept) >= 2 and deviation[-1] < 1e-3
    cf = closed_form(average_branches(x, xd, force, kept), model="extended", n_method=n_method)
    p = cf.parameters()
    # Seed step (a) and the plastic regression are exact up to the plastic-level bias.
    assert p["kappa_x"] == pytest.approx(TRUE["kappa_x"], rel=0.02)
    assert p["kappa_xdot"] == pytest.approx(TRUE["kappa_xdot"], rel=0.02)
    assert p["kappa_w"] == pytest.approx(TRUE["kappa_w"], rel=0.02)
    assert p["rho"] == pytest.approx(TRUE["rho"], rel=0.10)
    assert p["n"] == pytest.approx(TRUE["n"], rel=0.20)
    assert 0.5 <= p["sigma"] <= 2.0
    d = cf.design
    assert d.x3 < d.x_star < d.x1 < d.x2  # design points ordered as the method needs
    assert cf.rho_stroke > 20 and cf.w0 > 0.999


def test_closed_form_normalized_fixes_kappa_x_at_zero(loop):
    t, x, xd, force = loop
    kept, _ = steady_cycles(x, force, detect_cycles(x))
    cf = closed_form(average_branches(x, xd, force, kept), model="normalized")
    assert cf.kappa_x == 0.0
    assert cf.kappa_x_inclination == pytest.approx(TRUE["kappa_x"], rel=0.02)  # still reported


@pytest.mark.filterwarnings("ignore::damper.identification.cycles.ExcitationWarning")
def test_small_excitation_raises_with_the_number():
    p = dict(TRUE, rho=15.0)  # rho * stroke = 15 * 0.2 = 3 < 4
    t, x, xd, force = reference_loop(p, amplitude=0.1, cycles=3)
    kept, _ = steady_cycles(x, force, detect_cycles(x))
    with pytest.raises(InputError, match=r"rho\*\(X_max - X_min\) = [0-9.]+"):
        closed_form(average_branches(x, xd, force, kept), model="extended")


def test_check_excitation_warns_when_marginal_and_passes_when_large():
    with pytest.warns(ExcitationWarning, match="rho\\*\\(X_max - X_min\\) = 5"):
        check_excitation(50.0, 0.5, 1.0, 0.1)
    rho_stroke, w0 = check_excitation(100.0, 0.5, 1.0, 0.1)
    assert rho_stroke == pytest.approx(10.0) and w0 > 0.999
    with pytest.raises(InputError, match="increase the test amplitude"):
        check_excitation(10.0, 0.5, 1.0, 0.1)


def test_triangular_wave_cannot_separate_viscous_and_dry_friction():
    # Constant |xdot|: kappa_xdot xdot and kappa_w are collinear in the plastic regression.
    t = np.arange(0, 4.0, 1e-3)
    x = 0.1 * (2 / np.pi) * np.arcsin(np.sin(2 * np.pi * t))
    xd = np.gradient(x, t)
    w = np.tanh(50 * x)  # any hysteresis-free shape will do: the check comes first
    force = 1e5 * xd + 1e5 * np.sign(xd) * np.abs(w)
    kept, _ = steady_cycles(x, force, detect_cycles(x))
    with pytest.raises(InputError, match="velocity is \\(nearly\\) constant"):
        closed_form(average_branches(x, xd, force, kept))


def test_unknown_model_and_method_are_input_errors(loop):
    t, x, xd, force = loop
    br = average_branches(x, xd, force, detect_cycles(x))
    with pytest.raises(InputError, match="model"):
        closed_form(br, model="spencer")
    with pytest.raises(InputError, match="n_method"):
        closed_form(br, n_method="magic")
