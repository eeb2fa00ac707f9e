"""Flaw checks (identical components, baseline drift, PGA, length) and the baseline correction."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from records import Record, baseline_correct, check_record, load_benchmark_record
from records.baseline import baseline_correction_acceleration, end_condition_correction
from records.checks import (check_baseline_drift, check_duration, check_identical_components, check_pga,
                            identical_spans)


def _clean(n=4000, dt=0.01, seed=3):
    """A decaying narrow-band motion with zero final velocity and displacement."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    a = np.sin(2 * np.pi * 1.3 * t) * np.exp(-0.2 * t) * 3.0 + 0.3 * rng.standard_normal(n) * np.exp(-0.3 * t)
    a -= end_condition_correction(a, dt)
    return t, a


def test_identical_spans_ignore_zero_padding_and_short_runs():
    a = np.column_stack([np.arange(1.0, 101.0), np.arange(1.0, 101.0) * 2])
    a[:10] = 0.0                       # quiet padding: equal but zero, not a flaw
    a[40:45, 1] = a[40:45, 0]          # 5 equal samples: below min_length
    a[70:100, 1] = a[70:100, 0]        # 30 equal samples at the end
    assert identical_spans(a, min_length=20) == [(70, 100)]
    assert identical_spans(a, min_length=5) == [(40, 45), (70, 100)]
    assert identical_spans(a[:, :1]) == []
    flaws = check_identical_components(Record("r", 0.01, a, labels=("N-S", "E-W")))
    assert len(flaws) == 1 and "the last 30 samples" in flaws[0].message and "E-W identical to N-S" in flaws[0].message


def test_drift_check_flags_an_offset_only():
    t, a = _clean()
    rec = Record("r", 0.01, np.column_stack([a, a + 0.02]), labels=("ok", "offset"))
    flaws = check_baseline_drift(rec)
    assert [(f.kind, f.component) for f in flaws] == [("baseline_drift", 1)]
    assert flaws[0].details["final_velocity_m_s"] == pytest.approx(0.02 * t[-1], rel=1e-3)
    with pytest.raises(InputError, match="thresholds"):
        check_baseline_drift(rec, velocity_ratio=0)


def test_pga_and_duration_checks():
    rec = Record("r", 0.01, np.column_stack([np.full(100, 0.5), np.full(100, 1.0)]) * 9.80665)
    assert check_pga(rec, (0.5, 1.0)) == []
    flaws = check_pga(rec, (0.5, 1.2))
    assert [f.component for f in flaws] == [1] and "differs from the catalogue's 1.200 g" in flaws[0].message
    with pytest.raises(InputError, match="1 expected PGAs for 2 components"):
        check_pga(rec, (0.5,))
    assert check_duration(rec, 1.0) == [] and check_duration(rec, 3.0)[0].kind == "duration_mismatch"
    # constant components: they drift, and a channel that never changes is frozen
    # (and 1 s is shorter than any strong-motion record)
    assert {f.kind for f in check_record(rec, (0.1, 1.0), 5.0)} == {"pga_mismatch", "duration_mismatch",
                                                                       "baseline_drift", "stuck_channel",
                                                                       "implausible_duration"}


def test_a_record_shorter_than_any_earthquake_is_flagged():
    """Probed: a 0.5-s file (a truncated export) ran with 'flaws: none found'."""
    from records.plausibility import MIN_DURATION_S, check_plausibility
    t = np.arange(0.0, 0.5, 0.005)
    short = Record("short", 0.005, np.column_stack([np.sin(12 * t), np.cos(12 * t)]))
    flaws = [f for f in check_plausibility(short) if f.kind == "implausible_duration"]
    assert len(flaws) == 1 and "shorter than any strong-motion record" in flaws[0].message
    t = np.arange(0.0, MIN_DURATION_S + 1.0, 0.005)
    ok = Record("ok", 0.005, np.column_stack([np.sin(12 * t), np.cos(12 * t)]))
    assert not [f for f in check_plausibility(ok) if f.kind == "implausible_duration"]


def test_baseline_correction_removes_an_offset_and_trend():
    t, a = _clean()
    clean = Record("clean", 0.01, a)
    drifting = clean.replace(acceleration=a + 0.02 + 0.0002 * t)
    assert check_baseline_drift(drifting)
    fixed = baseline_correct(drifting)
    assert abs(fixed.velocity()[-1, 0]) < 1e-10          # final velocity zero by construction
    assert check_baseline_drift(fixed) == []
    assert fixed.pgd[0] == pytest.approx(clean.pgd[0], rel=0.15)
    assert drifting.pgd[0] > 5 * clean.pgd[0]
    assert "degree 3" in fixed.metadata["baseline_correction"]
    for degree in (1, 2.5, 9):
        with pytest.raises(InputError, match="degree"):
            baseline_correction_acceleration(a, 0.01, degree)


def test_end_condition_correction_is_exact():
    rng = np.random.default_rng(0)
    a = rng.standard_normal((500, 2))
    rec = Record("r", 0.02, a - end_condition_correction(a, 0.02))
    assert np.allclose(rec.velocity()[-1], 0, atol=1e-12) and np.allclose(rec.displacement()[-1], 0, atol=1e-12)


def test_correcting_the_drifting_benchmark_records_clears_the_flag(records_dir):
    for name in ("rinaldi", "jiji"):
        raw = load_benchmark_record(name, records_dir=records_dir)
        fixed = load_benchmark_record(name, records_dir=records_dir, baseline_correct=True)
        assert check_baseline_drift(raw) and not check_baseline_drift(fixed)
        assert np.allclose(fixed.pga_g, raw.pga_g, rtol=0.01)   # a gentle correction
