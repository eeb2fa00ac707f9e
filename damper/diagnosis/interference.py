"""Mains interference in the force channel: narrow spectral lines of the final residual.

A load cell's amplifier picks up the mains (a ground loop, an unshielded cable): the force
channel then carries a sinusoid at 50 or 60 Hz (and its harmonics) that no motion of the damper
drives. The screening cannot see it in the force itself (a broadband test, such as the Dyke
recordings up to 50 Hz, has motion there), and the residual trace
(:mod:`damper.diagnosis.trace`) finds no variable of the motion that holds it: it said
"unlocated", and a probe's UTFSM tests with a 40-N, 50-Hz hum (28 N RMS, 2.4 % of the force
RMS) read as a model 0.078 off where it was 0.073. Against the final model the residual is what the model
misses plus noise, and a hum stands out there as a line:

* each test whose scored span covers at least :data:`MIN_SPAN_S` seconds (a resolution of a
  quarter hertz) with steps uniform to :data:`STEP_SPREAD` is searched within
  :data:`TOLERANCE_HZ` of 50 and 60 Hz and their second and third harmonics, where the band
  around them lies below its Nyquist frequency;
* the residual (measured minus model, zero where the sample does not count) is windowed (Hann)
  and its periodogram's largest bin there must stand :data:`LINE_RATIO` times above every bin
  within the band around it (:data:`BAND_HZ`, and at least :data:`BAND_PERIODS` times the test's
  dominant frequency, so that a periodic test's neighbouring harmonics are in it: a 7.14-Hz
  test's 7th harmonic at 50 Hz is compared with its 5th and 9th) outside the line's own
  :data:`GUARD_HZ` (a residual's harmonic series, a sinusoidal test's odd harmonics at 49 and
  51 Hz, or a broadband edge, does not);
* the line's amplitude is the least-squares sinusoid at the refined frequency over the scored
  samples, and it must hold :data:`MIN_SHARE` of the residual's power;
* where the velocity has a line at the same frequency, the motion channels carry it too (the
  rig's motion, or the same hum on them): reported as such, never as the force channel's.

The check reports, it does not correct: ``error_without`` is the held-out error with the
fitted sinusoids of one frequency (``error_without_by_frequency``), or of all the lines found,
taken off the measured force (a diagnostic: the sinusoids are fitted on the held-out samples
too), so the user sees what the hum costs; filtering the channel or refitting is the user's
decision.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from damper.io.screening import dominant_frequency

__all__ = ["mains_lines", "interference_lines", "MAINS_HZ", "HARMONICS", "TOLERANCE_HZ", "BAND_HZ", "BAND_PERIODS",
           "GUARD_HZ", "LINE_RATIO", "MIN_SHARE", "MIN_SPAN_S", "STEP_SPREAD"]

#: Mains frequencies [Hz].
MAINS_HZ = (50.0, 60.0)
#: Harmonics searched (a rectifier's or a transformer's distortion puts power at 2f and 3f).
HARMONICS = (1, 2, 3)
#: A grid's frequency stays within a few tenths of a hertz of its nominal value.
TOLERANCE_HZ = 0.5
#: Half-width of the band a line must stand out of [Hz], ...
BAND_HZ = 10.0
#: ... at least this many times the test's dominant frequency (its harmonics k - 2 and k + 2 are
#: in the band: a residual with odd harmonics only has none between them) ...
BAND_PERIODS = 2.5
#: ... outside the line's own leakage (at least this, and four bins of the Hann window) [Hz].
GUARD_HZ = 0.75
#: The line's periodogram bin over the largest bin of the band around it.
LINE_RATIO = 10.0
#: Smallest share of the residual's power (over the scored samples) a line must hold.
MIN_SHARE = 0.01
#: Shortest scored span searched [s] (a resolution of 0.25 Hz).
MIN_SPAN_S = 4.0
#: Largest spread of the time steps over the scored span, as a share of the mean step, for the
#: periodogram (absolute logger stamps, 1.7e9 s, jitter by 2.4e-4 of a 1-ms step in float).
STEP_SPREAD = 0.01


def _line(y: np.ndarray, f0: float, dt: float, band_hz: float) -> tuple[float, float] | None:
    """The frequency [Hz] of a line of ``y`` (uniform samples ``dt`` apart) near ``f0`` and its
    ratio over the band of half-width ``band_hz`` around it (module docstring), or ``None`` when
    the band does not fit below Nyquist or holds nothing."""
    n = y.size
    if f0 + band_hz >= 0.5 / dt:
        return None
    spectrum = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(n))) ** 2
    freq = np.fft.rfftfreq(n, dt)
    df = freq[1]
    near = np.flatnonzero(np.abs(freq - f0) <= TOLERANCE_HZ)
    if near.size == 0:
        return None
    k = int(near[np.argmax(spectrum[near])])
    guard = max(GUARD_HZ, 4.0 * df)
    band = (np.abs(freq - freq[k]) <= band_hz) & (np.abs(freq - freq[k]) > guard)
    background = float(spectrum[band].max()) if band.any() else 0.0
    if not background > 0:
        return None  # a residual that is zero around the line (nothing to compare with)
    ratio = float(spectrum[k]) / background
    # the peak's frequency between bins: a parabola through the log power of three bins
    f = float(freq[k])
    if 0 < k < spectrum.size - 1 and np.all(spectrum[k - 1:k + 2] > 0):
        a, b, c = np.log(spectrum[k - 1:k + 2])
        if a - 2 * b + c < 0:
            f += 0.5 * (a - c) / (a - 2 * b + c) * df
    return float(f), ratio


def _sinusoid(t: np.ndarray, y: np.ndarray, mask: np.ndarray, f: float) -> np.ndarray:
    """The least-squares sinusoid (with a constant) at ``f`` over the ``mask`` samples, at every
    sample of ``t``."""
    w = 2.0 * math.pi * f
    basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(t)])
    coef, *_ = np.linalg.lstsq(basis[mask], y[mask], rcond=None)
    return basis[:, :2] @ coef[:2]


def mains_lines(names: Sequence[str], times: Sequence[np.ndarray], forces: Sequence[np.ndarray],
                predicted: Sequence[np.ndarray], displacements: Sequence[np.ndarray],
                velocities: Sequence[np.ndarray], masks: Sequence[np.ndarray],
                heldout: Sequence[np.ndarray]) -> dict | None:
    """Mains lines of the residual ``forces - predicted`` (module docstring).

    Parameters
    ----------
    names : sequence of str
        The tests' names.
    times : sequence of ndarray
        Each test's time [s].
    forces, predicted : sequence of ndarray
        Measured and model force [N] at the same samples.
    displacements : sequence of ndarray
        Each test's displacement [m] (its dominant frequency widens the band).
    velocities : sequence of ndarray
        Each test's velocity [m/s] (a line there is the motion channels').
    masks : sequence of bool ndarray
        The samples that count (usable: fitted or held out).
    heldout : sequence of bool ndarray
        The held-out samples (for the errors).

    Returns
    -------
    dict or None
        ``lines``: one dict per line found (``test``, ``frequency_hz``, ``amplitude_n``,
        ``share`` of the test's residual power, ``ratio`` over its band, ``in_motion``);
        ``searched``: the tests searched; ``tests``: how many were given; ``error``: the held-out
        relative RMS error as scored; ``error_without``: the same with every line of the force
        channel (not ``in_motion``) taken off the measured force; ``error_without_by_frequency``:
        with only the lines of one mains frequency (the key, in whole hertz) taken off. None when
        no test could be searched.
    """
    lines, searched = [], []
    waves: list = []  # (test index, span, frequency key, sinusoid) of the force channel's lines
    residuals, held_masks, norms = [], [], 0.0
    for i, (name, t, f, p, x, v, m, h) in enumerate(zip(names, times, forces, predicted, displacements,
                                                         velocities, masks, heldout)):
        t, f, p, x, v = (np.asarray(a, dtype=float) for a in (t, f, p, x, v))
        m, h = np.asarray(m, dtype=bool), np.asarray(h, dtype=bool)
        r = f - p
        residuals.append(r)
        held_masks.append(h)
        norms += float(np.sum(f[h] ** 2))
        scored = np.flatnonzero(m)
        if t.size < 16 or scored.size < 16 or float(t[scored[-1]] - t[scored[0]]) < MIN_SPAN_S:
            continue
        span = slice(int(scored[0]), int(scored[-1]) + 1)
        ts = t[span]
        steps = np.diff(ts)
        dt = float((ts[-1] - ts[0]) / (ts.size - 1))
        if not dt > 0 or float(np.ptp(steps)) > STEP_SPREAD * dt:
            continue
        rs, vs, ms = np.where(m, r, 0.0)[span], np.where(m, v, 0.0)[span], m[span]
        power = float(np.mean(r[m] ** 2))
        if not power > 0:
            continue
        searched.append(name)
        band = max(BAND_HZ, BAND_PERIODS * dominant_frequency(ts, x[span]))
        for base in MAINS_HZ:
            for k in HARMONICS:
                found = _line(rs, base * k, dt, band)
                if found is None or found[1] < LINE_RATIO:
                    continue
                freq, ratio = found
                wave = _sinusoid(ts, rs, ms, freq)
                amplitude = float(np.sqrt(2.0 * np.mean(wave[ms] ** 2)))
                share = 0.5 * amplitude ** 2 / power
                if share < MIN_SHARE:
                    continue
                motion = _line(vs, base * k, dt, band)
                in_motion = bool(motion is not None and motion[1] >= LINE_RATIO
                                 and abs(motion[0] - freq) <= GUARD_HZ)
                lines.append({"test": name, "frequency_hz": freq, "amplitude_n": amplitude,
                              "share": share, "ratio": ratio, "in_motion": in_motion})
                if not in_motion:
                    waves.append((i, span, round(base * k), wave))
    if not searched:
        return None

    def error(keys) -> float:
        num = 0.0
        for i, (r, h) in enumerate(zip(residuals, held_masks)):
            clean = r.copy()
            for j, span, key, wave in waves:
                if j == i and (keys is None or key in keys):
                    clean[span] -= wave
            num += float(np.sum(clean[h] ** 2))
        return math.sqrt(num / norms) if norms > 0 else math.nan

    keys = sorted({key for _, _, key, _ in waves})
    return {"lines": lines, "searched": searched, "tests": len(residuals), "error": error(()),
            "error_without": error(None), "error_without_by_frequency": {k: error((k,)) for k in keys}}


def interference_lines(result: dict | None) -> list[tuple[str, bool]]:
    """One sentence per mains frequency found, as ``sbib diagnose`` prints it and the report
    lists it, each with whether it is a finding on the force channel.

    Parameters
    ----------
    result : dict or None
        :func:`mains_lines`' result (None or no line: ``[]``).
    """
    if not result or not result["lines"]:
        return []
    out = []
    groups: dict = {}
    for line in result["lines"]:
        groups.setdefault((round(float(line["frequency_hz"])), bool(line["in_motion"])), []).append(line)
    n = len(result["searched"])
    for (freq, in_motion), found in sorted(groups.items()):
        amps = [float(x["amplitude_n"]) for x in found]
        shares = [100.0 * float(x["share"]) for x in found]
        amp = f"{min(amps):.3g} N" if max(amps) <= 1.05 * min(amps) else f"{min(amps):.3g}-{max(amps):.3g} N"
        share = f"{min(shares):.0f}" if round(min(shares)) == round(max(shares)) else f"{min(shares):.0f}-{max(shares):.0f}"
        where = f"in {len(found)} of {n} test(s) searched ({', '.join(x['test'] for x in found)})"
        if in_motion:
            out.append((f"a {freq:g}-Hz line in the force residual {where} is in the velocity too: the motion "
                        "channels carry it (the rig's motion, or the same hum on them), not the force channel alone",
                        False))
        else:
            by_frequency = result.get("error_without_by_frequency") or {}  # int keys, or str from JSON
            without = by_frequency.get(freq, by_frequency.get(f"{freq:g}", result["error_without"]))
            out.append((f"the force holds a {freq:g}-Hz line {where} that the motion does not have ({amp}, "
                        f"{share} % of the residual's power): mains interference on the force channel? Held-out "
                        f"error {result['error']:.4f} -> {without:.4f} without it (a diagnostic: nothing was "
                        "filtered or refitted)", True))
    return out
