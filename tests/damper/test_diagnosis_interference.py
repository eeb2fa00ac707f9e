"""Mains interference on the force channel: a line of the final residual no motion drives
(damper/diagnosis/interference.py)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from damper.diagnosis import diagnose
from damper.diagnosis.interference import LINE_RATIO, interference_lines, mains_lines
from damper.io.data import read_utfsm

UTFSM = "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados"


def _residual_case(rate=1000.0, seconds=8.0, f_test=1.0, hum=0.0, hum_hz=50.0, seed=0):
    """A sinusoidal test's residual: a model's harmonic series at the test frequency (odd
    harmonics decaying as 1/k, as a sharp corner's do) plus noise, and a hum."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(rate * seconds)) / rate
    series = sum(30.0 / k * np.sin(2 * np.pi * k * f_test * t + rng.uniform(0, 6.3)) for k in range(1, 80, 2))
    noise = rng.normal(0.0, 10.0, t.size)
    measured = 1000.0 * np.sign(np.cos(2 * np.pi * f_test * t)) + series + noise + hum * np.sin(2 * np.pi * hum_hz * t + 0.3)
    predicted = 1000.0 * np.sign(np.cos(2 * np.pi * f_test * t))
    velocity = 0.06 * np.cos(2 * np.pi * f_test * t)
    return t, measured, predicted, velocity


def _search(t, measured, predicted, velocity, scored=None):
    mask = np.ones(t.size, bool) if scored is None else scored
    held = np.zeros(t.size, bool)
    held[int(0.75 * t.size):] = True
    f_test = _search.f_test
    displacement = 0.01 * np.sin(2 * np.pi * f_test * t)
    return mains_lines(["test"], [t], [measured], [predicted], [displacement], [velocity], [mask], [held & mask])


_search.f_test = 1.0  # the displacement's frequency, set by the tests that change it


@pytest.mark.parametrize("hum_hz, rate", [(50.0, 1000.0), (60.0, 1000.0), (50.0, 200.0), (120.0, 3000.0)])
def test_a_hum_is_found_with_its_amplitude(hum_hz, rate):
    t, f, p, v = _residual_case(rate=rate, hum=25.0, hum_hz=hum_hz)
    result = _search(t, f, p, v)
    (line,) = result["lines"]
    assert line["frequency_hz"] == pytest.approx(hum_hz, abs=0.05)
    # least squares over 8 s of noise at 10 N RMS: the amplitude within a few tenths of a newton
    assert line["amplitude_n"] == pytest.approx(25.0, rel=0.03)
    assert not line["in_motion"] and line["ratio"] >= LINE_RATIO
    assert result["error_without"] < result["error"]
    assert result["error_without_by_frequency"] == {round(hum_hz): result["error_without"]}
    ((text, finding),) = interference_lines(result)
    assert f"{hum_hz:g}-Hz line" in text and "mains interference" in text and finding


@pytest.mark.parametrize("f_test", [1.0, 5.0, 0.5, 50 / 7, 10.0, 12.5, 15.0, 20.0, 25.0])
def test_a_residual_without_hum_has_no_line(monkeypatch, f_test):
    """The residual's own harmonic series stands out of no band: odd harmonics at 49 and 51 Hz
    for a 1-Hz test, 45 and 55 Hz at 5 Hz; a 7.14-Hz test's 7th harmonic at 50 Hz, a 20-Hz
    test's 3rd at 60 Hz and 5th at 100 Hz against the harmonics two orders away, which the band
    (2.5 test frequencies at least) holds (a review had found them flagged at 10-25 Hz)."""
    monkeypatch.setattr(_search, "f_test", f_test)
    t, f, p, v = _residual_case(f_test=f_test)
    result = _search(t, f, p, v)
    assert result["lines"] == [] and result["error_without"] == result["error"]
    assert interference_lines(result) == []


def test_a_hum_beside_a_periodic_tests_harmonics_is_found(monkeypatch):
    """A 12.5-Hz test (odd harmonics of 10 and 6 N at 37.5 and 62.5 Hz, in the band) with a
    50-Hz hum of 60 N (36 times the 3rd harmonic's power): found; at 25 N (6 times) it could be
    the test's own and is not claimed."""
    monkeypatch.setattr(_search, "f_test", 12.5)
    t, f, p, v = _residual_case(f_test=12.5, hum=25.0)
    assert _search(t, f, p, v)["lines"] == []
    t, f, p, v = _residual_case(f_test=12.5, hum=60.0)
    (line,) = _search(t, f, p, v)["lines"]
    assert line["frequency_hz"] == pytest.approx(50.0, abs=0.05) and not line["in_motion"]


def test_a_line_the_velocity_has_too_is_the_motions():
    t, f, p, v = _residual_case(hum=25.0)
    v = v + 0.002 * np.sin(2 * np.pi * 50.0 * t)  # the shaker's hum moves the damper
    result = _search(t, f, p, v)
    (line,) = result["lines"]
    assert line["in_motion"] and result["error_without"] == result["error"]
    ((text, finding),) = interference_lines(result)
    assert "the motion channels carry it" in text and not finding


def test_short_irregular_or_unscored_tests_are_not_searched():
    t, f, p, v = _residual_case(seconds=3.0, hum=25.0)
    assert _search(t, f, p, v) is None  # 3 s: a resolution coarser than the mains' tolerance
    t, f, p, v = _residual_case(hum=25.0)
    jittered = t + np.random.default_rng(1).uniform(-1e-4, 1e-4, t.size)  # 20 % of a step
    assert _search(jittered, f, p, v) is None
    # absolute stamps (a logger's clock, 1.7e9 s): uniform to the float's 2.4e-7 s, searched
    assert _search(1.7e9 + t, f, p, v)["lines"]
    scored = np.zeros(t.size, bool)
    scored[:3000] = True  # 3 s scored of 8
    assert _search(t, f, p, v, scored) is None


def test_flagged_samples_do_not_make_a_line():
    """A flagged span (zeroed in the search) does not spread into a line, and the hum is found
    with its amplitude over the rest."""
    t, f, p, v = _residual_case(hum=25.0)
    scored = np.ones(t.size, bool)
    scored[2000:2600] = False
    f = f.copy()
    f[2000:2600] = 5000.0  # a clipped span, excluded by the screening
    (line,) = _search(t, f, p, v, scored)["lines"]
    assert line["amplitude_n"] == pytest.approx(25.0, rel=0.03)


def test_the_loop_names_a_hum_on_a_measured_test(shared_dir):
    """The UTFSM 10 mm / 1 Hz test at 1 A with a 40-N, 50-Hz hum on its force (3.4 % of its
    RMS): the diagnosis names the line, its amplitude and what it costs; the test as measured
    has none."""
    test = read_utfsm(shared_dir / UTFSM / "10mm1Hz1A.txt")
    hum = 40.0 * np.sin(2 * np.pi * 50.0 * test.time + 1.0)
    hummed = dataclasses.replace(test, force=test.force + hum)
    result = diagnose([hummed], max_effects=0)
    (line,) = result.interference["lines"]
    assert line["frequency_hz"] == pytest.approx(50.0, abs=0.02)
    assert line["amplitude_n"] == pytest.approx(40.0, rel=0.05)
    document = json.loads(json.dumps(result.to_json()))
    assert document["interference"]["lines"][0]["test"] == test.name
    clean = diagnose([test], max_effects=0)
    assert clean.interference["lines"] == []
    assert "interference" in clean.to_json()
    # the hum holds (40^2 / 2) / 1191^2 of the force's power, 0.024 of its RMS in quadrature;
    # taken off, the error is the measured test's own to within the refit's change of the model
    assert result.interference["error_without"] < result.interference["error"] - 0.002
    assert result.interference["error_without"] == pytest.approx(clean.error_after, abs=0.002)
