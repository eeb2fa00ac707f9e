"""``--validate`` recordings that cannot score a model are refused before any fit
(:func:`damper.diagnosis.loop.check_recordings`), and one whose coil input lies past the fitted
levels is scored with that said (``input_beyond_levels``).

Each case was scored silently before: a recording without the current column at 0.885 error as if
at 0 A, one at 0 A against a model fitted at 1 A only at 7.54 (a model of one level has no law of
the input), a fitted test given again as a training score, 50 samples without a reversal."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.loop import check_recordings
from damper.io.data import DamperTest


def _test(name: str, current: float | None, seconds: float = 3.0, phase: float = 0.0) -> DamperTest:
    t = np.arange(0.0, seconds, 1e-3)
    x = 0.005 * np.sin(2 * np.pi * 2.0 * t + phase)
    xd = 0.005 * 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t + phase)
    f = 500.0 * np.tanh(xd / 0.01) + 2000.0 * xd
    i = None if current is None else np.full(t.size, current)
    return DamperTest(t, x, xd, f, current=i, name=name)


def _check(fitted, recordings):
    data = DiagnosisData.from_tests(fitted, holdout=0.25)
    check_recordings(fitted, data, recordings)


def test_a_recording_without_the_coil_input_is_refused():
    with pytest.raises(InputError, match="no voltage or current column"):
        _check([_test("a", 1.0)], [_test("b", None, phase=0.3)])


def test_a_fitted_test_given_again_is_refused():
    a = _test("a", 1.0)
    with pytest.raises(InputError, match="also a fitted test"):
        _check([a, _test("b", 1.0, phase=0.5)], [a])


def test_less_than_a_cycle_is_refused():
    with pytest.raises(InputError, match="a cycle of motion"):
        _check([_test("a", 1.0)], [_test("short", 1.0, seconds=0.05)])


def test_another_level_than_a_single_fitted_one_is_refused():
    with pytest.raises(InputError, match="at 0 A where the fitted tests are all at 1 A"):
        _check([_test("a", 1.0)], [_test("b", 0.0, phase=0.3)])


def test_valid_recordings_pass():
    # the same level, another recording (its current measured, wandering by 1 %); and a level
    # between two fitted ones
    _check([_test("a", 1.0)], [_test("b", 1.0, phase=0.3)])
    w = _test("w", 1.0, phase=0.3)
    wandering = DamperTest(w.time, w.displacement, w.velocity, w.force, name="w",
                           current=1.0 + 0.01 * np.sin(np.arange(w.time.size)))
    _check([_test("a", 1.0)], [wandering])
    _check([_test("a", 0.0), _test("c", 1.0)], [_test("b", 0.5, phase=0.3)])
    # no coil input anywhere: a passive device, fitted and scored as such
    _check([_test("a", None)], [_test("b", None, phase=0.3)])


def test_a_level_past_the_fitted_ones_is_scored_and_said():
    from damper.diagnosis.loop import diagnose
    fitted = [_test("a", 0.5), _test("c", 1.0, phase=0.2)]
    result = diagnose(fitted, holdout=0.25, candidates=["offset"], cross_validate=[_test("b", 0.0, phase=0.3)])
    beyond = result.validation["input_beyond_levels"]
    assert list(beyond) == ["b"] and beyond["b"]["share"] == 1.0 and beyond["b"]["levels"] == [0.5, 1.0]
    inside = diagnose(fitted, holdout=0.25, candidates=["offset"], cross_validate=[_test("d", 0.75, phase=0.3)])
    assert inside.validation["input_beyond_levels"] == {}
