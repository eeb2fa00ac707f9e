"""Dirty real-world files the screening must not over- or under-flag (issue 24 item 1, found by
probing the readers with corrupted copies): a single dropout in a broadband recording, a force
clipped at every peak, a force pinned at one value in every cycle, implausible units and a
test too short to trace, each with the one-line message a user gets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest, read_utfsm, write_csv
from damper.io.dyke import read_dyke
from damper.io.reader import require_samples
from damper.io.screening import screen, screened, stuck_spans
from damper.lab.laboratory import general_test, periodic_test

UTFSM = "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados"
DYKE = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"


def _broadband(seconds=12.0, rate=2000.0):
    """A random motion with a slow drift (its largest spectral peak) and a band up to ~30 Hz."""
    t = np.arange(int(seconds * rate)) / rate
    rng = np.random.default_rng(7)
    fast = np.convolve(rng.standard_normal(t.size), np.hanning(61) / 30, mode="same")
    x = 0.004 * np.sin(2 * np.pi * 0.2 * t) + 0.002 * fast / np.std(fast)
    v = np.where(np.floor(t / 0.5) % 2 == 0, 0.2, 0.8)
    return general_test("virtual", t, x, v, noise=0.01, seed=2)


def test_one_dropout_in_a_broadband_test_excludes_that_sample_only():
    """A NaN force in a random-motion test: the velocity check's derivative keeps the velocity's
    band (the dominant period, the slow drift, would smooth it into departures everywhere) and
    no island is cut around a force-only flag."""
    test = _broadband()
    assert screen(test).clean, screen(test).lines()
    mask = np.ones(test.n_samples, dtype=bool)
    mask[test.n_samples // 2] = False
    scr = screen(test, prior_excluded=~mask)
    assert int((~scr.usable).sum()) == 1, scr.lines()
    assert not {f.kind for f in scr.findings} & {"velocity", "island"}


@pytest.mark.parametrize("cell", ["NaN", ""])
def test_one_dropout_in_the_dyke_recording(shared_dir, tmp_path, cell):
    """A missing force (a NaN or an empty cell, as loggers write them) in half the shared
    recording: that one sample is left out (the whole file was, before)."""
    lines = (shared_dir / DYKE).read_text().splitlines()[:30001]
    row = lines[15001].split(",")
    row[6] = cell
    lines[15001] = ",".join(row)
    path = tmp_path / "dropout.csv"
    path.write_text("\n".join(lines) + "\n")
    test = read_dyke(path)
    scr = test.metadata["screening"]
    # the dropout, and the recording's own held reading at 4.97 s (two slots; tests/damper/test_screening.py)
    assert int((~test.mask).sum()) == 1 + 2, scr.lines()
    assert {f.kind for f in scr.findings} == {"nan", "rounded", "held"}
    assert sum(f.n_samples for f in scr.findings if f.kind == "nan") == 1


def test_force_clipped_at_every_peak_excludes_the_clipped_samples_only():
    """A load cell saturating at each force peak: the motion is intact, so the samples between
    the clipped spans are data (no island)."""
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    level = np.percentile(test.force, 97)
    f = np.minimum(test.force, level)
    scr = screen(dataclasses.replace(test, force=f, mask=None, metadata={}))
    clipped = f == level
    assert {f.kind for f in scr.findings} == {"clipped"}, scr.lines()
    assert np.array_equal(~scr.usable, clipped)


def test_force_pinned_at_one_value_in_every_cycle_is_stuck(shared_dir):
    """Runs at one constant inside the range (not the channel's extreme), many per file: more
    than the 1 % of the runs the old trimming left out of the channel's own repeat statistics."""
    test = read_utfsm(shared_dir / UTFSM / "10mm1Hz1A.txt")
    f = test.force.copy()
    pinned = (f > 0) & (f < 1000)
    f[pinned] = 1436.9
    starts = np.flatnonzero(np.diff(np.r_[0, pinned.astype(int)]) == 1)
    assert starts.size >= 10
    spans = stuck_spans(f)
    flagged = np.zeros(f.size, dtype=bool)
    for kind, a, b, level in spans:
        assert kind == "stuck" and level == 1436.9
        flagged[a:b] = True
    assert np.array_equal(flagged, pinned)
    # the clean files' own repeats stay below the threshold
    assert stuck_spans(test.force) == []


def test_a_rejected_file_says_what_the_screening_found(tmp_path):
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    f = test.force.copy()
    f[:-5] = 123.0                                       # a dead load cell
    bad = screened(dataclasses.replace(test, force=f, mask=None, metadata={}))
    with pytest.raises(InputError, match=r"\((stuck|clipped) force: 1 span, 2996 samples; --keep-flagged"):
        require_samples(bad, "dead.csv")


def test_implausible_units_are_refused_by_the_command_line_readers(tmp_path):
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    in_ms = DamperTest(test.time * 1e3, test.displacement, test.velocity / 1e3, test.force,
                       voltage=test.voltage, name="ms")
    with pytest.raises(InputError, match=r"implausible units \(time: sample rate 0\.5 Hz.*unit in the header.*or convert the file to SI"):
        require_samples(screened(in_ms), "ms.csv")


def test_a_coil_input_in_milli_units_is_refused_and_a_real_one_is_not(shared_dir):
    """A current in mA (or a voltage in mV) declared as A (V): a `units` finding and a one-line
    refusal; the UTFSM currents (0-1 A) and the Dyke command (-0.44-2.7 V) pass."""
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    in_mv = dataclasses.replace(test, voltage=test.voltage * 1e3, mask=None, metadata={})
    with pytest.raises(InputError, match=r"implausible units \(voltage: peak voltage 500 V is outside the "
                                         r"plausible 0-60 V"):
        require_samples(screened(in_mv), "mv.csv")
    utfsm = read_utfsm(shared_dir / "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados/10mm1Hz1A.txt")
    assert not [f for f in screen(utfsm).findings if f.kind == "units"]
    in_ma = dataclasses.replace(utfsm, current=utfsm.current * 1e3, mask=None, metadata={})
    assert [f.channel for f in screen(in_ma).findings if f.kind == "units"] == ["current"]
    dyke = read_dyke(shared_dir / "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv")
    assert not [f for f in screen(dyke).findings if f.kind == "units"]


def test_too_short_to_trace_is_one_clear_error():
    from damper.diagnosis import diagnose
    test = periodic_test("virtual", 0.02, 2.0, 0.5, cycles=1.2, sample_rate=120.0, noise=0.01, seed=3)
    with pytest.raises(InputError, match=r"usable held-out samples; the residual trace needs at least 80") as caught:
        diagnose([test])
    assert test.name in str(caught.value)  # which test, when several were given


def test_lag_estimate_of_a_signal_shorter_than_the_lag_window_warns_nothing():
    """A lag window as long as the signal (a few samples left after the screening) has no overlap
    at its ends: the estimate keeps to the lags it can average, with no divide warning."""
    import warnings

    from damper.io.screening import _lag

    rng = np.random.default_rng(3)
    a = rng.normal(size=12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lag, corr = _lag(np.roll(a, 2), a, max_lag=40)
    assert lag == 2 and np.isfinite(corr)


def test_the_rigs_lurch_is_found_in_a_part_of_the_dyke_recording_with_a_rounded_time_grid(shared_dir, tmp_path):
    """The recording's last half second is a rig out of control: a lurch at 19.51 s, then the
    force clipped at 4545 N. Its second part on its own (t >= 11 s, as another recording of the
    device would come) has only that fault near the lurch, and a rounded time grid, which is
    reported only. That finding used to count as an input fault over the whole test, and the
    flailing tail lifted the velocity envelope over the lurch: the lurch (|v| 0.9 m/s, a 14 mm
    jump) was fitted and scored as data, and a model that predicts the rest at 0.09-0.13 scored
    0.23 on it. Both parts must exclude the same span now."""
    lines = [ln for ln in (shared_dir / DYKE).read_text().splitlines() if ln.strip()]
    cut = 1 + int(0.55 * (len(lines) - 1))
    rows = [ln.split(",") for ln in lines[cut:]]
    for i, row in enumerate(rows):
        row[4] = "3004.8" if i == 0 else ""  # the sample rate cell, on the first row as in the file
    path = tmp_path / "second_part.csv"
    path.write_text("\n".join([lines[0]] + [",".join(r) for r in rows]) + "\n")
    part, whole = read_dyke(path), read_dyke(shared_dir / DYKE)
    assert "rounded" in {f.kind for f in part.metadata["screening"].findings}
    for test in (part, whole):
        lurch = (test.time > 19.505) & (test.time < 19.59)
        assert not test.mask[lurch & (np.abs(test.velocity) > 0.5)].any(), test.metadata["screening"].lines()
        kinds = {f.kind for f in test.metadata["screening"].findings if f.t_start > 19.5}
        assert "excursion" in kinds
    clean = part.time < 19.4
    assert part.mask[clean].all()  # nothing else in the second part is touched


def _held_copy(test, slots, tmp_path, name="held.csv"):
    """``test`` written as a logger that missed sample periods would write it: at each slot the
    displacement and the force repeat the reading before, and the velocity, differentiated by
    the logger, is zero there and doubled after."""
    x, f = test.displacement.copy(), test.force.copy()
    for i in slots:
        x[i], f[i] = x[i - 1], f[i - 1]
    v = np.gradient(x, test.time)
    path = tmp_path / name
    write_csv(dataclasses.replace(test, displacement=x, force=f, velocity=v, mask=None, metadata={}), path)
    return path


def test_a_loggers_held_readings_are_found_interpolated_and_left_out(tmp_path):
    """A reading written into two slots in mid-stroke (the 50-Hz LabControl UTFPR rig's files
    hold 7-13 per 15-s test, one before most reversals): found, the motion interpolated through
    it, the samples left out; ``--keep-flagged`` reports it and keeps the file's values."""
    from damper.io.data import read_csv
    # 0.93 Hz: a rig never repeats its stroke to the digit from cycle to cycle (a sine whose period is
    # a whole number of samples would, and would look quantised to its own sample values)
    clean = periodic_test("virtual", 0.02, 0.93, 1.0, cycles=6, sample_rate=50.0, noise=0.005, seed=1)
    slots = [67, 118, 171, 240]   # mid-stroke and near reversals, away from the start
    path = _held_copy(clean, slots, tmp_path)
    test = read_csv(path)
    held = [fd for fd in test.metadata["screening"].findings if fd.kind == "held"]
    assert sorted(round(fd.t_start * 50.0) for fd in held) == [s - 1 for s in slots], test.metadata["screening"].lines()
    assert all(fd.n_samples == 2 for fd in held)
    out = np.flatnonzero(~test.mask)
    assert set(out) == {s - 1 for s in slots} | set(slots)  # no settling after a slot or two
    # the motion through a held pair is the line from the reading before to the one after
    for s in slots:
        expected = np.interp(test.time[s - 1:s + 1], test.time[[s - 2, s + 1]], clean.displacement[[s - 2, s + 1]])
        # the file keeps 10 significant digits of a 0.02-m stroke: 1e-12 m
        np.testing.assert_allclose(test.displacement[s - 1:s + 1], expected, rtol=0, atol=1e-11)
    # the file's velocity was 0 at the held slot: interpolated too, so within a step's change of the truth
    assert np.max(np.abs(test.velocity[slots] - clean.velocity[slots])) < 0.5 * np.max(np.abs(clean.velocity))
    kept = read_csv(path, keep_flagged=True)
    assert kept.mask is None
    assert all(not fd.excluded for fd in kept.metadata["screening"].findings if fd.kind == "held")
    np.testing.assert_array_equal(kept.displacement[slots], kept.displacement[[s - 1 for s in slots]])


def test_repeats_of_a_quantised_slow_stroke_are_not_held_readings():
    """A slow stroke on a coarse encoder and a coarse load cell repeats both channels at once on
    its plateaus and at its reversals (a staircase, one quantum per sample or less): data."""
    from damper.io.screening import held_samples
    t = np.arange(4000) / 200.0
    x = np.round(0.01 * np.sin(2 * np.pi * 0.1 * t) / 1e-4) * 1e-4        # 0.1-mm encoder
    f = np.round(800.0 * np.tanh(np.gradient(x, t) / 2e-3) / 20.0) * 20.0  # 20-N load cell
    assert np.sum((np.diff(x) == 0) & (np.diff(f) == 0)) > 100  # plenty of joint repeats
    assert not held_samples(x, f).any()
    # the same stroke, fast enough to move many quanta per sample, with one reading held
    x2 = np.round(0.01 * np.sin(2 * np.pi * 2.0 * t) / 1e-4) * 1e-4
    f2 = 800.0 * np.tanh(np.gradient(x2, t) / 2e-3) + 5.0 * np.sin(7 * t)
    x2[1013], f2[1013] = x2[1012], f2[1012]
    assert np.flatnonzero(held_samples(x2, f2)).tolist() == [1012, 1013]


@pytest.mark.parametrize("kind", ["backward", "forward", "sensor"])
def test_a_velocity_column_differenced_by_the_logger_is_replaced_by_the_central_difference(tmp_path, kind):
    """A logger's ``(x[i] - x[i-1]) / dt`` is the velocity half a step before the sample (the
    LabControl UTFPR files and all 30 UTFSM files): found and replaced by the central difference,
    which the model's time base expects. A velocity sensor's channel (the true derivative and its
    noise) is left as it is."""
    from damper.io.data import read_csv
    t = np.arange(1000) / 100.0
    x = 0.01 * np.sin(2 * np.pi * 0.73 * t) + 0.002 * np.sin(2 * np.pi * 2.1 * t)
    f = 900.0 * np.tanh(np.gradient(x, t) / 0.01)
    if kind == "backward":
        v = np.r_[0.0, np.diff(x) / np.diff(t)]
    elif kind == "forward":
        v = np.r_[np.diff(x) / np.diff(t), 0.0]
    else:
        exact = 2 * np.pi * (0.0073 * np.cos(2 * np.pi * 0.73 * t) + 0.0042 * np.cos(2 * np.pi * 2.1 * t))
        v = exact + 1e-4 * np.random.default_rng(3).standard_normal(t.size)
    path = tmp_path / "v.csv"
    path.write_text("time,displacement,velocity,force\n"
                    + "".join(f"{a!r},{b!r},{c!r},{d!r}\n" for a, b, c, d in
                              zip(t.tolist(), x.tolist(), v.tolist(), f.tolist())))
    test = read_csv(path, voltage=0.0)
    found = [fd for fd in test.metadata["screening"].findings if fd.kind == "difference"]
    if kind == "sensor":
        assert not found
        np.testing.assert_array_equal(test.velocity, v)
        return
    assert len(found) == 1 and f"{kind} difference" in found[0].message and not found[0].excluded
    np.testing.assert_allclose(test.velocity, np.gradient(x, t, edge_order=2), rtol=1e-12, atol=1e-15)
    assert test.mask is None


def test_repeats_that_are_no_missed_sample_are_left_as_read(tmp_path):
    """A pause of the rig (a reading repeated over 20 slots), and a file where every reading is
    written twice (resampled by repetition): neither is a missed sample period. The pause is no
    finding; the resampled file is said once and left as read, not interpolated into triangles."""
    from damper.io.data import read_csv
    from damper.io.screening import held_samples
    t = np.arange(2000) / 200.0
    x = 0.01 * np.sin(2 * np.pi * 0.37 * t)
    f = 500.0 * np.tanh(np.gradient(x, t) / 0.004) + 3.0 * np.sin(5.1 * t)
    paused_x, paused_f = x.copy(), f.copy()
    paused_x[700:720], paused_f[700:720] = x[700], f[700]
    assert not held_samples(paused_x, paused_f).any()
    twice_x, twice_f = np.repeat(x[::2], 2), np.repeat(f[::2], 2)
    assert not held_samples(twice_x, twice_f).any()
    path = tmp_path / "twice.csv"
    write_csv(DamperTest(t, twice_x, np.gradient(twice_x, t), twice_f, voltage=np.zeros(t.size), name="twice"), path)
    test = read_csv(path)
    held = [fd for fd in test.metadata["screening"].findings if fd.kind == "held"]
    assert len(held) == 1 and not held[0].excluded and "throughout the file" in held[0].message
    np.testing.assert_allclose(test.displacement, twice_x, rtol=0, atol=1e-12)


def test_half_a_sample_of_delay_is_placed_with_its_own_lag():
    """The delay estimate of a velocity channel half a sample late: the fraction and the lag it
    was computed at belong together (it used to come back a sample off, and the velocity check
    then flagged the whole test)."""
    from damper.io.screening import _delay
    t = np.arange(3000) / 50.0
    b = np.sin(2 * np.pi * 0.9 * t) + 0.3 * np.sin(2 * np.pi * 2.3 * t)
    a = np.sin(2 * np.pi * 0.9 * (t - 0.01)) + 0.3 * np.sin(2 * np.pi * 2.3 * (t - 0.01))
    lag, gain, _ = _delay(a, b, 5)
    assert lag == pytest.approx(0.5, abs=0.05) and gain == pytest.approx(1.0, abs=0.01)


def _clipped_utfsm(shared_dir, tmp_path, level):
    """The UTFSM 10 mm / 1 Hz / 1 A test (peak 1460 N) with its force clipped at ``level`` [N]."""
    rows = np.loadtxt(shared_dir / UTFSM / "10mm1Hz1A.txt")
    rows[:, 3] = np.clip(rows[:, 3], -level, level)
    path = tmp_path / "10mm1Hz1A.txt"  # the name carries the current
    np.savetxt(path, rows, fmt="%.7e")
    return path


def test_a_test_clipped_over_most_of_its_samples_is_refused(shared_dir, tmp_path):
    """A probe clipped at 1200 of 1460 N: 62 % of the samples left out, the model fitted on the rest
    printed a 7 % fit error and erred by 54 % over the whole record; 1350 N (35 %) still fits."""
    from damper.io.reader import read_usable
    with pytest.raises(InputError, match=r"the force is clipped over 6\d % of the test"):
        read_usable([_clipped_utfsm(shared_dir, tmp_path, 1200.0)])
    (path, test), = read_usable([_clipped_utfsm(shared_dir, tmp_path, 1350.0)])
    # the clipped peaks are said in one line, not one per peak (22 lines before)
    lines = screen(test).lines()
    assert sum("clipped (force)" in line for line in lines) == 1 and "in 2" in next(
        line for line in lines if "clipped (force)" in line)


def test_a_frozen_displacement_span_does_not_move_the_lag_estimates(shared_dir):
    """300 frozen displacement samples had read as the velocity lagging d(x)/dt by 6 ms and moved
    the force's lag from 18 to 11 ms: the lags are estimated on the longest clean stretch."""
    test = read_utfsm(shared_dir / UTFSM / "10mm1Hz1A.txt")
    clean = screen(test).estimates
    x = test.displacement.copy()
    x[5000:5300] = x[5000]
    dirty = screen(dataclasses.replace(test, displacement=x, mask=None, metadata={}))
    assert abs(dirty.estimates["force_velocity_lag_s"] - clean["force_velocity_lag_s"]) <= 0.0015
    assert abs(dirty.estimates["velocity_lag_s"]) < 0.001
    assert not [f for f in dirty.findings if f.kind == "offset"], dirty.lines()


def test_a_utfsm_file_with_decimal_commas_reads(shared_dir, tmp_path):
    text = (shared_dir / UTFSM / "10mm1Hz1A.txt").read_text()
    path = tmp_path / "10mm1Hz1A.txt"
    path.write_text(text.replace(".", ","))
    a, b = read_utfsm(shared_dir / UTFSM / "10mm1Hz1A.txt"), read_utfsm(path)
    assert np.array_equal(a.force, b.force) and np.array_equal(a.displacement, b.displacement)


def _spiked_copy(test, spikes, tmp_path, name="spiked.csv"):
    """``test`` written with glitches: ``spikes`` maps a channel to ``[(first sample, samples,
    jump)]``, each jump added to that many samples and gone after them."""
    cols = {"displacement": test.displacement.copy(), "force": test.force.copy(), "velocity": test.velocity.copy()}
    for channel, runs in spikes.items():
        for i, k, jump in runs:
            cols[channel][i:i + k] += jump
    path = tmp_path / name
    write_csv(dataclasses.replace(test, **cols, mask=None, metadata={}), path)
    return path


def test_spikes_in_the_force_and_the_motion_are_found_interpolated_and_left_out(tmp_path):
    """A logger's glitches (one to three samples far off their neighbours and back) in the force,
    the displacement and the velocity: each found where it is, interpolated through, left out of
    fit and error with no settling after it (the motion through it is the line between its
    neighbours); ``--keep-flagged`` reports them and keeps the file's values. The clean test has
    none (damper/io/screening.py ``spike_samples``)."""
    from damper.io.data import read_csv
    clean = _broadband(seconds=6.0)
    path = tmp_path / "clean.csv"
    write_csv(dataclasses.replace(clean, mask=None, metadata={}), path)
    assert not [fd for fd in read_csv(path).metadata["screening"].findings if fd.kind == "spike"]
    f_peak, x_peak, v_peak = (float(np.max(np.abs(a))) for a in (clean.force, clean.displacement, clean.velocity))
    spikes = {"force": [(1500, 1, 4.0 * f_peak), (4100, 2, -1.5 * f_peak)],
              "displacement": [(2600, 1, 0.5 * x_peak), (7900, 3, -0.8 * x_peak)],
              "velocity": [(9300, 1, 2.0 * v_peak)]}
    path = _spiked_copy(clean, spikes, tmp_path)
    test = read_csv(path)
    found = sorted((fd.channel, int(round(fd.t_start * 2000.0)), fd.n_samples)
                   for fd in test.metadata["screening"].findings if fd.kind == "spike")
    assert found == sorted((ch, i, k) for ch, runs in spikes.items() for i, k, _ in runs), \
        test.metadata["screening"].lines()
    hit = {i + j for runs in spikes.values() for i, k, _ in runs for j in range(k)}
    assert set(np.flatnonzero(~test.mask)) == hit  # nothing else: no settling, no island
    # interpolated: within the file's digits and the curvature over four samples of the truth
    for ch, truth in (("force", clean.force), ("displacement", clean.displacement)):
        for i, k, _ in spikes[ch]:
            got = getattr(test, ch)[i:i + k]
            assert np.max(np.abs(got - truth[i:i + k])) < 0.05 * np.ptp(truth), (ch, i)
    kept = read_csv(path, keep_flagged=True)
    assert kept.mask is None
    assert all(not fd.excluded for fd in kept.metadata["screening"].findings if fd.kind == "spike")
    assert kept.force[1500] == pytest.approx(clean.force[1500] + 4.0 * f_peak, rel=1e-8)


def test_spikes_in_the_dyke_recording_are_found_and_only_they_left_out(shared_dir, tmp_path):
    """Twelve force glitches in the first 6 s of the shared recording (six times the force, as
    a saturating amplifier writes them): found and left out, so the screened test is the clean
    one but for those samples."""
    from damper.io.screening import spike_samples
    clean = read_dyke(shared_dir / DYKE)
    n = int(np.searchsorted(clean.time, 6.0))
    part = dataclasses.replace(clean, time=clean.time[:n], displacement=clean.displacement[:n],
                               velocity=clean.velocity[:n], force=clean.force[:n], voltage=clean.voltage[:n],
                               mask=None, metadata={})
    rng = np.random.default_rng(5)
    loud = np.flatnonzero(np.abs(part.force) > 0.2 * np.max(np.abs(part.force)))  # a glitch that matters
    at = np.sort(rng.choice(loud[(loud > 100) & (loud < n - 100)], 12, replace=False))
    f = part.force.copy()
    f[at] *= 6.0
    assert np.flatnonzero(spike_samples(f)).tolist() == at.tolist()
    assert not spike_samples(part.force).any()  # its clean part: no glitch, sharp transients and all
    path = tmp_path / "spiked_dyke.csv"
    write_csv(dataclasses.replace(part, force=f), path)
    from damper.io.data import read_csv
    test = read_csv(path)
    assert sorted(set(np.flatnonzero(~test.mask)) - set(at)) == []  # nothing else left out for them
    assert set(at) <= set(np.flatnonzero(~test.mask))


def test_what_looks_like_a_spike_and_is_not():
    """A sharp but continuous peak (a force transient of a random test: the neighbours differ
    as much as the peak stands out), a coarsely sampled sine's crest, a step, a quantised channel
    toggling by its resolution: none is a spike. Glitches at more than 0.2 % of the samples (a
    knock at every reversal) are something the channel does: reported, left as read."""
    from damper.io.screening import SPIKE_MAX_SHARE, repair_samples, spike_samples
    t = np.arange(2000) / 1000.0
    sine = np.sin(2 * np.pi * 12.5 * t)          # 80 samples per period
    assert not spike_samples(sine).any()
    assert not spike_samples(np.sin(2 * np.pi * 100.0 * t)).any()  # 10 samples per period
    step = np.where(t < 1.0, 0.0, 1.0) + 0.001 * np.sin(2 * np.pi * 3 * t)
    assert not spike_samples(step).any()
    transient = sine.copy()
    transient[1000:1003] += [0.5, 1.0, 0.6]      # a ramp up and down over neighbours that differ
    transient[999] += 0.3
    transient[1003] += 0.3
    assert not spike_samples(transient).any()
    toggling = np.round(sine * 1000.0) / 1000.0
    toggling[500] += 0.001
    assert not spike_samples(toggling).any()
    glitch = sine.copy()
    glitch[700] += 2.0
    assert np.flatnonzero(spike_samples(glitch)).tolist() == [700]
    knocks = sine.copy()
    every = np.arange(20, 2000, 40)              # every reversal
    knocks[every] += 1.5
    assert spike_samples(knocks).sum() > SPIKE_MAX_SHARE * t.size
    _, cols, excluded, findings = repair_samples(t, {"displacement": sine, "force": knocks})
    assert not excluded.any()
    assert [fd.kind for fd in findings] == ["spike"] and not findings[0].excluded
    np.testing.assert_array_equal(cols["force"], knocks)


def test_a_second_recording_appended_after_a_clock_restart_is_said_as_such(tmp_path):
    """Two tests in one file, the clock back at 0 for the second: its rows are dropped as time
    going backwards, in one finding that says the clock restarts and how to use them (a logger's
    glitch of a few rows keeps the plain words)."""
    from damper.io.data import read_csv
    from damper.io.screening import RESTART_ROWS
    first = periodic_test("virtual", 0.01, 1.0, 0.5, cycles=4, sample_rate=200.0, noise=0.01, seed=1)
    second = periodic_test("virtual", 0.01, 2.0, 1.0, cycles=8, sample_rate=200.0, noise=0.01, seed=2)
    rows = ["time,displacement,force"]
    for test in (first, second):
        rows += [f"{a!r},{b!r},{c!r}" for a, b, c in zip(test.time.tolist(), test.displacement.tolist(),
                                                            test.force.tolist())]
    path = tmp_path / "two.csv"
    path.write_text("\n".join(rows) + "\n")
    test = read_csv(path, voltage=0.5)
    assert test.n_samples == first.n_samples
    np.testing.assert_array_equal(test.force, first.force)
    restart = [fd for fd in test.metadata["screening"].findings if "clock restarts" in fd.message]
    assert len(restart) == 1 and restart[0].n_samples >= second.n_samples - 1 >= RESTART_ROWS
    assert f"two.csv:{first.n_samples + 2}" in restart[0].message  # the line where it restarts
    stale = rows[20].split(",")
    glitch = rows[:50] + [",".join(stale[:2] + ["1.0"])] + rows[50:first.n_samples + 1]  # a stale stamp
    path.write_text("\n".join(glitch) + "\n")
    words = [fd.message for fd in read_csv(path, voltage=0.5).metadata["screening"].findings if fd.kind == "time"]
    assert words and not any("clock restarts" in w for w in words)


def test_commands_read_each_recording_of_a_file_whose_clock_restarts(tmp_path):
    """damper/io/reader.py read_tests: two recordings in one file (the clock back at 0 for the
    second) are two tests, each screened on its own and keyed by its part in the report; a
    stale stamp or a block written again does not split the file."""
    from damper.io.reader import read_tests
    from damper.io.screening import clock_restarts, screening_lines
    first = periodic_test("virtual", 0.01, 1.0, 0.5, cycles=4, sample_rate=200.0, noise=0.01, seed=1)
    second = periodic_test("virtual", 0.01, 2.0, 0.5, cycles=8, sample_rate=200.0, noise=0.01, seed=2)
    rows = ["time,displacement,force,voltage"]
    for test in (first, second):
        rows += [f"{a!r},{b!r},{c!r},0.5" for a, b, c in zip(test.time.tolist(), test.displacement.tolist(),
                                                              test.force.tolist())]
    path = tmp_path / "two.csv"
    path.write_text("\n".join(rows) + "\n")
    one, two = read_tests(path)
    np.testing.assert_array_equal(one.force, first.force)
    np.testing.assert_array_equal(two.force, second.force)
    assert (one.name, two.name) == ("two part 1", "two part 2")
    lines = screening_lines([one, two])
    assert any(f"two.csv (two part 2): the file's clock restarts at line {first.n_samples + 2}" in line
               for line in lines), lines
    t = np.arange(300) / 100.0
    stale = t.copy()
    stale[150] = 0.2
    assert clock_restarts(stale) == []                     # rejoins the clock at the next row
    again = np.r_[t, t[:150]]
    x = np.sin(again)
    assert clock_restarts(again, {"x": x}) == []           # the same rows written again
    assert clock_restarts(again, {"x": np.r_[x[:300], np.cos(t[:150])]}) == [300]  # another recording
