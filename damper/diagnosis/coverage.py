"""What another recording asks of a model beyond what its fitted tests showed.

``sbib diagnose --data A --validate B`` scores a model fitted on A over all of B. When B moves
faster or at higher frequencies than A did, part of that error is extrapolation, not a fault the
loop could have found in A: no fit on A sees how the device behaves there. Fitted on the shared
Dyke recording (``ransim_u``: 90 % of its velocity power below 10 Hz, 99 % below 29.8 Hz in its fitted part,
speeds up to 0.29 m/s) and scored on ``ranran_50`` (a random displacement up to 50 Hz: half of
its velocity power above 22 Hz, speeds up to 0.59 m/s), the Spencer-type model's error was
0.192 → 0.195, and 0.127 → 0.130 over the part of ``ranran_50``'s force in the 29.8-Hz band of
the fitted part (81 % of its force power; measured 2026-11-28, docs/diagnosis.md). This module says so, per recording:

* the **fitted band**: the frequency below which :data:`BAND_POWER` of the fitted tests' velocity
  power lies (their usable samples, pooled over every contiguous run of at least
  :data:`MIN_RUN` samples; a Hann-windowed periodogram per run, weighted by its energy);
* the **fitted amplitudes**: the largest speed and the displacement range of those samples;
* for each other recording, over its scored samples: the share of its velocity power above the
  fitted band (beyond the main lobe of its own periodogram, :data:`LEAKAGE_BINS`), the share of samples faster than the fitted speed (by :data:`AMPLITUDE_MARGIN`)
  or outside the displacement range (by that share of the stroke), and both models' errors
  **in the fitted band** (residual and force through a zero-phase low-pass just above the band
  edge: eighth-order Butterworth at :data:`CUTOFF_FACTOR` times it, ``sosfiltfilt``, run by run, without :data:`EDGE_PERIODS` periods
  of the band edge at each end of a run, where the filter starts up), with the share of the
  force power there;
* a finding when the power above the band reaches :data:`BEYOND_BAND_SHARE` or the samples
  beyond the amplitudes :data:`BEYOND_AMPLITUDE_SHARE`. The in-band error is given when that
  band holds at least :data:`MIN_IN_BAND_POWER` of the force power (below it the figure would
  rest on a sliver of the signal).

Nothing is refitted or filtered for the scores themselves: the errors the loop reports stay
those over every scored sample; this is an account of where they come from.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from benchmark.foundation.channel_runs import runs

__all__ = ["velocity_band", "motion_coverage", "coverage_lines", "periodogram", "BAND_POWER", "MIN_RUN", "CUTOFF_FACTOR", "LEAKAGE_BINS",
           "AMPLITUDE_MARGIN", "BEYOND_BAND_SHARE", "BEYOND_AMPLITUDE_SHARE", "MIN_IN_BAND_POWER"]

#: The fitted band's edge: this share of the fitted tests' velocity power lies below it.
BAND_POWER = 0.99
#: Shortest contiguous run of counted samples a spectrum is taken over (a 256-point periodogram
#: resolves a 200-Hz test to 0.8 Hz).
MIN_RUN = 256
#: A sample is beyond the fitted amplitudes when faster than the fitted speed by this share, or
#: outside the fitted displacement range by this share of the fitted stroke.
AMPLITUDE_MARGIN = 0.02
#: A recording with this share of its velocity power above the fitted band is a finding ...
BEYOND_BAND_SHARE = 0.10
#: ... as is one with this share of its scored samples beyond the fitted amplitudes.
BEYOND_AMPLITUDE_SHARE = 0.05
#: The in-band error is given when the fitted band holds this share of the recording's force power.
MIN_IN_BAND_POWER = 0.25
#: Order of the low-pass filter (applied forwards and backwards: zero phase, twice the roll-off) ...
FILTER_ORDER = 8
#: ... and its cutoff over the band edge: at the edge the two passes keep 94 % of the power (a
#: cutoff at the edge itself halved it: a pure 2-Hz force against a 2.02-Hz band read as 27 % in
#: band), one and a half times above it 0.3 %.
CUTOFF_FACTOR = 1.25
#: Bins of a recording's periodogram beyond the band edge that still count as in band (the Hann
#: window's main lobe: a line leaks into two bins each side).
LEAKAGE_BINS = 2
#: The in-band sums leave out this many periods of the band edge at each end of a run: the
#: filter's start-up there (a broadband signal's edge transient put 3 % of a removed band back in
#: band over a 20-s run; without the ends, 3e-5).
EDGE_PERIODS = 3.0


def _runs(mask: np.ndarray) -> list[slice]:
    """Contiguous runs of True in ``mask`` at least :data:`MIN_RUN` long."""
    return [slice(a, b) for a, b in runs(mask) if b - a >= MIN_RUN]


def periodogram(t: np.ndarray, y: np.ndarray, run: slice) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] and energy-weighted periodogram of ``y`` over ``run`` (mean removed, Hann).

    Parameters
    ----------
    t, y : ndarray
        Times [s] (uniform over ``run``) and the signal.
    run : slice
        The samples taken.
    """
    seg = np.asarray(y[run], dtype=float)
    dt = float(t[run.stop - 1] - t[run.start]) / max(1, seg.size - 1)
    seg = seg - seg.mean()
    window = np.hanning(seg.size)
    power = np.abs(np.fft.rfft(seg * window)) ** 2 / max(1e-300, float(np.sum(window ** 2)))
    return np.fft.rfftfreq(seg.size, dt), power


def velocity_band(motions: Sequence, masks: Sequence[np.ndarray]) -> float:
    """The fitted band [Hz]: below it lies :data:`BAND_POWER` of the velocity power of ``motions``
    over the samples ``masks`` count (runs of at least :data:`MIN_RUN` samples; NaN if none).

    Parameters
    ----------
    motions : sequence of Motion
        The fitted tests' motions (:class:`damper.diagnosis.effects.Motion`, SI).
    masks : sequence of ndarray of bool
        The samples of each that the loop saw (training and held-out).
    """
    freqs, powers = [], []
    for m, k in zip(motions, masks):
        for run in _runs(k):
            f, p = periodogram(m.t, m.xdot, run)
            freqs.append(f)
            powers.append(p)
    if not freqs:
        return math.nan
    f = np.concatenate(freqs)
    p = np.concatenate(powers)
    order = np.argsort(f, kind="stable")
    cum = np.cumsum(p[order])
    if not cum[-1] > 0:
        return math.nan
    return float(f[order][min(order.size - 1, int(np.searchsorted(cum, BAND_POWER * cum[-1])))])


def _lowpass(t: np.ndarray, y: np.ndarray, band: float) -> tuple[np.ndarray, slice] | None:
    """``y`` (sampled at the times ``t``, uniformly) through the zero-phase low-pass that keeps the
    band up to ``band`` [Hz] (cutoff :data:`CUTOFF_FACTOR` times it), and the part of it clear of
    the filter's start-up at both ends (:data:`EDGE_PERIODS`); ``(y, all)`` when that cutoff
    reaches 0.45 of the sampling rate (nothing above it to take off; the band then runs to the
    Nyquist frequency); None when the run is too short to leave anything clear."""
    from scipy.signal import butter, sosfiltfilt  # scipy.signal loads scipy.stats: kept off the import path

    fs = (t.size - 1) / float(t[-1] - t[0])
    cutoff = CUTOFF_FACTOR * band
    if cutoff >= 0.45 * fs:
        return np.asarray(y, dtype=float), slice(0, t.size)
    edge = int(math.ceil(EDGE_PERIODS * fs / band))
    if t.size < 4 * edge:
        return None
    sos = butter(FILTER_ORDER, cutoff, fs=fs, output="sos")
    return sosfiltfilt(sos, np.asarray(y, dtype=float)), slice(edge, t.size - edge)


def _defined(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _share(value) -> float:
    """A share of :func:`motion_coverage` for comparisons (None, undefined, as 0)."""
    return 0.0 if value is None else float(value)


def motion_coverage(fitted_motions: Sequence, fitted_masks: Sequence[np.ndarray], histories: Sequence) -> dict:
    """How far each other recording's motion lies outside the fitted tests' (module docstring).

    Parameters
    ----------
    fitted_motions : sequence of Motion
        The fitted tests' motions (SI).
    fitted_masks : sequence of ndarray of bool
        The samples of each the loop saw (training and held-out).
    histories : sequence of ValidationHistory
        Each other recording: motion, measured force [N], scored samples, both models' forces
        (:class:`damper.diagnosis.loop.ValidationHistory`).

    Returns
    -------
    dict
        ``band_hz``, ``speed_max`` [m/s], ``displacement_range`` [m] of the fitted tests, and
        ``recordings``: per name, ``power_beyond_band``, ``beyond_amplitude`` (shares),
        ``speed_max`` [m/s], ``in_band_power`` (share of the force power in the band; None when
        no run could be filtered), ``error_before_in_band``, ``error_after_in_band`` (None below
        :data:`MIN_IN_BAND_POWER`), ``finding``.
    """
    band = velocity_band(fitted_motions, fitted_masks)
    seen = [np.asarray(k, dtype=bool) for k in fitted_masks]
    v = np.concatenate([np.abs(m.xdot[k]) for m, k in zip(fitted_motions, seen)]) if seen else np.zeros(0)
    x = np.concatenate([m.x[k] for m, k in zip(fitted_motions, seen)]) if seen else np.zeros(0)
    speed = float(v.max()) if v.size else math.nan
    lo, hi = (float(x.min()), float(x.max())) if x.size else (math.nan, math.nan)
    stroke = hi - lo
    out: dict = {"band_hz": _defined(band), "speed_max": _defined(speed),
                 "displacement_range": [_defined(lo), _defined(hi)], "recordings": {}}
    for h in histories:
        m, k = h.motion, np.asarray(h.scored, dtype=bool)
        n = int(k.sum())
        faster = np.abs(m.xdot) > speed * (1.0 + AMPLITUDE_MARGIN)
        wider = (m.x < lo - AMPLITUDE_MARGIN * stroke) | (m.x > hi + AMPLITUDE_MARGIN * stroke)
        beyond = float(np.sum(k & (faster | wider)) / n) if n else math.nan
        share_faster = float(np.sum(k & faster) / n) if n else math.nan
        share_wider = float(np.sum(k & wider) / n) if n else math.nan
        above = total = 0.0
        sums = {"force": [0.0, 0.0], "before": [0.0, 0.0], "after": [0.0, 0.0]}  # [in band, all]
        filtered = False
        for run in (_runs(k) if math.isfinite(band) else ()):  # no fitted band: nothing to compare with
            f, p = periodogram(m.t, m.xdot, run)
            # the Hann window spreads a line over two bins each side: a recording shorter than the
            # fitted tests (coarser bins) would otherwise put its leakage "above" their band
            above += float(p[f > band + LEAKAGE_BINS * f[1]].sum())
            total += float(p.sum())
            force = h.force[run]
            series = {"force": force, "before": force - h.before[run], "after": force - h.after[run]}
            for name, y in series.items():
                low = _lowpass(m.t[run], y, band)
                if low is None:  # too short to filter: left out of the in-band sums
                    break
                y_low, clear = low
                sums[name][0] += float(y_low[clear] @ y_low[clear])
                sums[name][1] += float(y[clear] @ y[clear])
                filtered = True
        share_above = above / total if total > 0 else math.nan
        in_band = sums["force"][0] / sums["force"][1] if sums["force"][1] > 0 else None
        errors = {}
        for label in ("before", "after"):
            ok = in_band is not None and in_band >= MIN_IN_BAND_POWER and sums["force"][0] > 0
            errors[label] = math.sqrt(sums[label][0] / sums["force"][0]) if ok else None
        finding = bool((math.isfinite(share_above) and share_above >= BEYOND_BAND_SHARE)
                       or (math.isfinite(beyond) and beyond >= BEYOND_AMPLITUDE_SHARE))
        out["recordings"][m.name] = {  # None, not NaN, where undefined: diagnosis.json stays strict JSON
            "power_beyond_band": _defined(share_above), "beyond_amplitude": _defined(beyond),
            "faster": _defined(share_faster), "beyond_displacement": _defined(share_wider),
            "speed_max": float(np.max(np.abs(m.xdot[k]))) if n else None,
            "in_band_power": in_band if filtered else None,
            "error_before_in_band": errors["before"] if filtered else None,
            "error_after_in_band": errors["after"] if filtered else None,
            "finding": finding}
    return out


def coverage_lines(coverage: dict | None) -> list[tuple[str, bool]]:
    """One sentence per other recording for the output and the report, with whether it is a
    finding (the recording asks the model to extrapolate).

    Parameters
    ----------
    coverage : dict or None
        :func:`motion_coverage`'s result (``Diagnosis.validation["coverage"]``).
    """
    if not coverage or not coverage.get("recordings"):
        return []
    band, speed = coverage["band_hz"], coverage["speed_max"]
    lo, hi = coverage["displacement_range"]
    # fitted tests without a run of MIN_RUN counted samples have no measured band
    band_text = f"band ({band:.3g} Hz)" if band is not None else f"band (not measured: no run of {MIN_RUN} samples)"
    speed_text = f"{speed:.3g} m/s" if speed is not None else "speed"
    lines = []
    for name, c in coverage["recordings"].items():
        parts = []
        if _share(c["power_beyond_band"]) >= 0.005:
            parts.append(f"{100 * c['power_beyond_band']:.0f} % of its velocity power lies above the fitted "
                         f"tests' {band_text}")
        if _share(c["faster"]) >= 0.005:
            parts.append(f"{100 * c['faster']:.0f} % of its scored samples move faster than their "
                         f"{speed_text} (up to {c['speed_max']:.3g} m/s)")
        if _share(c["beyond_displacement"]) >= 0.005:
            parts.append(f"{100 * c['beyond_displacement']:.0f} % of its scored samples lie outside their "
                         f"displacements ({1e3 * lo:.3g} to {1e3 * hi:.3g} mm)")
        if c["finding"]:
            text = f"{name} asks the model to extrapolate: " + "; ".join(parts)
            if c["error_before_in_band"] is not None and c["in_band_power"] < 0.99:
                text += (f"; in the fitted band (to {band:.3g} Hz: {100 * c['in_band_power']:.0f} % of its force power) "
                         f"the error is {c['error_before_in_band']:.4f} → {c['error_after_in_band']:.4f}")
            elif c["in_band_power"] is not None and c["error_before_in_band"] is None:
                text += (f"; only {100 * c['in_band_power']:.0f} % of its force power lies in the fitted band, "
                         "too little for an in-band error")
        elif c["power_beyond_band"] is None:
            text = (f"{name} moves within the fitted tests' amplitudes ({speed_text})"
                    + (" but for small shares: " + "; ".join(parts) if parts else "")
                    + f"; its frequencies could not be compared with theirs (no run of {MIN_RUN} samples "
                    "on one side or the other)")
        else:
            text = (f"{name} moves within the fitted tests' {band_text} and amplitudes ({speed_text})"
                    + (" but for small shares: " + "; ".join(parts) if parts else "")
                    + ": its error is not an extrapolation in frequency or amplitude")
        lines.append((text, c["finding"]))
    return lines
