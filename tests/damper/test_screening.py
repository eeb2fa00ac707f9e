"""Screening of measured damper tests (issue 24 item 1): each flaw injected into real (shared)
and synthetic tests is found, and its samples are left out of the fit and the error; clean
data (noisy synthetic tests, the 30 UTFSM files) give no finding."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest, read_csv, read_utfsm, write_csv
from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.selection import relative_rms_error as selection_rms
from damper.io.dyke import read_dyke
from damper.identification.metrics import relative_rms_error
from damper.lab.laboratory import general_test, periodic_test
from damper.io.screening import keep_flagged, repair_samples, screen, screened

UTFSM = "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados"
DYKE = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"


@pytest.fixture(scope="module")
def clean_synthetic():
    """A noisy (2 % force noise) but otherwise clean virtual-laboratory test."""
    return periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.02, seed=3)


@pytest.fixture(scope="module")
def utfsm_test(shared_dir):
    return read_utfsm(shared_dir / UTFSM / "25mm0x5Hz1A.txt")


def _kinds(scr, channel=None):
    return {f.kind for f in scr.findings if channel is None or f.channel == channel}


def _with(test, **arrays):
    return dataclasses.replace(test, mask=None, metadata={}, **arrays)


def _flagged_span(scr, kind, channel):
    hits = [f for f in scr.findings if f.kind == kind and f.channel == channel]
    assert hits, [f.line() for f in scr.findings]
    return hits


# --------------------------------------------------------------------------------------------
# no false positives
# --------------------------------------------------------------------------------------------
def test_clean_noisy_synthetic_tests_give_no_finding(clean_synthetic):
    scr = screen(clean_synthetic)
    assert scr.clean, scr.lines()
    assert scr.usable.all()
    # a random-motion test with a switching command, noisy too
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 6.0, 1e-3)
    x = 0.01 * np.convolve(rng.standard_normal(t.size), np.hanning(301) / 150, mode="same")
    v = np.where(np.floor(t / 0.7) % 2 == 0, 0.0, 1.0)
    random = general_test("virtual", t, x, v, noise=0.02, seed=1)
    assert screen(random).clean, screen(random).lines()


def test_clean_utfsm_files_give_no_finding_but_their_differenced_velocity(shared_dir):
    """The 30 UTFSM files are clean; their velocity column is the displacement's backward
    difference to the files' digits (at most 5e-6 of the peak velocity), half a step late, and is
    replaced by the central difference: reported, nothing excluded."""
    files = sorted((shared_dir / UTFSM).glob("*.txt"))
    assert len(files) == 30
    for path in files:
        raw = np.loadtxt(path)
        test = read_utfsm(path)
        scr = test.metadata["screening"]
        assert [(f.kind, f.excluded) for f in scr.findings] == [("difference", False)], scr.lines()
        assert "backward difference" in scr.findings[0].message
        assert test.mask is None
        # the central difference of the displacement as read, in m/s
        np.testing.assert_allclose(test.velocity, np.gradient(raw[:, 1] * 1e-3, raw[:, 0], edge_order=2),
                                   rtol=1e-12, atol=1e-15)


# --------------------------------------------------------------------------------------------
# the shared Dyke record: the corrupted tail
# --------------------------------------------------------------------------------------------
def test_dyke_clipped_tail_is_found_and_excluded(shared_dir):
    test = read_dyke(shared_dir / DYKE)
    scr = test.metadata["screening"]
    clipped = [f for f in scr.findings if f.kind == "clipped" and f.channel == "force"]
    assert sum(f.n_samples for f in clipped) == 217
    assert min(f.t_start for f in clipped) >= 19.59 - 1e-9
    tail = (test.time >= 19.59) & (np.abs(test.force - 4545.4545) < 1e-3)
    assert tail.sum() == 217
    assert test.mask is not None and not test.mask[tail].any()
    # nothing flagged in the first 19.5 s but one held reading: at 4.9724 and 4.9727 s the
    # displacement D and the force F repeat exactly (-0.37044 in, -290.9618 N) in mid-stroke,
    # steps of 77 and 47 quanta of D on either side, while the velocity and acceleration
    # channels move on: two slots of one reading, interpolated and left out
    early = [f for f in scr.findings if f.t_end < 19.5]
    assert [(f.kind, f.n_samples) for f in early] == [("held", 2)], scr.lines()
    assert early[0].t_start == pytest.approx(4.9724, abs=2e-4)
    early_mask = test.mask[test.time < 19.5]
    assert (~early_mask).sum() == 2
    # the displacement is frozen there too
    assert any(f.channel == "displacement" and f.kind in ("stuck", "frozen") for f in scr.findings)
    # and before it freezes the rig lurches (14 mm in 20 ms at 0.9 m/s, three times anything
    # before): from t = 19.513 s on nothing counts
    assert any(f.kind == "excursion" for f in scr.findings), scr.lines()
    assert not test.mask[test.time >= 19.513].any()
    # --keep-flagged: reported, not masked
    kept = read_dyke(shared_dir / DYKE, keep_flagged=True)
    assert kept.mask is None and kept.metadata["screening"].findings


# --------------------------------------------------------------------------------------------
# each flaw injected into a synthetic and a real test
# --------------------------------------------------------------------------------------------
@pytest.fixture(params=["synthetic", "utfsm"])
def base_test(request, clean_synthetic, shared_dir):
    if request.param == "synthetic":
        return clean_synthetic
    return read_utfsm(shared_dir / UTFSM / "25mm0x5Hz1A.txt")


def _span(test, start=0.45, length=0.06):
    n = test.n_samples
    a = int(start * n)
    return a, a + max(int(length * n), 30)


def test_stuck_force_is_found_and_only_its_samples_excluded(base_test):
    a, b = _span(base_test)
    f = base_test.force.copy()
    f[a:b] = f[a]
    scr = screen(_with(base_test, force=f))
    hit = _flagged_span(scr, "stuck", "force")[0]
    assert hit.n_samples >= b - a - 1
    assert not scr.usable[a + 1:b].any()
    assert scr.usable[:a].all() and scr.usable[b + 1:].all()  # the force alone: no settling


def test_clipped_force_is_found(base_test):
    f = base_test.force.copy()
    level = 0.8 * f.max()
    clipped = f >= level
    f[clipped] = level
    scr = screen(_with(base_test, force=f))
    hits = _flagged_span(scr, "clipped", "force")
    assert sum(h.n_samples for h in hits) == clipped.sum()
    assert not scr.usable[clipped].any()


def test_frozen_displacement_is_found_with_settling(base_test):
    a, b = _span(base_test)
    x = base_test.displacement.copy()
    x[a:b] = x[a]
    scr = screen(_with(base_test, displacement=x))
    assert _kinds(scr, "displacement") & {"frozen", "stuck"}
    assert not scr.usable[a + 1:b].any()
    # the model's state after an unknown motion: excluded up to the next reversal
    assert "settling" in _kinds(scr)
    assert not scr.usable[b:b + 3].any()


def test_gap_is_found(base_test):
    n = base_test.n_samples
    keep = np.ones(n, bool)
    keep[n // 2: n // 2 + 40] = False
    test = DamperTest(base_test.time[keep], base_test.displacement[keep], base_test.velocity[keep],
                      base_test.force[keep], current=None if base_test.current is None else base_test.current[keep],
                      voltage=None if base_test.voltage is None else base_test.voltage[keep])
    scr = screen(test)
    gap = _flagged_span(scr, "gap", "time")[0]
    assert gap.t_start == pytest.approx(base_test.time[n // 2 - 1])
    assert not scr.usable[n // 2]


def test_idle_span_is_found(clean_synthetic):
    # the rig waits: 2 s at rest between two runs (the displacement sensor's noise 10 um)
    t = np.arange(0.0, 8.0, 2e-3)
    x = np.where(t < 3, 0.02 * np.sin(2 * np.pi * t), 0.0)
    x = np.where(t >= 5, 0.02 * np.sin(2 * np.pi * (t - 5)), x)
    x = x + 1e-5 * np.random.default_rng(4).standard_normal(t.size)
    test = general_test("virtual", t, x, 0.0, noise=0.02, seed=2)
    scr = screen(test)
    idle = _flagged_span(scr, "idle", "displacement")
    # the force relaxes for a while after the stop (the device's own dynamics): idle once at rest
    assert any(f.t_start <= 4.0 and f.t_end >= 4.9 for f in idle), scr.lines()
    assert not scr.usable[(t > 4.0) & (t < 4.9)].any()
    assert scr.usable[t < 2.5].all()
    assert "frozen" not in _kinds(scr)


def test_a_rest_at_a_reversal_with_the_sensor_exactly_still_is_idle_not_frozen():
    # the stroke held exactly (a digital sensor at rest) from a reversal on, for 1 s: the force
    # relaxes to rest first; that stretch was reported as a frozen displacement as well as idle
    # (larger strokes before and after, so that the rest is not at the stroke's end, a clipping
    # level; stamps half a step off the sine's peaks)
    t = np.arange(0.001, 6.0, 1e-3)
    t_rest = 6.25 / 3.0  # a crest of the 3-Hz stroke
    x = np.where(t < 1.0, 0.03 * np.sin(6 * np.pi * t), 0.02 * np.sin(6 * np.pi * t))
    x = np.where((t >= t_rest) & (t < t_rest + 1.0), 0.02, x)
    x = np.where(t >= t_rest + 1.0, 0.02 * np.sin(6 * np.pi * (t - 1.0)), x)
    x = np.where(t >= 4.0, 0.03 * np.sin(6 * np.pi * (t - 1.0)), x)
    test = general_test("virtual", t, x, 0.0, noise=0.02, seed=2)
    rest = (t >= t_rest) & (t < t_rest + 1.0)
    k = np.searchsorted(t, t_rest)
    x_read = test.displacement.copy()
    x_read[rest] = x_read[k]
    # a device whose force relaxes within 10 ms once the stroke stops (a probe's UTFSM copy)
    f = test.force.copy()
    f[rest] = f[k - 1] * np.exp(-(t[rest] - t[k - 1]) / 0.01) + np.random.default_rng(5).normal(
        0.0, 0.002 * np.ptp(f), rest.sum())
    scr = screen(_with(test, displacement=x_read, force=f))
    idle = _flagged_span(scr, "idle", "displacement")
    assert any(f.t_start <= t_rest + 0.002 and f.t_end >= t_rest + 0.99 for f in idle), scr.lines()
    assert "frozen" not in _kinds(scr), scr.lines()


def test_velocity_gain_and_offset_are_found(base_test):
    scr = screen(_with(base_test, velocity=base_test.velocity * 1000.0))
    assert "velocity" in _kinds(scr, "velocity")
    lag = 6
    v = np.r_[np.full(lag, base_test.velocity[0]), base_test.velocity[:-lag]]
    scr = screen(_with(base_test, velocity=v))
    dt = float(np.median(np.diff(base_test.time)))
    assert "offset" in _kinds(scr, "velocity"), scr.lines()
    assert scr.estimates["velocity_lag_s"] == pytest.approx(lag * dt, abs=1.5 * dt)
    assert "force_velocity_lag_s" in screen(base_test).estimates


def test_implausible_units_are_reported(base_test):
    scr = screen(_with(base_test, displacement=base_test.displacement * 1000.0,
                       velocity=base_test.velocity * 1000.0))
    units = [f for f in scr.findings if f.kind == "units"]
    assert {f.channel for f in units} >= {"amplitude", "velocity"}, scr.lines()
    assert all(not f.excluded for f in units)


# --------------------------------------------------------------------------------------------
# readers: NaN, repeated and backward time stamps
# --------------------------------------------------------------------------------------------
def _csv_lines(test, path):
    write_csv(test, path)
    return path.read_text().splitlines()


def test_csv_reader_fills_and_flags_nan_and_drops_bad_time(tmp_path, clean_synthetic):
    lines = _csv_lines(clean_synthetic, tmp_path / "c.csv")
    header = next(i for i, ln in enumerate(lines) if ln.startswith("time"))
    cols = lines[header].split(",")
    rows = [ln.split(",") for ln in lines[header + 1:]]
    n = len(rows)
    names = [c.split("[")[0].strip() for c in cols]  # the header names each column with its unit
    i_force, i_disp = names.index("force"), names.index("displacement")
    for k in range(n // 3, n // 3 + 5):
        rows[k][i_force] = "nan"
    rows[2 * n // 3][i_disp] = "nan"
    again = list(rows[n // 2 - 1])
    again[i_force] = repr(float(again[i_force]) + 50.0)
    rows.insert(n // 2, again)                            # a repeated time stamp, another reading
    back = list(rows[n // 4])
    back[i_force] = repr(float(back[i_force]) - 50.0)
    rows.insert(n // 4 + 10, back)                        # a time going backwards
    path = tmp_path / "dirty.csv"
    path.write_text("\n".join(lines[:header + 1] + [",".join(r) for r in rows]) + "\n")
    test = read_csv(path)
    assert test.n_samples == n
    assert np.all(np.diff(test.time) > 0) and np.all(np.isfinite(test.force))
    scr = test.metadata["screening"]
    nan = [f for f in scr.findings if f.kind == "nan"]
    assert {f.channel for f in nan} == {"force", "displacement"}
    assert sum(f.n_samples for f in nan if f.channel == "force") == 5
    assert sum(f.n_samples for f in scr.findings if f.kind == "time") == 2
    assert not test.mask[n // 3:n // 3 + 5].any()
    # the displacement dropout is interpolated (the model is driven through it) and excluded,
    # with the settling after it
    k = 2 * n // 3
    assert test.displacement[k] == pytest.approx(0.5 * (test.displacement[k - 1] + test.displacement[k + 1]),
                                                 rel=0.05, abs=1e-5)
    assert not test.mask[k] and "settling" in _kinds(scr)


def test_exact_copies_of_rows_are_dropped_and_nothing_is_excluded(tmp_path, clean_synthetic):
    """A logger that writes a row twice, or a block again after a restart, loses nothing: the
    copies are one finding, reported only; no sample is excluded and no settling follows (a
    review found three copied rows made a clean file unusable)."""
    lines = _csv_lines(clean_synthetic, tmp_path / "c.csv")
    header = next(i for i, ln in enumerate(lines) if ln.startswith("time"))
    rows = lines[header + 1:]
    n = len(rows)
    dirty = list(rows)
    for k in (n - 5, n // 2, 0):                          # rows written twice (from the end: indices hold)
        dirty.insert(k + 1, rows[k])
    block = rows[n // 3 - 40:n // 3]                      # a block written again
    dirty[n // 3 + 2:n // 3 + 2] = block
    path = tmp_path / "copies.csv"
    path.write_text("\n".join(lines[:header + 1] + dirty) + "\n")
    test = read_csv(path)
    scr = test.metadata["screening"]
    dup = [f for f in scr.findings if f.kind == "duplicate"]
    assert len(dup) == 1 and dup[0].n_samples == 43 and not dup[0].excluded
    assert "time" not in _kinds(scr) and "settling" not in _kinds(scr)
    assert test.n_samples == n and test.usable.all()
    np.testing.assert_array_equal(test.force, read_csv(tmp_path / "c.csv").force)


def test_too_little_left_is_a_one_line_error(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("time,displacement,force\n" + "\n".join(f"{i * 0.01},nan,{i}" for i in range(20)) + "\n")
    with pytest.raises(InputError, match=r"bad.csv:2: column 'displacement'"):
        read_csv(path)


def test_repair_samples_names_the_line():
    t = np.array([0.0, 0.1, 0.05])
    with pytest.raises(InputError, match=r"f.csv:4: column 'time': expected strictly increasing"):
        repair_samples(t, {"force": np.ones(3)}, label="f.csv", lines=[2, 3, 4])


# --------------------------------------------------------------------------------------------
# exclusion: the error, the loop's data and the identification honour the mask
# --------------------------------------------------------------------------------------------
def test_one_relative_rms_error_with_mask():
    assert selection_rms is relative_rms_error
    f = np.array([1.0, 2.0, 3.0, 100.0])
    g = np.array([1.0, 2.0, 3.0, 0.0])
    assert relative_rms_error(f, g, mask=np.array([True, True, True, False])) == 0.0
    assert relative_rms_error(f, g) > 0.9
    assert relative_rms_error(f, g, weights=np.array([1.0, 1.0, 1.0, 0.0])) == 0.0
    with pytest.raises(InputError, match="identically zero"):
        relative_rms_error(np.zeros(3), np.ones(3))


def test_diagnosis_data_leaves_flagged_samples_out(clean_synthetic):
    f = clean_synthetic.force.copy()
    n = f.size
    f[int(0.8 * n):int(0.85 * n)] = f[int(0.8 * n)]        # stuck, in the held-out part
    f[int(0.3 * n):int(0.35 * n)] = f[int(0.3 * n)]        # stuck, in the training part
    test = screened(_with(clean_synthetic, force=f))
    assert test.mask is not None
    data = DiagnosisData.from_tests([test], holdout=0.25)
    bad = ~test.mask
    assert not (data.train[0] & bad).any() and not (data.heldout[0] & bad).any()
    plain = DiagnosisData.from_tests([keep_flagged(test)], holdout=0.25)
    assert (plain.heldout[0] & bad).any() and (plain.train[0] & bad).any()
    # the split in time is unchanged
    assert np.flatnonzero(data.heldout[0])[0] >= np.flatnonzero(plain.heldout[0])[0]


def test_a_flagged_tail_does_not_take_the_place_of_held_out_data(clean_synthetic):
    """A test whose last fifth is flagged (a rig at rest after the test, a corrupted end: the
    Dyke recordings have both) holds out the last quarter of the data before that tail, not the
    last quarter of the file, which would leave only a twentieth of the test held out."""
    n = clean_synthetic.time.size
    mask = np.ones(n, dtype=bool)
    mask[int(0.8 * n):] = False
    test = dataclasses.replace(clean_synthetic, mask=mask)
    data = DiagnosisData.from_tests([test], holdout=0.25)
    used = data.train[0] | data.heldout[0]
    assert not used[int(0.8 * n):].any()
    share = data.heldout[0].sum() / used.sum()
    assert share == pytest.approx(0.25, abs=0.01)
    first_held = np.flatnonzero(data.heldout[0])[0]
    assert np.flatnonzero(data.train[0])[-1] == first_held - 1  # one cut, in time
    # a tail that leaves nothing to fit says so in one line
    mask[5:] = False
    with pytest.raises(InputError, match="before the flagged tail"):
        DiagnosisData.from_tests([dataclasses.replace(clean_synthetic, mask=mask)], holdout=0.25)


def test_acceleration_window_does_not_reach_into_flagged_samples(clean_synthetic):
    """A velocity spike over a flagged span (a dropout the screening found) enters the
    Savitzky-Golay acceleration of its neighbours: samples within half a window of it count
    neither in the fit nor in the error, so no usable sample's acceleration saw the spike."""
    from damper.diagnosis.dataset import acceleration_from_velocity, acceleration_window
    t, x = clean_synthetic.time, clean_synthetic.displacement
    v = clean_synthetic.velocity.copy()
    n = t.size
    span = slice(int(0.5 * n), int(0.5 * n) + 4)
    mask = np.ones(n, dtype=bool)
    mask[span] = False
    test = dataclasses.replace(clean_synthetic, mask=mask)
    data = DiagnosisData.from_tests([test], holdout=0.25)
    window = acceleration_window(t, v, x)
    assert window >= 5
    spiked = v.copy()
    spiked[span] += 50.0 * np.ptp(v)
    # the derivative of the spike alone, over the window the test's acceleration used (the
    # spiked channel would change the band edge and so the window)
    from scipy.signal import savgol_filter
    leak = np.abs(savgol_filter(spiked - v, window, 2, deriv=1, delta=t[1] - t[0], mode="interp"))
    assert np.allclose(data.motions[0].xddot, acceleration_from_velocity(t, v, x))
    used = data.train[0] | data.heldout[0]
    reached = leak > 1e-9 * leak.max()
    assert reached.sum() > span.stop - span.start            # the window does reach out
    assert not (used & reached).any()
    # and no more is lost than the window's reach each side
    assert used[span.start - window // 2 - 1] and used[span.stop + window // 2]


@pytest.mark.slow
def test_identification_ignores_flagged_samples():
    from damper.identification.identify import identify

    clean = periodic_test("virtual", 0.03, 1.0, 0.5, cycles=5, sample_rate=400.0, noise=0.01, seed=8)
    f = clean.force.copy()
    n = f.size
    f[int(0.55 * n):int(0.65 * n)] = 3.0 * f.max()           # a stuck, saturated span
    dirty = screened(_with(clean, force=f))
    assert dirty.mask is not None and not dirty.mask[int(0.56 * n)]
    ref = identify(clean, model="normalized", n_bootstrap=0)
    masked = identify(dirty, model="normalized", n_bootstrap=0)
    assert masked.errors["rel_rms_error"] < 1.2 * ref.errors["rel_rms_error"]
    for k in ("kappa_w", "kappa_xdot", "rho"):
        assert masked.parameters[k] == pytest.approx(ref.parameters[k], rel=0.02)
    # kept in, the saturated span spoils the identification (today's behaviour on such data)
    try:
        scored = identify(keep_flagged(dirty), model="normalized", n_bootstrap=0)
    except InputError:
        return  # the corrupted cycle breaks the closed form
    assert scored.errors["rel_rms_error"] > 3 * masked.errors["rel_rms_error"]


def test_raw_utfsm_files_show_the_idle_spans_between_currents(shared_dir):
    """Each raw logger export holds five currents back to back: the screening finds the idle
    spans between them (true findings) and nothing else."""
    from damper.io.data import read_utfsm_raw

    files = sorted((shared_dir / "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Datos_crudos").glob("ME*.txt"))
    assert len(files) == 6
    for path in files:
        test = read_utfsm_raw(path)
        scr = test.metadata["screening"]
        idle = [f for f in scr.findings if f.kind == "idle"]
        assert len(idle) >= 4, scr.lines()          # at least the four gaps between five runs
        assert _kinds(scr) == {"idle"}, scr.lines()
        assert not test.mask[(test.time > idle[1].t_start + 0.1) & (test.time < idle[1].t_end - 0.1)].any()
        assert 0.001 < 0.5 * np.ptp(test.displacement) < 0.03      # the 2-25 mm tests, in metres


def _random_test(seed=7, duration=8.0, rate=1000.0):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, 1.0 / rate)
    x = 0.01 * np.convolve(rng.standard_normal(t.size), np.hanning(301) / 150, mode="same")
    v = 0.3 + 0.7 * (np.sin(2 * np.pi * 0.5 * t) > 0)
    return general_test("virtual", t, x, v, noise=0.01, seed=seed)


def _lurch(test, at, freeze):
    """The rig lurches at ``at`` [fraction of the test] by 1.5 strokes in 40 ms (several times the
    test's fastest motion) and comes back as fast; with ``freeze`` it stays there instead, the
    displacement and the force frozen (a rig that lost control)."""
    t, x, v, f = test.time, test.displacement.copy(), test.velocity.copy(), test.force.copy()
    a, w = int(at * t.size), 40
    jump = 1.5 * np.ptp(x)
    phase = np.pi * np.arange(w) / w
    h = t[1] - t[0]
    up, dup = 0.5 - 0.5 * np.cos(phase), 0.5 * np.pi / (w * h) * np.sin(phase)
    if freeze:
        x[a:a + w] += jump * up
        v[a:a + w] += jump * dup
        x[a + w:], v[a + w:], f[a + w:] = x[a + w - 1], 0.0, f[a + w - 1]
    else:
        x[a:a + w] += jump * up
        v[a:a + w] += jump * dup
        x[a + w:a + 2 * w] += jump * up[::-1]
        v[a + w:a + 2 * w] -= jump * dup
    return _with(test, displacement=x, velocity=v, force=f), a


def test_a_lurch_before_a_freeze_is_excluded_from_its_start():
    test, a = _lurch(_random_test(), 0.8, freeze=True)
    scr = screen(test)
    hits = _flagged_span(scr, "excursion", "velocity")
    assert min(h.t_start for h in hits) <= test.time[a + 5]
    assert not scr.usable[a + 5:].any()
    assert scr.usable[: a - 200].all()


def test_a_fast_stretch_far_from_any_fault_is_data():
    test, a = _lurch(_random_test(seed=8), 0.3, freeze=False)
    scr = screen(test)
    assert "excursion" not in _kinds(scr), scr.lines()


# --------------------------------------------------------------------------------------------
# time stamps written with too few digits (the Dyke files: 0.1-ms stamps, a 0.333-ms step)
# --------------------------------------------------------------------------------------------
def _grid(n=9000, rate=3004.8):
    return np.arange(n) / rate


def test_rounded_time_stamps_are_restored_to_their_grid():
    from damper.io.screening import rounded_time_grid
    true = _grid()
    stamps = np.round(true, 4)  # steps of 0.3 and 0.4 ms on a 0.3328-ms grid
    found = rounded_time_grid(stamps)
    assert found is not None
    grid, q, largest = found
    assert q == pytest.approx(1e-4)
    # the least-squares line through n stamps rounded to q is off by ~q/sqrt(n): far below q
    assert np.max(np.abs(grid - true)) < 0.02 * q
    assert 0.4 * q < largest <= 0.5 * q + 1e-12
    # written with five significant digits (MATLAB's num2str: 0.00033280, 0.33280, 1.6633), so
    # the stamps of a 3-s excerpt have four to nine decimals
    short = true[:9000]
    sig = np.array([float(f"{x:.5g}") for x in short])
    found = rounded_time_grid(sig)
    assert found is not None and found[1] == pytest.approx(1e-4)
    assert np.max(np.abs(found[0] - short)) < 0.02 * q
    late = rounded_time_grid(np.round(1000.0 + true, 4))  # a clock that started long before
    assert late is not None and late[1] == pytest.approx(1e-4)
    assert np.max(np.abs(late[0] - 1000.0 - true)) < 0.02 * q
    t, _, excluded, findings = repair_samples(stamps, {"force": np.ones(stamps.size)}, label="r.csv")
    assert np.ptp(np.diff(t)) < 1e-12 and not excluded.any()
    (f,) = findings
    assert f.kind == "rounded" and f.channel == "time" and not f.excluded and "3004.8 Hz" in f.message


@pytest.mark.parametrize("stamps", [
    _grid(),                                                              # written with every digit
    _grid() + np.random.default_rng(0).normal(0.0, 0.1 / 3004.8, 9000),   # real jitter, unrounded
    np.round(_grid() + np.random.default_rng(1).uniform(-0.3, 0.3, 9000) / 3004.8, 4),  # jitter beyond the rounding
    np.round(_grid(rate=1.0e3), 3),                                       # rounded, but the step is a multiple of q
    1000.0 + np.round(_grid() + np.random.default_rng(2).uniform(-0.3, 0.3, 9000) / 3004.8, 4),  # the same, late
    np.delete(np.round(_grid() + np.random.default_rng(3).uniform(-0.3, 0.3, 9000) / 3004.8, 4), 4000),  # and a row lost
])
def test_stamps_that_are_not_a_rounded_grid_are_left_alone(stamps):
    from damper.io.screening import rounded_time_grid
    stamps = np.sort(stamps)
    assert rounded_time_grid(stamps) is None
    t, _, _, findings = repair_samples(stamps, {"force": np.ones(stamps.size)})
    assert not [f for f in findings if f.kind == "rounded"]
    np.testing.assert_array_equal(t, stamps)


def test_a_lost_sample_on_a_grid_as_coarse_as_its_stamps_is_not_rounding():
    # 1 kHz stamps written in ms, one row deleted mid-test: the least-squares line is off by half
    # a step on both sides, like a 999.8-Hz grid rounded to ms; the displacement moves twice as
    # far across the long step, so the stamps are not re-timed (they had been by 0.52 ms): the
    # lost slot is put back on the 1-ms grid instead
    from damper.io.screening import lost_slots, rounded_time_grid
    full = np.round(np.arange(4308) / 1e3, 3)
    x_full = 0.005 * np.sin(2 * np.pi * 3.0 * full)
    t, x = np.delete(full, 2000), np.delete(x_full, 2000)
    assert rounded_time_grid(t) is not None  # the stamps alone cannot tell
    assert rounded_time_grid(t, x) is None
    assert lost_slots(t) is None  # as coarse as a step: not without the displacement's word
    kept, channels, excluded, findings = repair_samples(t, {"displacement": x, "force": np.ones(t.size)})
    assert not [f for f in findings if f.kind == "rounded"]
    np.testing.assert_allclose(kept, full, rtol=0, atol=1e-9)
    (lost,) = [f for f in findings if f.kind == "lost"]
    assert lost.n_samples == 1 and lost.t_start == pytest.approx(2.0) and lost.excluded
    assert np.flatnonzero(excluded).tolist() == [2000]
    # interpolated through the slot: a sine's chord over 2 ms, off the true value by ~x (w dt)^2 / 2
    assert abs(channels["displacement"][2000] - x_full[2000]) < 1e-6
    # a grid that is rounded indeed (steps of 1 and 2 ms on 1.5 ms) keeps its finding with x
    true = np.arange(3000) * 1.5e-3
    assert rounded_time_grid(np.round(true, 3), 0.005 * np.sin(2 * np.pi * 3.0 * true)) is not None


@pytest.mark.parametrize("rounded", [True, False])
def test_a_lost_sample_is_put_back_on_the_grid(rounded):
    """One or two rows missing from a uniform grid (a logger's lost sample period): left as read,
    the double step spread the steps, the rounded stamps were not restored and the screening's
    derivative, taken on the median step (0.3 ms on the 0.333-ms grid), put the velocity's gain
    at 0.95. The slots are put back, interpolated and excluded, and the grid restored."""
    from damper.io.screening import velocity_scale
    true = _grid(12000)
    x_true = 0.004 * np.sin(2 * np.pi * 1.7 * true) + 0.001 * np.sin(2 * np.pi * 11.0 * true)
    v_true = np.gradient(x_true, true)
    lost_at = [3000, 7001]
    t = np.delete(np.round(true, 4) if rounded else true, lost_at)
    x, v = np.delete(x_true, lost_at), np.delete(v_true, lost_at)
    f = np.delete(300.0 * np.tanh(v_true / 0.02), lost_at)
    kept, channels, excluded, findings = repair_samples(t, {"displacement": x, "velocity": v, "force": f},
                                                        label="r.csv", lines=list(range(2, t.size + 2)))
    # the least-squares line through n stamps rounded to q is off by ~q/sqrt(n): far below q
    np.testing.assert_allclose(kept, true, rtol=0, atol=0.02e-4 if rounded else 1e-12)
    lost = [fd for fd in findings if fd.kind == "lost"]
    assert [fd.n_samples for fd in lost] == [1, 1] and all(fd.excluded for fd in lost)
    assert "r.csv:3002" in lost[0].message  # the file line after the lost slot
    assert np.flatnonzero(excluded).tolist() == lost_at
    assert bool([fd for fd in findings if fd.kind == "rounded"]) == rounded
    assert not [fd for fd in findings if fd.kind == "nan"]  # the slots are the lost finding's
    for name, truth in (("displacement", x_true), ("velocity", v_true)):
        assert np.all(np.isfinite(channels[name]))
        np.testing.assert_allclose(channels[name][lost_at], truth[lost_at], atol=0.01 * np.ptp(truth))
    assert velocity_scale(kept, channels["displacement"], channels["velocity"], ~excluded) == pytest.approx(1.0, abs=0.01)
    # screened as a test: the slots are interpolated readings, no fault of the rig: nothing settles after them
    test = screened(DamperTest(kept, channels["displacement"], channels["velocity"], channels["force"],
                               mask=~excluded, name="r"), prior=findings, prior_excluded=excluded)
    result = test.metadata["screening"]
    assert not [fd for fd in result.findings if fd.kind in ("settling", "gap", "velocity")]
    assert int((~result.usable).sum()) == 2


def test_a_derivative_over_uneven_stamps_takes_the_mean_step():
    """Stamps rounded to 0.1 ms that no single grid explains (a file spliced from two, its second
    half 0.02 ms off) stay as read; their steps of 0.3 and 0.4 ms on a 0.333-ms grid have a
    median of 0.3 ms, which had put the velocity's gain against d(x)/dt at 0.90 (a "unit or gain
    error", and a good velocity column replaced). The mean step gives 1."""
    from damper.io.screening import lost_slots, rounded_time_grid, velocity_scale
    true = _grid(12000)
    stamps = np.round(true, 4) + np.where(np.arange(true.size) >= 6000, 2e-5, 0.0)
    assert rounded_time_grid(stamps) is None and lost_slots(stamps) is None
    x = 0.004 * np.sin(2 * np.pi * 1.7 * true) + 0.001 * np.sin(2 * np.pi * 11.0 * true)
    v = np.gradient(x, true)
    assert velocity_scale(stamps, x, v) == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("clock", [np.floor, np.round])
def test_a_clock_coarser_than_the_sampling_keeps_every_row(clock):
    """3 kHz written with a 1-ms clock (truncated or rounded): each stamp two or three times. The
    repeated stamps had been dropped as glitches (two thirds of the test, the rest stamped up to
    a tick early); now the uniform grid is restored and every row kept."""
    from damper.io.screening import coarse_time_grid
    true = _grid(9000)
    stamps = clock(true * 1e3) / 1e3
    x = 0.004 * np.sin(2 * np.pi * 1.7 * true)
    f = 300.0 * np.cos(2 * np.pi * 1.7 * true)
    grid, q, repeats = coarse_time_grid(stamps, {"displacement": x, "force": f})
    assert q == pytest.approx(1e-3) and repeats > 5000
    # the least-squares slope through n stamps off by up to q/2 is off by ~q sqrt(12) / n^1.5
    # (1.2e-9 s, 4e-6 of the step, at n = 9000); anchored at the first stamp, a truncating
    # clock's grid is the true one, a rounding clock's within half a tick of it
    np.testing.assert_allclose(np.diff(grid), 1.0 / 3004.8, rtol=2e-5)
    assert np.max(np.abs(grid - true)) < 0.5e-3 + 1e-9
    t, channels, excluded, findings = repair_samples(stamps, {"displacement": x, "force": f}, label="ms.csv")
    assert t.size == 9000 and not excluded.any()
    assert [fd.kind for fd in findings] == ["rounded"] and "every row kept" in findings[0].message
    np.testing.assert_array_equal(channels["force"], f)


@pytest.mark.parametrize("rate", [1024.0, 1200.0, 3004.8, 20000.0])
def test_a_coarse_clock_with_a_missing_stamp_and_rows_at_rest_keeps_every_row(rate):
    """A review's cases: a 1-ms clock at 1024 Hz repeats 2.4 % of its stamps, at 1200 Hz 17 %
    (the share 1 - dt/q such a clock gives, not a fixed one); a missing stamp (NaN) gets its
    slot's time; a test at rest for its first 50 ms (rows equal to the one before: a tenth of
    the rows at 20 kHz) and a held reading are no double writes."""
    from damper.io.screening import coarse_time_grid
    n = 9000
    true = np.arange(n) / rate
    stamps = np.floor(true * 1e3 + 1e-9) / 1e3  # a tick counter's truncation (no float rounding below a tick)
    stamps[4000] = np.nan
    x = np.where(true < 0.05, 0.0, 0.004 * np.sin(2 * np.pi * 1.7 * (true - 0.05)))
    f = np.where(true < 0.05, 0.0, 300.0 * np.cos(2 * np.pi * 1.7 * (true - 0.05)))
    x[6001], f[6001] = x[6000], f[6000]  # a held reading
    grid, q, _ = coarse_time_grid(stamps, {"displacement": x, "force": f})
    assert q == pytest.approx(1e-3)
    # the least-squares slope is off by ~q sqrt(12) / n^1.5: the grid within 5 % of a step at its end
    np.testing.assert_allclose(grid, true, rtol=0, atol=0.05 / rate)
    t, _, _, findings = repair_samples(stamps, {"displacement": x, "force": f})
    assert t.size == n and not [fd for fd in findings if fd.kind == "time"]


def test_repeated_stamps_that_are_no_coarse_clock_are_still_dropped():
    from damper.io.screening import coarse_time_grid
    true = _grid(9000)
    x = 0.004 * np.sin(2 * np.pi * 1.7 * true)
    glitches = true.copy()
    glitches[100:160:3] = glitches[99:159:3]  # 20 repeats among 9000 steps: a logger's glitches
    assert coarse_time_grid(glitches, {"displacement": x}) is None
    t, _, excluded, findings = repair_samples(glitches, {"displacement": x})
    # the rows of the repeated stamps dropped, their slots put back as lost samples (interpolated)
    assert sum(fd.n_samples for fd in findings if fd.kind == "time") == 20
    assert sum(fd.n_samples for fd in findings if fd.kind == "lost") == 20
    assert t.size == 9000 and int(excluded.sum()) == 20
    coarse = np.floor(true * 1e3) / 1e3
    doubled = np.repeat(x, 2)[:9000]  # every row written twice: copies, not samples
    assert coarse_time_grid(coarse, {"displacement": doubled}) is None
    backwards = coarse.copy()
    backwards[5000] -= 0.002
    assert coarse_time_grid(backwards, {"displacement": x}) is None
    assert coarse_time_grid(np.round(true, 4), {"displacement": x}) is None  # finer than a step: no repeats


def test_irregular_or_holed_stamps_get_no_lost_slots():
    from damper.io.screening import lost_slots
    true = _grid(6000)
    rng = np.random.default_rng(4)
    assert lost_slots(np.delete(true, [100, 101])) is None        # two in a row: a gap, not a lost sample
    assert lost_slots(np.delete(true, rng.choice(5990, 120, replace=False) + 5)) is None  # 2 %: irregular
    jitter = np.delete(true + rng.normal(0.0, 0.05 / 3004.8, true.size), 3000)
    assert lost_slots(jitter) is None                             # a clock's jitter is not a grid
    assert lost_slots(true) is None                               # nothing lost


def test_dyke_time_stamps_are_rounded_and_restored(shared_dir):
    test = read_dyke(shared_dir / DYKE)
    rounded = [f for f in test.metadata["screening"].findings if f.kind == "rounded"]
    assert len(rounded) == 1 and not rounded[0].excluded
    assert np.ptp(np.diff(test.time)) < 1e-12 * test.time[-1]
    assert 1.0 / np.mean(np.diff(test.time)) == pytest.approx(3004.8, rel=1e-6)  # the file's fs column
    # the velocity channel against d(x)/dt over the restored grid: gain 1 within 1 % (0.96 over
    # the rounded stamps' jittered steps)
    assert test.metadata["screening"].estimates["velocity_gain"] == pytest.approx(1.0, abs=0.01)


def test_acceleration_of_a_broadband_motion_keeps_its_band():
    """A random motion with its largest peak at 1 Hz and velocity up to 50 Hz (the Dyke
    recordings'): the Savitzky-Golay window follows the velocity's band edge, not the dominant
    period (whose twentieth, 50 ms, would halve the acceleration at 20 Hz)."""
    from damper.diagnosis.dataset import acceleration_from_velocity
    rate = 3000.0
    t = np.arange(int(6 * rate)) / rate
    rng = np.random.default_rng(3)
    freqs = np.r_[1.0, rng.uniform(2.0, 50.0, 40)]
    amps = np.r_[5e-3, np.full(40, 2e-4)]
    phases = rng.uniform(0, 2 * np.pi, freqs.size)
    arg = 2 * np.pi * np.outer(t, freqs) + phases
    x = (np.sin(arg) * amps).sum(axis=1)
    v = (np.cos(arg) * amps * 2 * np.pi * freqs).sum(axis=1)
    a = (-np.sin(arg) * amps * (2 * np.pi * freqs) ** 2).sum(axis=1)
    got = acceleration_from_velocity(t, v, x)
    inner = slice(300, -300)
    assert relative_rms_error(a[inner], got[inner]) < 0.02
    # a periodic motion keeps the dominant period's window (the UTFSM tests): the quadratic
    # Savitzky-Golay slope over a twentieth of the period lowers the amplitude by ~0.25 %
    xs = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    vs = 0.01 * 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t)
    as_ = -0.01 * (2 * np.pi * 2.0) ** 2 * np.sin(2 * np.pi * 2.0 * t)
    assert relative_rms_error(as_[inner], acceleration_from_velocity(t, vs, xs)[inner]) < 5e-3


def test_one_smoothed_derivative_serves_the_screening_and_the_diagnosis():
    """The screening's d(x)/dt and the diagnosis's acceleration are one Savitzky-Golay derivative
    (damper/io/screening.py ``derivative_window``, ``smoothed_derivative``) with their own share
    of the period: order 2 is exact on a parabola (to rounding), the band edge shortens the
    window, and a ragged or short grid falls back to numpy.gradient."""
    from damper.diagnosis.dataset import acceleration_window
    from damper.io.screening import derivative_window, smoothed_derivative
    t = np.linspace(0.0, 1.0, 1001)  # dt = 1 ms
    y = 3.0 * t**2 - 2.0 * t + 1.0
    assert derivative_window(t, 1.0, per_period=20.0) == 51     # 50 ms, made odd
    assert derivative_window(t, 1.0) == 25                      # the screening's 1/40
    assert derivative_window(t, 1.0, edge=10.0, per_period=20.0) == 11  # 2/edge = 0.2 s is shorter
    assert derivative_window(t, np.inf) == 5 and derivative_window(t[:6], 1.0) == 0
    for window in (51, 25, 0):
        # the fallback is second order too: exact on a parabola
        assert np.allclose(smoothed_derivative(t, y, window), 6.0 * t - 2.0, rtol=0.0, atol=1e-9)
    ragged = t + np.where(np.arange(t.size) % 2 == 1, 0.3e-3, 0.0)  # steps of 1.3 and 0.7 ms
    assert derivative_window(ragged, 1.0) == 0 and derivative_window(ragged, 1.0, jitter=1.0) == 25
    # the diagnosis's window: a twentieth of the displacement's period, on a uniform grid only
    x = np.sin(2.0 * np.pi * 2.0 * t)
    assert acceleration_window(t, np.gradient(x, t), x) == derivative_window(t, 0.5, 2.0, per_period=20.0)
    assert acceleration_window(ragged, np.gradient(x, ragged), x) == 0


def test_a_measured_current_that_wanders_around_its_level_reads_as_that_level():
    # a probe (2026-11-28): 1 A measured with 0.5 % noise, or in 1-mA converter steps, made the
    # Spencer base fit voltage laws on nodes 0.999 and 1.001 A (0.105 where 1 A gives 0.078)
    from damper.io.screening import STEADY_FLOOR, repair_samples, steady_level
    rng = np.random.default_rng(3)
    t = np.arange(2000) * 1e-3
    x = 0.005 * np.sin(2 * np.pi * 3 * t)
    noisy = 1.0 + 0.005 * rng.standard_normal(t.size)
    _, out, _, findings = repair_samples(t, {"displacement": x, "current": noisy, "force": 1e3 * np.cos(6 * np.pi * t)})
    assert np.all(out["current"] == out["current"][0]) and abs(out["current"][0] - 1.0) < 1e-3
    assert [f.kind for f in findings] == ["steady"] and "read as the constant" in findings[0].message
    assert steady_level(np.round(noisy, 3)) is not None  # a converter's 1-mA steps
    assert steady_level(np.full(10, 0.0) + 0.5 * STEADY_FLOOR) is not None  # a sensor's offset near 0 A
    # a command that changes within the test is not a level
    assert steady_level(np.where(t < 1.0, 0.0, 1.0)) is None
    assert steady_level(1.0 + 0.1 * np.sin(t)) is None


def test_a_force_that_follows_the_velocity_exactly_is_named():
    # a probe (2026-11-28): a headerless file in another column order had its velocity fitted
    # as force (held-out error 0.0025, nothing said)
    from damper.io.screening import screen
    from damper.io.data import DamperTest
    t = np.arange(4000) * 1e-3
    x = 0.005 * np.sin(2 * np.pi * 3 * t)
    v = 0.005 * 2 * np.pi * 3 * np.cos(2 * np.pi * 3 * t)
    as_velocity = screen(DamperTest(t, x, v, 1e3 * v, current=np.ones(t.size)))
    assert any(f.kind == "velocity_like" for f in as_velocity.findings)
    damper = screen(DamperTest(t, x, v, 500.0 * np.tanh(v / 0.01) + 2000.0 * v, current=np.ones(t.size)))
    assert not any(f.kind == "velocity_like" for f in damper.findings)
