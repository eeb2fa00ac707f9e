"""Mains interference in the force channel: narrow spectral lines of the final residual.

A load cell's amplifier picks up the mains (a ground loop, an unshielded cable): the force
channel then carries a sinusoid at 50 or 60 Hz (and its harmonics) that no motion of the damper
drives. The screening cannot see it in the force itself (a broadband test, such as the Dyke
recordings up to 50 Hz, has motion there), and the residual trace
(:mod:`damper.diagnosis.trace`) finds no variable of the motion that holds it: it said
"unlocated", and a probe's UTFSM tests with a 40-N, 50-Hz hum (3.5 % of the force RMS) read as
a model 0.078 off where it was 0.073. Against the final model the residual is what the model
misses plus noise, and a hum stands out there as a line:

* each test whose steps are uniform and whose scored span covers at least
  :data:`MIN_SPAN_S` seconds (a resolution of a quarter hertz) is searched within
  :data:`TOLERANCE_HZ` of 50 and 60 Hz and their second and third harmonics, below 0.45 times its
  sampling rate;
* the residual (measured minus model, zero where the sample does not count) is windowed (Hann)
  and its periodogram's largest bin there must stand :data:`LINE_RATIO` times above every bin
  within :data:`BAND_HZ` of it outside the line's own :data:`GUARD_HZ` (a residual's harmonic
  series, a sinusoidal test's odd harmonics at 49 and 51 Hz, or a broadband edge, does not);
* the line's amplitude is the least-squares sinusoid at the refined frequency over the scored
  samples, and it must hold :data:`MIN_SHARE` of the residual's power;
* where the velocity has a line at the same frequency the rig moved the damper there (a
  shaker's hum): the line is the motion's, reported as such, never as interference.

The check reports, it does not correct: ``error_without`` is the held-out error with the
fitted sinusoids taken off the measured force (a diagnostic: the sinusoids are fitted on the
held-out samples too), so the user sees what the hum costs; filtering the channel or refitting
is the user's decision.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

__all__ = ["mains_lines", "interference_lines", "MAINS_HZ", "HARMONICS", "TOLERANCE_HZ", "BAND_HZ", "GUARD_HZ",
           "LINE_RATIO", "MIN_SHARE", "MIN_SPAN_S"]

#: Mains frequencies [Hz].
MAINS_HZ = (50.0, 60.0)
#: Harmonics searched (a rectifier's or a transformer's distortion puts power at 2f and 3f).
HARMONICS = (1, 2, 3)
#: A grid's frequency stays within a few tenths of a hertz of its nominal value.
TOLERANCE_HZ = 0.5
#: Half-width of the band a line must stand out of [Hz] ...
BAND_HZ = 10.0
#: ... outside the line's own leakage (at least this, and four bins of the Hann window) [Hz].
GUARD_HZ = 0.75
#: The line's periodogram bin over the largest bin of the band around it.
LINE_RATIO = 10.0
#: Smallest share of the residual's power (over the scored samples) a line must hold.
MIN_SHARE = 0.01
#: Shortest scored span searched [s] (a resolution of 0.25 Hz).
MIN_SPAN_S = 4.0


def _line(t: np.ndarray, y: np.ndarray, f0: float, dt: float) -> tuple[float, float] | None:
    """The frequency [Hz] of a line of ``y`` near ``f0`` and its ratio over the band around it
    (module docstring), or ``None`` when the band does not fit below Nyquist."""
    n = y.size
    spectrum = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(n))) ** 2
    freq = np.fft.rfftfreq(n, dt)
    df = freq[1]
    if f0 + BAND_HZ >= 0.5 / dt:
        return None
    near = np.flatnonzero(np.abs(freq - f0) <= TOLERANCE_HZ)
    if near.size == 0:
        return None
    k = int(near[np.argmax(spectrum[near])])
    guard = max(GUARD_HZ, 4.0 * df)
    band = (np.abs(freq - freq[k]) <= BAND_HZ) & (np.abs(freq - freq[k]) > guard)
    if not band.any():
        return None
    background = float(spectrum[band].max())
    ratio = float(spectrum[k]) / background if background > 0 else math.inf
    # the peak's frequency between bins: a parabola through the log power of three bins
    f = float(freq[k])
    if 0 < k < spectrum.size - 1 and np.all(spectrum[k - 1:k + 2] > 0):
        a, b, c = np.log(spectrum[k - 1:k + 2])
        if a - 2 * b + c < 0:
            f += 0.5 * (a - c) / (a - 2 * b + c) * df
    return f, ratio


def _sinusoid(t: np.ndarray, y: np.ndarray, mask: np.ndarray, f: float) -> np.ndarray:
    """The least-squares sinusoid (with a constant) at ``f`` over the ``mask`` samples, at every
    sample of ``t``."""
    w = 2.0 * math.pi * f
    basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(t)])
    coef, *_ = np.linalg.lstsq(basis[mask], y[mask], rcond=None)
    return basis[:, :2] @ coef[:2]


def mains_lines(names: Sequence[str], times: Sequence[np.ndarray], forces: Sequence[np.ndarray],
                predicted: Sequence[np.ndarray], velocities: Sequence[np.ndarray],
                masks: Sequence[np.ndarray], heldout: Sequence[np.ndarray]) -> dict | None:
    """Mains lines of the residual ``forces - predicted`` (module docstring).

    Parameters
    ----------
    names : sequence of str
        The tests' names.
    times : sequence of ndarray
        Each test's time [s].
    forces, predicted : sequence of ndarray
        Measured and model force [N] at the same samples.
    velocities : sequence of ndarray
        Each test's velocity [m/s] (a line there is the motion's).
    masks : sequence of bool ndarray
        The samples that count (usable: fitted or held out).
    heldout : sequence of bool ndarray
        The held-out samples (for ``error_without``).

    Returns
    -------
    dict or None
        ``lines``: one dict per line found (``test``, ``frequency_hz``, ``amplitude_n``,
        ``share`` of the test's residual power, ``ratio`` over its band, ``in_motion``);
        ``searched``: the tests searched; ``error``, ``error_without``: the held-out relative RMS
        error as scored and with the interference lines' sinusoids taken off the measured force.
        None when no test could be searched.
    """
    lines, searched = [], []
    num = num_without = den = 0.0
    for name, t, f, p, v, m, h in zip(names, times, forces, predicted, velocities, masks, heldout):
        t, f, p, v = (np.asarray(a, dtype=float) for a in (t, f, p, v))
        m, h = np.asarray(m, dtype=bool), np.asarray(h, dtype=bool)
        r = f - p
        clean = r.copy()
        steps = np.diff(t)
        ok = t.size > 16 and m.any() and float(np.ptp(steps)) <= 1e-6 * float(np.mean(steps))
        if ok:
            scored = np.flatnonzero(m)
            ok = float(t[scored[-1]] - t[scored[0]]) >= MIN_SPAN_S
        if ok:
            dt = float(np.mean(steps))
            span = slice(int(scored[0]), int(scored[-1]) + 1)
            ts, rs, vs, ms = t[span], np.where(m, r, 0.0)[span], v[span], m[span]
            power = float(np.mean(r[m] ** 2))
            searched.append(name)
            for base in MAINS_HZ:
                for k in HARMONICS:
                    found = _line(ts, rs, base * k, dt)
                    if found is None or found[1] < LINE_RATIO or not power > 0:
                        continue
                    freq, ratio = found
                    wave = _sinusoid(ts, rs, ms, freq)
                    amplitude = float(np.sqrt(2.0 * np.mean(wave[ms] ** 2)))
                    share = 0.5 * amplitude ** 2 / power
                    if share < MIN_SHARE:
                        continue
                    motion = _line(ts, np.where(ms, vs, 0.0), base * k, dt)
                    in_motion = bool(motion is not None and motion[1] >= LINE_RATIO
                                     and abs(motion[0] - freq) <= GUARD_HZ)
                    lines.append({"test": name, "frequency_hz": freq, "amplitude_n": amplitude,
                                  "share": share, "ratio": ratio, "in_motion": in_motion})
                    if not in_motion:
                        clean[span] -= wave
        if h.any():
            num += float(np.sum(r[h] ** 2))
            num_without += float(np.sum(clean[h] ** 2))
            den += float(np.sum(f[h] ** 2))
    if not searched:
        return None
    return {"lines": lines, "searched": searched,
            "error": math.sqrt(num / den) if den > 0 else math.nan,
            "error_without": math.sqrt(num_without / den) if den > 0 else math.nan}


def interference_lines(result: dict | None) -> list[str]:
    """One sentence per mains frequency found, as ``sbib diagnose`` prints it and the report
    lists it.

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
            out.append(f"a {freq:g}-Hz line in the force residual {where} is in the velocity too: the rig moved "
                       "the damper at that frequency (not the force channel's interference)")
        else:
            out.append(f"the force holds a {freq:g}-Hz line {where} that the motion does not have ({amp}, "
                       f"{share} % of the residual's power): mains interference on the force channel? Held-out "
                       f"error {result['error']:.4f} -> {result['error_without']:.4f} without it (a diagnostic: "
                       "nothing was filtered or refitted)")
    return out
