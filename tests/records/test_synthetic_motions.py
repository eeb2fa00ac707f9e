"""The synthetic generator: targets met (PGA exactly, length, D5-95, spectral shape, pulse period), seeds, labels."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import welch

from benchmark.foundation.errors import InputError, ParameterError
from records import BENCHMARK_RECORDS, CATALOGUE, benchmark_like, check_record
from records.measures import mean_period, significant_duration
from records.pulse import PulseParameters, fit_pulse
from records.record import STANDARD_GRAVITY, cumulative_trapezoid
from records.synthetic import (Envelope, GroundMotionModel, benchmark_like_models, envelope_for_duration,
                               generate, omega_g_for_mean_period)


def test_pga_scaling_is_exact_and_length_matches():
    for name in ("kobe", "elcentro"):
        rec = benchmark_like(name, "FN-x", seed=3)
        entry = CATALOGUE[name]
        assert np.max(np.abs(rec.acceleration), axis=0) / STANDARD_GRAVITY == pytest.approx(entry.pga_g, rel=1e-12)
        assert rec.duration == pytest.approx(entry.duration_s) and rec.dt == 0.005


def test_seed_reproducibility_bit_for_bit_and_orientation_swap():
    a = benchmark_like("rinaldi", "FN-x", seed=7)
    b = benchmark_like("rinaldi", "FN-x", seed=7)
    c = benchmark_like("rinaldi", "FN-x", seed=8)
    fp = benchmark_like("rinaldi", "FP-x", seed=7)
    assert np.array_equal(a.acceleration, b.acceleration)
    assert not np.allclose(a.acceleration, c.acceleration)
    assert np.array_equal(fp.acceleration, a.acceleration[:, ::-1])
    assert fp.labels == a.labels[::-1]
    other = benchmark_like("sylmar", "FN-x", seed=7)           # each record draws its own stream
    n = min(other.n_samples, a.n_samples)
    assert not np.allclose(other.acceleration[:n], a.acceleration[:n])


def test_labelled_synthetic_everywhere():
    rec = benchmark_like("erzincan", "FP-x", seed=0)
    assert rec.synthetic and rec.name == "synthetic-erzikan"
    assert rec.source.startswith("synthetic:") and "seed=0" in rec.source
    assert all(label.startswith("synthetic") for label in rec.labels)
    assert rec.metadata["targets"]["pga_g"] == [0.496, 0.515]
    assert check_record(rec) == []                              # no drift, no identical columns


def test_significant_duration_and_mean_period_match_the_targets_on_average():
    name = "kobe"
    entry = CATALOGUE[name]
    seeds = range(6)
    recs = [benchmark_like(name, "FN-x", seed=s) for s in seeds]
    d2 = np.mean([significant_duration(r.acceleration[:, 1], r.dt) for r in recs])
    tm2 = np.mean([mean_period(r.acceleration[:, 1], r.dt) for r in recs])
    assert d2 == pytest.approx(entry.significant_duration_s[1], rel=0.15)
    assert tm2 == pytest.approx(entry.mean_period_s[1], rel=0.15)


def test_envelope_calibration_reaches_the_significant_duration():
    for total, target in ((30.0, 5.3), (30.0, 23.8), (90.0, 12.5)):
        env = envelope_for_duration(total, target)
        model = GroundMotionModel(duration=total, pga=3.0, envelope=env)
        d = np.mean([significant_duration(generate(model, seed=s).acceleration[:, 0], 0.005) for s in range(4)])
        assert d == pytest.approx(target, rel=0.12), (total, target)
    with pytest.raises(ParameterError, match="shorter than the record length"):
        envelope_for_duration(10.0, 12.0)


def test_stationary_spectrum_has_the_filters_shape_and_peak():
    model = GroundMotionModel(duration=1500.0, pga=2.0, dt=0.01, omega_g=2 * np.pi * 2.0, zeta_g=0.4,
                              omega_f=2 * np.pi * 0.2, zeta_f=0.6)
    acc = generate(model, seed=11).acceleration[:, 0]
    f, pxx = welch(acc, fs=1 / model.dt, nperseg=1024)
    band = (f > 0.3) & (f < 15)
    shape = model.psd_shape(2 * np.pi * f[band])
    # peak frequency of a smoothed estimate close to the filters' (1.78 Hz)
    smooth = np.convolve(pxx[band], np.ones(9) / 9, mode="same")
    assert f[band][np.argmax(smooth)] == pytest.approx(model.peak_frequency(), rel=0.1)
    # the whole shape: log-spectra agree after normalisation (Welch scatter alone is about 0.07)
    ratio = np.log(pxx[band] / pxx[band].mean()) - np.log(shape / shape.mean())
    assert np.std(ratio) < 0.15
    # a different filter gives a clearly different shape: the comparison can fail
    other = GroundMotionModel(duration=10.0, pga=1.0, omega_g=2 * np.pi * 5.0).psd_shape(2 * np.pi * f[band])
    assert np.std(np.log(pxx[band] / pxx[band].mean()) - np.log(other / other.mean())) > 0.3
    # and the mean period of the generated noise matches the one the calibration predicts
    wg = omega_g_for_mean_period(0.5)
    noise = GroundMotionModel(duration=200.0, pga=2.0, omega_g=wg, omega_f=0.1 * wg)
    tm = np.mean([mean_period(generate(noise, seed=s).acceleration[:, 0], 0.005) for s in range(3)])
    assert tm == pytest.approx(0.5, rel=0.08)


def test_pulse_model_acceleration_is_the_velocity_derivative():
    pulse = PulseParameters(amplitude=0.8, period=1.5, gamma=2.3, phase=0.4, t_peak=6.0)
    t = np.arange(0, 15, 0.001)
    v = pulse.velocity(t)
    assert np.max(np.abs(cumulative_trapezoid(pulse.acceleration(t), 0.001) - v)) < 1e-5
    assert v[0] == 0 and v[-1] == 0 and np.max(np.abs(v)) <= 0.8 + 1e-12
    assert pulse.support == pytest.approx((6.0 - 1.725, 6.0 + 1.725))
    with pytest.raises(ParameterError, match="gamma"):
        PulseParameters(1.0, 1.0, gamma=1.0)


def test_pulse_period_is_recovered_from_a_generated_motion():
    for tp, amplitude in ((0.9, 0.6), (2.5, 1.0), (6.0, 1.2)):
        pulse = PulseParameters(amplitude=amplitude, period=tp, gamma=2.0, phase=0.0, t_peak=4.0 + tp)
        model = GroundMotionModel(duration=30.0, pga=0.5 * STANDARD_GRAVITY, omega_g=8 * np.pi,
                                  omega_f=max(0.8 * np.pi, 2 * np.pi / tp), envelope=Envelope(2.0, 4.0, 0.4),
                                  pulse=pulse)
        periods = []
        for seed in range(3):
            rec = generate(model, seed=seed)
            assert rec.pga[0] == pytest.approx(model.pga, rel=1e-12)
            assert 0.3 < rec.metadata["pulse_scale"] < 1.5   # may exceed 1 where the pulse cancels a noise peak
            fit = fit_pulse(rec.velocity()[:, 0], rec.dt)
            periods.append(fit.period)
            assert fit.period == pytest.approx(tp, rel=0.15)
            assert fit.pulse.amplitude == pytest.approx(amplitude * rec.metadata["pulse_scale"], rel=0.2)
        assert np.median(periods) == pytest.approx(tp, rel=0.08), periods


def test_pulse_records_keep_their_significant_duration():
    entry = CATALOGUE["rinaldi"]
    d = np.mean([significant_duration(benchmark_like("rinaldi", seed=s).acceleration[:, 0], 0.005)
                 for s in range(4)])
    assert d == pytest.approx(entry.significant_duration_s[0], rel=0.25)


def test_benchmark_like_pulse_periods_are_recovered():
    for name in ("rinaldi", "newhall"):
        tp = CATALOGUE[name].pulse_period_s[0]
        periods = [fit_pulse(benchmark_like(name, seed=s).velocity()[:, 0], 0.005).period for s in range(3)]
        assert np.median(periods) == pytest.approx(tp, rel=0.2), (name, periods)


def test_models_of_every_record_are_valid_and_pulses_only_where_catalogued():
    for name in BENCHMARK_RECORDS:
        m1, m2 = benchmark_like_models(name)
        assert (m1.pulse is not None) == (CATALOGUE[name].pulse_period_s[0] is not None)
        assert m2.pulse is None
        assert m1.pga == pytest.approx(CATALOGUE[name].pga_g[0] * STANDARD_GRAVITY)


@pytest.mark.parametrize("kwargs, match", [
    (dict(pga=0.0), "pga"),
    (dict(duration=-1.0), "duration"),
    (dict(zeta_g=0.0), "zeta_g"),
    (dict(omega_g=1000.0), "Nyquist"),
    (dict(duration=0.01), "shorter than 4 steps"),
])
def test_invalid_models_are_rejected(kwargs, match):
    args = dict(duration=10.0, pga=1.0)
    args.update(kwargs)
    with pytest.raises(ParameterError, match=match):
        GroundMotionModel(**args)


def test_invalid_benchmark_like_arguments():
    with pytest.raises(InputError, match="not a benchmark record"):
        benchmark_like("loma")
    with pytest.raises(InputError, match="orientation"):
        benchmark_like("kobe", "x-FN")
    with pytest.raises(InputError, match="seed"):
        benchmark_like("kobe", seed=-1)
    strong = PulseParameters(amplitude=5.0, period=0.5, gamma=2.0, t_peak=5.0)
    with pytest.raises(ParameterError, match="reaches the target PGA"):
        generate(GroundMotionModel(duration=20.0, pga=1.0, pulse=strong))
