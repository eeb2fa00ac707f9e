"""Residual tracing and the selection statistics, on synthetic residuals with known structure."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.diagnosis.loop import unexplained_structure
from damper.diagnosis.selection import screen_columns
from damper.diagnosis.trace import bic_delta, heldout_bic
from damper.diagnosis.trace import (TRACE_VARIABLES, correlation_ratio, effective_sample_size,
                                    ljung_box, trace_residual)

RNG = np.random.default_rng(7)
N = 4000
T = np.linspace(0.0, 20.0, N)
X = 0.01 * np.sin(2 * np.pi * 0.5 * T)
XD = 0.01 * np.pi * np.cos(2 * np.pi * 0.5 * T)


def _signals(**over):
    s = {"displacement": X, "velocity": XD, "acceleration": -(np.pi ** 2) * X,
         "voltage": np.zeros(N), "voltage_rate": np.zeros(N), "time": T,
         "cycle": np.floor(T / 2.0)}
    s.update(over)
    return s


def test_noise_is_explained_by_nothing_and_is_white():
    r = RNG.standard_normal(N)
    tr = trace_residual(r, _signals())
    assert set(tr.shares) == set(TRACE_VARIABLES)
    assert max(tr.shares.values()) < 0.02
    assert tr.white and tr.ljung_box_p > 0.01
    assert tr.noise_fraction == pytest.approx(1.0, abs=0.1)
    assert effective_sample_size(r) > 0.7 * N
    assert tr.shares["voltage"] == 0.0 and tr.profiles["voltage"].constant


def test_residual_living_in_velocity_is_found_there():
    r = 50.0 * XD * np.abs(XD) / np.max(XD ** 2) + 0.05 * RNG.standard_normal(N)
    tr = trace_residual(r, _signals())
    assert tr.dominant()[0] == "velocity"
    assert tr.shares["velocity"] > 0.95
    assert tr.shares["displacement"] < 0.1
    assert not tr.white
    assert effective_sample_size(r) < 0.05 * N


def test_branch_dependent_residual_shows_in_loop_not_in_displacement():
    # +x on the loading branch, -x on the unloading one: cancels in the plain displacement
    r = np.sign(XD) * X / 0.01 + 0.05 * RNG.standard_normal(N)
    tr = trace_residual(r, _signals())
    assert tr.shares["loop"] > 0.9
    assert tr.shares["displacement"] < 0.1


def test_time_share_reads_cycles_so_periodic_residuals_are_not_drifts():
    periodic = X / 0.01
    drift = T / 20.0
    tp = trace_residual(periodic, _signals())
    td = trace_residual(drift + 0.01 * RNG.standard_normal(N), _signals())
    assert tp.shares["time"] < 0.05
    assert td.shares["time"] > 0.9


def test_constant_offset_is_reported_as_mean():
    r = 3.0 + 0.1 * RNG.standard_normal(N)
    tr = trace_residual(r, _signals())
    assert tr.mean_share > 0.99
    assert max(tr.shares.values()) < 0.02


def test_correlation_ratio_bounds_and_ljung_box_on_ar1():
    assert correlation_ratio(np.ones(10), np.arange(10) % 2) == 0.0
    z = RNG.integers(0, 5, 5000)
    assert correlation_ratio(z + 0.01 * RNG.standard_normal(5000), z) > 0.99
    e = RNG.standard_normal(3000)
    ar = np.empty_like(e)
    ar[0] = e[0]
    for k in range(1, e.size):
        ar[k] = 0.8 * ar[k - 1] + e[k]
    q, p, h = ljung_box(ar)
    assert p < 1e-6 and h == 20
    # AR(1): tau = (1 + phi)/(1 - phi) = 9
    assert effective_sample_size(ar) == pytest.approx(3000 / 9, rel=0.35)


def test_trace_refuses_bad_input():
    with pytest.raises(InputError, match="at least"):
        trace_residual(np.zeros(10), _signals())
    with pytest.raises(InputError, match="missing"):
        trace_residual(np.zeros(N), {"displacement": X})
    with pytest.raises(InputError, match="non-finite"):
        trace_residual(np.full(N, np.nan), _signals())


def test_screen_scores_the_right_column_and_respects_the_model_directions_and_signs():
    a = np.sin(T)
    b = np.cos(3 * T)
    c = T / 20.0
    r = 2.0 * a + 0.01 * RNG.standard_normal(N)
    s = screen_columns(r, base_columns=b[:, None], columns={"a": a, "b_again": 3 * b, "c": c,
                                                            "minus_a": -a},
                       lower={"minus_a": 0.0})
    assert s["a"].score > 0.99 and s["a"].estimate == pytest.approx(2.0, rel=1e-3)
    assert s["b_again"].score == 0.0 and "collinear" in s["b_again"].reason
    assert s["minus_a"].score == 0.0 and "inadmissible" in s["minus_a"].reason
    assert s["c"].score < 0.05


def test_heldout_bic_penalty_and_delta():
    assert heldout_bic(4.0, 4, 10.0, 2) == pytest.approx(10 * math.log(1.0) + 2 * math.log(10))
    # one parameter pays only if RSS falls by more than a factor exp(-ln(n)/n)
    n = 20.0
    limit = math.exp(-math.log(n) / n)
    assert bic_delta(1.0, 0.99 * limit, n, 1) < 0 < bic_delta(1.0, 1.01 * limit, n, 1)
    with pytest.raises(InputError):
        heldout_bic(0.0, 10, 5.0, 1)


def test_unexplained_needs_both_share_and_level():
    r = 0.5 * XD / np.max(XD) + 0.01 * RNG.standard_normal(N)
    tr = trace_residual(r, _signals())
    big = unexplained_structure(tr, force_rms=10.0)      # 0.35/10: above 2 %
    small = unexplained_structure(tr, force_rms=1000.0)  # 0.35/1000: below 2 %
    assert big and big[0][0] == "velocity"
    assert small == []


def test_structure_no_variable_locates_is_unexplained():
    """A residual that is not white but that no trace variable holds (here an oscillation at a
    frequency of its own, as a rig's resonance leaves it) is reported as ``unlocated``, not as
    nothing."""
    from damper.diagnosis.loop import UNLOCATED
    drift = 0.3 * np.sin(2 * np.pi * 7.3 * T) + 0.01 * RNG.standard_normal(N)
    tr = trace_residual(drift, _signals())
    assert tr.noise_fraction < 0.5
    found = unexplained_structure(tr, force_rms=10.0)
    assert found and found[0][0] == UNLOCATED
    assert found[0][1] == pytest.approx(1.0 - tr.noise_fraction)
    assert found[0][2] == pytest.approx(math.sqrt(1.0 - tr.noise_fraction) * tr.rms / 10.0)
    assert unexplained_structure(tr, force_rms=1000.0) == []  # below the level
    white = trace_residual(0.3 * RNG.standard_normal(N), _signals())
    assert unexplained_structure(white, force_rms=10.0) == []  # white: noise, not structure
