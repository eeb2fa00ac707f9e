"""How far the measured force is shifted in time against a fitted model: a channel-skew check.

Data acquisition systems that sample force and motion through different chains (another
filter, another card, a buffer) deliver the force a few samples late or early. The screening
(:mod:`damper.io.screening`) estimates the lag between force and velocity by cross-correlation,
but an MR damper's force itself lags and leads its velocity through the hysteresis, so that
figure mixes the device's physics with the channels' skew. Against a fitted model, whose
dynamics carry the physics, what is left is the skew (or a dynamic the model lacks):

.. math::

   \\hat\\tau = \\arg\\min_\\tau \\sum_i \\big(F_i - \\hat F(t_i - \\tau)\\big)^2 ,

searched on a grid of whole samples of the finest sampling step (within
:data:`MAX_SHIFT_SAMPLES` samples and :data:`MAX_SHIFT_S` seconds) and refined by a parabola
through the best three. :math:`\\hat\\tau > 0`: the measured force comes *later* than the model
predicts (a force channel delayed by :math:`\\hat\\tau`). The model's force is interpolated
linearly between its samples. Only the usable samples count (the screening's exclusions stay out).

The check reports, it does not correct: a skew of a sample or more that lowers the error by
:data:`MIN_GAIN` or more is a finding for the user to check against the rig (``sbib diagnose``
prints it and the report lists it); shifting a channel is the user's decision. Against a model
*fitted to the skewed data* the figure is a lower bound: a model with a field lag or a series
dashpot takes up part of a skew in its own phase (the shared Dyke recording with its force
delayed by 4 samples, 1.33 ms: 1.2 samples found, error 0.0988 -> 0.0954 if shifted; the
recording decimated to 1 kHz: -0.2 samples, no finding; docs/diagnosis.md).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from benchmark.foundation.channel_runs import runs
from damper.diagnosis.coverage import periodogram

__all__ = ["force_alignment", "MAX_SHIFT_SAMPLES", "MAX_SHIFT_S", "MIN_GAIN", "MIN_FINDING_S"]

#: Widest shift searched, in samples of the finest sampling step ...
MAX_SHIFT_SAMPLES = 16
#: ... and in seconds (whichever is smaller): channel skews are a few samples, while shifts of a
#: sizeable part of a cycle would fit the model's own phase errors instead.
MAX_SHIFT_S = 0.010
#: Relative drop of the error a shift must bring to be reported as a finding.
MIN_GAIN = 0.02
#: Smallest shift reported where a sample is longer than this [s] (below 200 Hz).
MIN_FINDING_S = 0.005


def _error(times, forces, predicted, masks, tau: float) -> float:
    num = 0.0
    den = 0.0
    for t, f, p, m in zip(times, forces, predicted, masks):
        shifted = np.interp(t[m] - tau, t, p)
        num += float(np.sum((f[m] - shifted) ** 2))
        den += float(np.sum(f[m] ** 2))
    return float(np.sqrt(num / den)) if den > 0 else float("nan")


#: A test whose velocity holds this share of its power within :data:`LINE_WIDTH` of its peak
#: frequency moves as one sinusoid ...
SINUSOID_SHARE = 0.9
#: ... (relative width of that neighbourhood) ...
LINE_WIDTH = 0.25
#: ... and sinusoidal tests whose frequencies span less than this ratio leave a skew of the force
#: channel indistinguishable from a phase of the model (a shift is a phase at one frequency).
FREQUENCY_SPAN = 1.5


def _sinusoid_frequency(t: np.ndarray, v: np.ndarray, mask: np.ndarray) -> float | None:
    """The frequency [Hz] of a velocity that is one sinusoid over its longest counted run, else
    None (a broadband or multi-frequency motion, or too short a run)."""
    spans = runs(mask)
    a, b = max(spans, key=lambda r: r[1] - r[0]) if spans else (0, 0)
    if b - a < 64:
        return None
    f, power = periodogram(t, v, slice(a, b))
    if not power.sum() > 0:
        return None
    peak = float(f[int(np.argmax(power))])
    near = np.abs(f - peak) <= max(LINE_WIDTH * peak, 2.0 * f[1])
    return peak if power[near].sum() >= SINUSOID_SHARE * power.sum() else None


def skew_identifiable(times: Sequence[np.ndarray], velocities: Sequence[np.ndarray],
                      masks: Sequence[np.ndarray], inputs: Sequence[np.ndarray] | None = None
                      ) -> tuple[bool, list[float]]:
    """Whether the tests can tell a skew of the force channel from a phase of the model: the
    coil input changes within some test (its steps are events the force follows in time), some
    test is not one sinusoid, or the sinusoidal tests' frequencies span :data:`FREQUENCY_SPAN`.
    Returns that and the sinusoidal tests' frequencies [Hz].

    A probe (2026-11-28) delayed the force of one 3-Hz UTFSM test by 8 ms: the model's hysteresis
    took the delay as its phase (the error fell, 0.078 to 0.056) and the search found the force
    0.05 ms off, which the report read as "no skew".

    Parameters
    ----------
    times, velocities, masks : sequence of ndarray
        Each test's time [s], velocity [m/s] and counted samples.
    inputs : sequence of ndarray, optional
        Each test's coil input (V or A).
    """
    if inputs is not None and any(np.ptp(np.asarray(u, dtype=float)) > 1e-12 for u in inputs):
        return True, []
    freqs = []
    for t, v, m in zip(times, velocities, masks):
        f = _sinusoid_frequency(t, v, m)
        if f is None:
            return True, freqs
        freqs.append(f)
    return bool(freqs and max(freqs) >= FREQUENCY_SPAN * min(freqs)), freqs


def force_alignment(times: Sequence[np.ndarray], forces: Sequence[np.ndarray],
                    predicted: Sequence[np.ndarray], masks: Sequence[np.ndarray],
                    velocities: Sequence[np.ndarray] | None = None,
                    inputs: Sequence[np.ndarray] | None = None) -> dict | None:
    """The time shift of the measured force against a model's prediction (module docstring).

    Parameters
    ----------
    times : sequence of ndarray
        Each test's time [s], strictly increasing.
    forces : sequence of ndarray
        Each test's measured force [N].
    predicted : sequence of ndarray
        The model's force at the same samples [N].
    masks : sequence of bool ndarray
        The samples that count (usable, not excluded by the screening).
    velocities : sequence of ndarray, optional
        Each test's velocity [m/s]: with it, ``identifiable`` and ``frequencies``
        (:func:`skew_identifiable`); a skew that is not identifiable is never a finding.
    inputs : sequence of ndarray, optional
        Each test's coil input, for :func:`skew_identifiable`.

    Returns
    -------
    dict or None
        ``shift_s`` (:math:`\\hat\\tau` [s], positive: the measured force is late),
        ``shift_samples`` (in samples of the finest step), ``step_s`` (that step [s]),
        ``error_unshifted`` and ``error_shifted`` (relative RMS force error over the counted
        samples), ``finding`` (a shift of at least one sample, or of :data:`MIN_FINDING_S` where a
        sample is longer, that lowers the error by :data:`MIN_GAIN` or more and lies inside the
        search), ``searched_s`` (the widest shift searched: :data:`MAX_SHIFT_S`, or one sample
        where a sample is longer), ``at_limit`` (the best shift is the widest searched: a bound,
        never a finding); None when no sample counts or no force is there to compare.
    """
    masks = [np.asarray(m, dtype=bool) for m in masks]
    if not any(m.any() for m in masks):
        return None
    # a test's mean step (time stamps rounded to a few digits make the median step jitter)
    steps = [float((t[-1] - t[0]) / (t.size - 1)) for t in times if t.size > 1]
    if not steps:
        return None
    dt = min(steps)
    # at least a sample each way: a coarsely sampled test (50 Hz: 20 ms) is searched within one
    # sample and the parabola places the shift inside it
    j_max = max(1, int(min(MAX_SHIFT_SAMPLES, np.floor(MAX_SHIFT_S / dt + 1e-9))))
    shifts = np.arange(-j_max, j_max + 1)
    errors = np.array([_error(times, forces, predicted, masks, j * dt) for j in shifts])
    if not np.isfinite(errors).any():
        return None  # no force to compare (all zero where it counts)
    k = int(np.nanargmin(errors))
    best = float(shifts[k])
    if 0 < k < shifts.size - 1:
        e0, e1, e2 = errors[k - 1], errors[k], errors[k + 1]
        curvature = e0 - 2.0 * e1 + e2
        if curvature > 0:
            best += 0.5 * (e0 - e2) / curvature
    tau = best * dt
    error_shifted = _error(times, forces, predicted, masks, tau)
    error_unshifted = float(errors[j_max])
    # a skew of a sample, or of MIN_FINDING_S where a sample is longer (a half sample at 50 Hz
    # is 10 ms, a tenth of a 1-Hz stroke's quarter)
    # at the edge of the search the shift is only a bound (the skew, or the model's phase error,
    # may be larger): no finding, said by ``at_limit``
    at_limit = k in (0, shifts.size - 1)
    identifiable, freqs = ((True, []) if velocities is None
                           else skew_identifiable(times, velocities, masks, inputs))
    finding = bool(abs(tau) >= min(dt, MIN_FINDING_S) - 1e-12 and not at_limit and identifiable
                   and error_shifted <= (1.0 - MIN_GAIN) * error_unshifted)
    return {"shift_s": tau, "shift_samples": best, "step_s": dt,
            "error_unshifted": error_unshifted, "error_shifted": error_shifted,
            "finding": finding, "searched_s": j_max * dt, "at_limit": bool(at_limit),
            "identifiable": bool(identifiable), "frequencies": [float(f) for f in freqs]}
