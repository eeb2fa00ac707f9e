"""Response spectra by the exact piecewise-linear recurrence, against an ODE solver and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import InputError
from records import Record, response_spectrum
from records.spectra import default_periods, sdof_response


def test_recurrence_matches_a_tight_ode_solution():
    dt = 0.01
    t = np.arange(600) * dt
    a = np.random.default_rng(1).standard_normal(t.size)
    period, zeta = 0.7, 0.05
    w = 2 * np.pi / period
    ref = solve_ivp(lambda s, x: [x[1], -np.interp(s, t, a) - 2 * zeta * w * x[1] - w * w * x[0]],
                    (0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12, max_step=dt / 4)
    ours = sdof_response(a, dt, period, zeta)
    assert np.max(np.abs(ours[:, 0] - ref.y[0])) < 1e-6 * np.max(np.abs(ref.y[0]))
    assert np.max(np.abs(ours[:, 1] - ref.y[1])) < 1e-6 * np.max(np.abs(ref.y[1]))


def test_resonant_sine_reaches_the_steady_state_amplitude():
    period, zeta, amp, dt = 1.0, 0.05, 1.0, 0.005
    t = np.arange(int(60 / dt)) * dt
    rec = Record("sine", dt, amp * np.sin(2 * np.pi * t / period))
    spec = response_spectrum(rec, periods=[period], damping=zeta)
    w = 2 * np.pi / period
    assert spec.sd[0, 0] == pytest.approx(amp / (2 * zeta * w ** 2), rel=0.01)
    assert spec.psa[0, 0] == pytest.approx(amp / (2 * zeta), rel=0.01)
    assert spec.psv[0, 0] == pytest.approx(spec.sd[0, 0] * w)


def test_limits_zero_period_rigid_and_long_period_flexible():
    dt = 0.005
    t = np.arange(4000) * dt
    a = np.exp(-((t - 5) / 0.6) ** 2) * np.sin(2 * np.pi * 2 * t)     # a short wavelet, no residual motion
    rec = Record("w", dt, np.column_stack([a, 2 * a]))
    spec = response_spectrum(rec, periods=[0.0, 0.01, 50.0])
    assert np.allclose(spec.psa[0], rec.pga)                     # T = 0: PGA
    assert np.allclose(spec.sa[1], rec.pga, rtol=0.02)           # very stiff: follows the ground
    assert np.allclose(spec.sd[2], rec.pgd, rtol=0.05)           # very flexible: relative = ground displacement
    assert np.allclose(spec.psa[:, 1], 2 * spec.psa[:, 0])       # linear in the input


def test_substeps_catch_peaks_between_samples():
    dt_fine, dt_coarse = 0.0005, 0.01
    t = np.arange(int(8 / dt_coarse) + 1) * dt_coarse
    a = np.random.default_rng(5).standard_normal(t.size)
    fine_t = np.arange(int(8 / dt_fine) + 1) * dt_fine
    fine = np.interp(fine_t, t, a)                               # the same piecewise-linear motion
    periods = [0.03, 0.05, 0.1]
    coarse_spec = response_spectrum(a, dt_coarse, periods)
    fine_spec = response_spectrum(fine, dt_fine, periods)
    assert np.allclose(coarse_spec.sd, fine_spec.sd, rtol=2e-3)


def test_spectrum_input_errors():
    with pytest.raises(InputError, match="give dt"):
        response_spectrum(np.ones(10))
    with pytest.raises(InputError, match="damping"):
        response_spectrum(np.ones(10), 0.01, damping=1.0)
    with pytest.raises(InputError, match="periods"):
        response_spectrum(np.ones(10), 0.01, periods=[-1.0])
    with pytest.raises(InputError, match="t_min"):
        default_periods(t_min=2.0, t_max=1.0)
    p = default_periods()
    assert p[0] == pytest.approx(0.02) and p[-1] == pytest.approx(10.0) and np.all(np.diff(p) > 0)


@pytest.mark.parametrize("period, zeta, h", [(0.02, 0.05, 0.0004), (0.7, 0.05, 0.005), (10.0, 0.0, 0.005),
                                             (3.0, 0.3, 0.01), (50.0, 0.05, 0.005)])
def test_coefficients_equal_the_matrix_exponential_and_the_closed_form(period, zeta, h):
    from scipy.linalg import expm

    from records.spectra import _augmented, _discretise, _discretise_closed_form

    omega = 2 * np.pi / period
    ours = _discretise(omega, zeta, h)
    e = expm(_augmented(omega, zeta, h))
    for mine, ref in zip(ours, (e[:2, :2], e[:2, 2], e[:2, 3])):
        assert np.allclose(mine, ref, rtol=1e-12, atol=0)
    for mine, ref in zip(ours, _discretise_closed_form(omega, zeta, h)):
        assert np.allclose(mine, ref, rtol=1e-6, atol=1e-13 * np.max(np.abs(ref)))
