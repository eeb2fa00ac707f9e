"""The coarse pass of the residual loop: the same tests on fewer samples, and progress lines.

Every candidate the loop tries is a joint nonlinear least-squares refit whose Jacobian is built
by finite differences, one simulation of every test per free parameter; the cost of the loop is
therefore the number of samples times the number of simulations. The models are continuous-time
(:func:`damper.models.response.simulate` sub-steps the hysteresis between samples and interpolates the
motion), so a test sampled densely (1-3 kHz for motions of a few hertz) carries far more samples
than the fit of a dozen parameters needs. :func:`decimate` keeps one sample in ``q``, with ``q``
chosen by :func:`decimation_factor` so that

* the fitted samples of all tests together are at most about ``max_samples``, and
* every test keeps at least :data:`MIN_SAMPLES_PER_PERIOD` samples per period of its dominant
  frequency and at least :data:`MIN_SAMPLES_PER_LAG` per :data:`FASTEST_LAG` (so that a voltage
  lag of ten milliseconds or more stays visible).

Decimation alone does not make a stiff model cheap: the hysteretic kernels sub-step each sample
in proportion to the stiffness of the hysteresis times the sample's length, so a Spencer-type
model with a large ``rho`` costs about the same per *second* of test at any sampling (on the
shared Dyke recording, 5x fewer samples cost 2.2x less, not 5x). The decimated tests are
therefore also simulated at :data:`COARSE_SUBSTEP_SCALE` times the model's sub-step tolerance
(:func:`damper.models.base.with_coarser_substeps`, at most 1; the RK4 error is of order
``tol**4``): on that recording's Spencer fit, 3x cheaper, with the force 4e-4 (relative RMS) from
the model's own tolerance where the residual the loop works on is 0.1. Every error the loop
reports is computed on every sample at the model's own tolerance.

Nor does decimation make a *long* test cheap, for the same reason: the kernels' cost follows the
seconds of motion simulated, not the samples kept. And it cannot go below the motion's own
bandwidth: between samples the motion is interpolated (cubic Hermite in ``x`` and ``xdot``), so
every test also keeps at least :data:`MIN_SAMPLES_PER_BAND` samples per period of the frequency
below which :data:`BAND_POWER` of its velocity's power lies (between its first and last scored
samples, :func:`damper.io.screening.band_edge`). On the Dyke damper's random
recording (`ranran_50`, content up to about 80 Hz), one sample in 16 instead of 9 raised the
Spencer base's training error from 0.16 to 0.21, and its refinement took five times as long.
Where that bound is what stops the decimation (alone, or at the same ``q`` as another) and the
tests, so decimated, still hold more than :data:`WINDOW_TRIGGER` times ``max_samples`` fitted
samples (a random-input recording of a minute at 3 kHz, or of 20 s at 1 kHz), the coarse pass fits
**windows** of them (:func:`windows`): stretches spread evenly over each test's usable span,
each a separate motion that starts :data:`LEAD_IN` before its first scored sample, where the
displacement passes through its value at the test's start (so that the models' rest state is as
close to the test's own start as the data allow), with the time since the test began kept
(``Motion.origin``). Their fitted samples come to about ``max_samples``; the seconds simulated,
hence the cost, shrink with them.

The loop screens, refits and chooses on the decimated tests, then evaluates (and polishes) the
chosen models on every sample (:func:`damper.diagnosis.loop.diagnose`).

:class:`Progress` writes one line per long step, prefixed with the elapsed time, so that a log
(or CI) shows where the loop spends its time.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from typing import Callable, TextIO

import numpy as np

from benchmark.foundation.errors import InputError
from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.effects import Motion
from damper.io.screening import band_edge, dominant_frequency

__all__ = ["decimation_factor", "decimate", "held_input", "INPUT_RULES", "windows", "coarse_pass", "Progress",
           "DEFAULT_COARSE_SAMPLES", "MIN_SAMPLES_PER_PERIOD", "MIN_SAMPLES_PER_BAND", "BAND_POWER",
           "WINDOW_TRIGGER", "LEAD_IN", "COARSE_SUBSTEP_SCALE"]

#: Factor on the models' sub-step tolerance while the coarse pass simulates (module docstring).
COARSE_SUBSTEP_SCALE = 4.0
#: Default cap on the fitted samples of the coarse pass (all tests together).
DEFAULT_COARSE_SAMPLES = 6000
#: Samples per period of the dominant frequency a decimated test keeps at least.
MIN_SAMPLES_PER_PERIOD = 100
#: The fastest coil-field time constant the coarse pass must still resolve [s] ...
FASTEST_LAG = 0.02
#: ... with at least this many samples.
MIN_SAMPLES_PER_LAG = 2
#: Samples per period of the velocity's bandwidth a decimated test keeps at least (four times
#: Nyquist's two: the motion is interpolated between samples through measured displacement and
#: velocity channels, not reconstructed; at 4 per period a Spencer-type model's force on the Dyke
#: recordings moved by 5.3 % of itself, at 8 by 3.7 %, and `ranran_50`'s loop took 75 s instead
#: of 29 s for a worse fit; docs/diagnosis.md) ...
MIN_SAMPLES_PER_BAND = 8
#: ... the bandwidth being the frequency below which this share of the velocity's power lies.
BAND_POWER = 0.99
#: The coarse pass fits windows of the tests once, decimated, they still hold more than this
#: many times the fitted samples asked for (:func:`windows`).
WINDOW_TRIGGER = 1.5
#: Seconds simulated before a window's first scored sample, so that the models' internal states
#: (hysteresis, field, series dashpot) forget their rest start: 25 field time constants of 10 ms.
LEAD_IN = 0.25
#: A window is at least this long [s] and holds at least this many periods of the test's
#: dominant frequency, so that each window shows whole strokes.
MIN_WINDOW = 2.0
MIN_WINDOW_PERIODS = 4


def decimation_factor(data: DiagnosisData, max_samples: int | None) -> int:
    """Keep one sample in ``q`` (see the module docstring); ``1`` when no decimation is needed.

    Parameters
    ----------
    data : DiagnosisData
    max_samples : int or None
        Cap on the fitted samples of all tests together (``None``: no decimation).

    Raises
    ------
    InputError
        ``max_samples`` is not a positive integer.
    """
    return _decimation(data, max_samples)[0]


def _decimation(data: DiagnosisData, max_samples: int | None) -> tuple[int, bool]:
    """:func:`decimation_factor`'s ``q``, and whether a test's velocity bandwidth is what bounds it
    (alone or with another bound) below the ``q`` the sample cap asks for (then the coarse pass may
    fit windows)."""
    if max_samples is None:
        return 1, False
    if isinstance(max_samples, bool) or not isinstance(max_samples, (int, np.integer)) or max_samples < 100:
        raise InputError(f"coarse_samples: expected None or an integer >= 100, got {max_samples!r}")
    fitted = sum(int(k.sum()) for k in data.train)
    q = int(math.ceil(fitted / int(max_samples)))
    if q <= 1:
        return 1, False
    limit, band_limit = q, q
    for m, tr, ho in zip(data.motions, data.train, data.heldout):
        dt = float(m.t[-1] - m.t[0]) / (m.n_samples - 1)
        f = dominant_frequency(m.t, m.x)
        per_period = (1.0 / f) / (MIN_SAMPLES_PER_PERIOD * dt) if f > 0 else limit
        per_lag = FASTEST_LAG / (MIN_SAMPLES_PER_LAG * dt)
        band = _velocity_band(m, tr | ho)
        # no velocity content (a test at rest): no band bound, not a tie with the others
        per_band = (1.0 / band) / (MIN_SAMPLES_PER_BAND * dt) if band > 0 else q
        limit = min(limit, int(per_period), int(per_lag))
        band_limit = min(band_limit, int(per_band))
    # the bandwidth stops the decimation also where another bound stops it at the same q: a
    # broadband record's "dominant" frequency is the peak of a flat spectrum and moves with the
    # span (ranran_50 at 3 kHz: 1.9 Hz; its first 21 s at 1 kHz: 8 Hz, where the period rule and
    # the bandwidth both ask for one sample in 1)
    limit, band_limit = max(1, limit), max(1, band_limit)
    return min(limit, band_limit), band_limit <= limit and band_limit < q


def _velocity_band(m: Motion, scored: np.ndarray) -> float:
    """The velocity's band edge [Hz] (:data:`BAND_POWER` of its power below,
    :func:`damper.io.screening.band_edge`) between the first and last scored samples: a flagged
    fault outside them (the Dyke recording's lurch at its end) is no content of the test."""
    idx = np.flatnonzero(scored)
    if idx.size < 4:
        return 0.0
    span = slice(int(idx[0]), int(idx[-1]) + 1)
    return band_edge(m.t[span], m.xdot[span], BAND_POWER)


def _take(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a)[idx])


#: How a decimated test holds the coil input over each of its steps (:func:`held_input`), by
#: what the base model does with it: ``"end"`` for a base that reads the input in its laws, ``"mean"``
#: for a base that filters it through its own field (the Spencer-type base).
INPUT_RULES = ("end", "mean")


def held_input(v: np.ndarray, idx: np.ndarray, rule: str = "end") -> np.ndarray:
    """The coil input a decimated test holds over each of its steps, so that the field the model
    sees keeps the full-rate test's timing.

    The models hold the input of a sample over the step that follows it
    (:func:`damper.models.response.simulate`: ``v[k]`` over ``(t_k, t_k+1]``). Holding
    ``v[idx[j]]`` over a decimated step, a test saw every change of the input up to ``q - 1``
    samples late, and a fitted field lag came out short (a probe's 8.41-ms lag at one sample in 5
    of 2 kHz: 6.44 ms; the Spencer-type base's 15-ms field at one in 4 of 1 kHz: 13.8 ms).
    Which value is right depends on where the input acts:

    ``"end"``
        The input the full-rate test holds over the last full-rate step before the next kept
        sample, ``v[idx[j+1] - 1]``: a base that reads the input in its laws computes the force
        at a sample with the input of the step that ends there, so the force at each kept sample
        is computed with the input the full-rate model uses (the ``voltage_lag`` effect's filter
        interpolates its input between samples and hands the base the result): the probe's lag
        then comes out at 8.415 ms.
    ``"mean"``
        The mean of the inputs the full-rate test holds over the decimated step: a base that
        integrates its own field over each step (Spencer et al.'s filter inside the kernel) is
        driven by the input's integral, which the mean keeps; a span where the input holds one
        value keeps that value exactly.

    Parameters
    ----------
    v : np.ndarray
        The test's coil input at every sample [V] (or [A]).
    idx : np.ndarray
        The samples kept, increasing, starting at 0 and ending at the last sample (:func:`decimate`).
    rule : {"end", "mean"}
        See above.
    """
    if rule not in INPUT_RULES:
        raise InputError(f"held_input: rule must be one of {', '.join(INPUT_RULES)}, got {rule!r}")
    v = np.asarray(v, dtype=np.float64)
    taken = _take(v, idx)
    if v.size == 0 or np.ptp(v) == 0.0:
        return taken
    if rule == "end":
        held = np.maximum(np.append(idx[1:], idx[-1] + 1) - 1, 0)
        return _take(v, np.minimum(held, v.size - 1))
    counts = np.diff(np.append(idx, v.size))
    mean = np.clip(np.add.reduceat(v, idx) / counts, v.min(), v.max())  # rounding kept in range
    steady = np.minimum.reduceat(v, idx) == np.maximum.reduceat(v, idx)
    return np.ascontiguousarray(np.where(steady, taken, mean))


def coarse_pass(data: DiagnosisData, q: int, max_samples: int | None = None,
                input_rule: str = "end") -> DiagnosisData:
    """The tests the loop's coarse pass fits: one sample in ``q`` (:func:`decimate`) and, even when
    ``q = 1``, simulated at :data:`COARSE_SUBSTEP_SCALE` times the models' sub-step tolerance;
    windows of them (:func:`windows`) where a test's velocity bandwidth stops the decimation (alone
    or at the same ``q`` as another bound) and they still hold more than :data:`WINDOW_TRIGGER`
    times ``max_samples`` fitted samples.

    Parameters
    ----------
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    q : int
        Keep one sample in ``q`` (≥ 1, :func:`decimation_factor`).
    max_samples : int or None
        The fitted samples asked for (``None``: no windows).
    input_rule : {"end", "mean"}
        How the decimated tests hold the coil input (:func:`held_input`).
    """
    if q > 1:
        coarse = decimate(data, q, input_rule)
    else:
        motions = tuple(dataclasses.replace(m, substep_scale=COARSE_SUBSTEP_SCALE) for m in data.motions)
        coarse = dataclasses.replace(data, motions=motions)
    if (max_samples is not None and _decimation(data, max_samples)[1]
            and sum(int(k.sum()) for k in coarse.train) > WINDOW_TRIGGER * max_samples):
        return windows(coarse, max_samples)
    return coarse


def decimate(data: DiagnosisData, q: int, input_rule: str = "end") -> DiagnosisData:
    """``data`` with one sample in ``q`` of every test (the first and last samples kept).

    The decimated motions are simulated at :data:`COARSE_SUBSTEP_SCALE` times the models' sub-step
    tolerance (``Motion.substep_scale``). The motion signals (the acceleration already smoothed on
    the full rate), the forces and the training and held-out masks are sampled alike, and the coil
    input is held as the base model needs it (:func:`held_input`); the coil-input levels (hence
    the law nodes and the input range) stay those of ``data``. ``q = 1`` returns ``data`` itself.

    Parameters
    ----------
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    q : int
        Keep one sample in ``q`` (≥ 1).
    input_rule : {"end", "mean"}
        How the decimated tests hold the coil input (:func:`held_input`).
    """
    if q <= 1:
        return data
    motions, forces, train, held = [], [], [], []
    for m, f, tr, ho in zip(data.motions, data.forces, data.train, data.heldout):
        idx = np.arange(0, m.n_samples, q)
        if idx[-1] != m.n_samples - 1:
            idx = np.append(idx, m.n_samples - 1)
        motions.append(Motion(_take(m.t, idx), _take(m.x, idx), _take(m.xdot, idx),
                              _take(m.xddot, idx), held_input(m.v, idx, input_rule), name=m.name,
                              substep_scale=COARSE_SUBSTEP_SCALE, origin=m.origin))
        forces.append(_take(f, idx))
        train.append(_take(tr, idx))
        held.append(_take(ho, idx))
    return DiagnosisData(tuple(motions), tuple(forces), tuple(train), tuple(held),
                         data.input_name, data.holdout, source_levels=data.levels(),
                         _source_nodes=data.nodes(), input_recorded=data.input_recorded)


def windows(data: DiagnosisData, max_samples: int) -> DiagnosisData:
    """Windows of the tests of ``data`` holding about ``max_samples`` fitted samples in all.

    The training span and the held-out span of each test (first to last sample of each) are
    each cut into ``k`` windows spread evenly over the span, each at least :data:`MIN_WINDOW`
    seconds and :data:`MIN_WINDOW_PERIODS` periods of the test's dominant frequency long, together
    about the share ``max_samples / fitted`` of the span (so the loop's held-out choices still
    see held-out samples in proportion); a span whose windows would cover most of it is one
    window, and a test both of whose spans are is kept whole. A window is a motion of its own: it
    is simulated from :data:`LEAD_IN` seconds before its first scored sample (moved back to the
    last sample where the displacement passes through its value at the test's start, when that
    is within as much again), the samples before are scored neither in the fit nor in the error,
    and its ``origin`` is the test's start. Windows with fewer than 5 scored samples are dropped.
    The coil-input levels stay those of ``data``.

    Parameters
    ----------
    data : DiagnosisData
        The (decimated) tests.
    max_samples : int
        The fitted samples asked for, all tests together.
    """
    fitted = sum(int(k.sum()) for k in data.train)
    share = min(1.0, max_samples / max(fitted, 1))
    motions, forces, train, held = [], [], [], []
    for m, f, tr, ho in zip(data.motions, data.forces, data.train, data.heldout):
        origin = float(m.t[0] if m.origin is None else m.origin)
        freq = dominant_frequency(m.t, m.x)
        length = max(MIN_WINDOW, MIN_WINDOW_PERIODS / freq if freq > 0 else MIN_WINDOW)
        crossing = np.flatnonzero(np.diff(np.signbit(m.x - m.x[0])))  # x passes its start value
        cuts = []  # (scored from, scored to) [s]
        windowed = False
        for part in (tr, ho):
            scored = np.flatnonzero(part)
            if scored.size == 0:
                continue
            t_a, t_b = float(m.t[scored[0]]), float(m.t[scored[-1]])
            count = int(math.ceil(share * (t_b - t_a) / length))
            if count * (length + LEAD_IN) >= 0.8 * (t_b - t_a):
                cuts.append((t_a, t_b))
                continue
            cuts += [(w0, w0 + length) for w0 in np.linspace(t_a, t_b - length, count)]
            windowed = True
        if not windowed:
            motions.append(m)
            forces.append(f)
            train.append(tr)
            held.append(ho)
            continue
        for w0, w1 in cuts:
            first = int(np.searchsorted(m.t, w0))
            stop = min(int(np.searchsorted(m.t, w1, side="right")), m.n_samples)
            lead = max(int(np.searchsorted(m.t, w0 - LEAD_IN, side="right")) - 1, 0)
            before = crossing[(crossing <= lead) & (m.t[crossing] >= w0 - 2.0 * LEAD_IN)]
            if before.size:
                lead = int(before[-1])
            keep = slice(lead, stop)
            tr_w = tr[keep].copy()
            ho_w = ho[keep].copy()
            tr_w[:first - lead] = False
            ho_w[:first - lead] = False
            if tr_w.sum() + ho_w.sum() < 5 or stop - lead < 2:
                continue
            motions.append(Motion(_take(m.t, keep), _take(m.x, keep), _take(m.xdot, keep),
                                  _take(m.xddot, keep), _take(m.v, keep),
                                  name=f"{m.name} [{w0 - origin:.1f}-{w1 - origin:.1f} s]",
                                  substep_scale=m.substep_scale, origin=origin))
            forces.append(np.ascontiguousarray(f[keep]))
            train.append(tr_w)
            held.append(ho_w)
    return DiagnosisData(tuple(motions), tuple(forces), tuple(train), tuple(held),
                         data.input_name, data.holdout, source_levels=data.levels(),
                         _source_nodes=data.nodes(), input_recorded=data.input_recorded)


class Progress:
    """One progress line per long step, with the elapsed time (see the module docstring).

    Parameters
    ----------
    sink : callable or None
        Receives each finished line (``sbib diagnose`` passes a printer to stderr); ``None``
        prints to ``stream``.
    stream : file, optional
        Where lines go without a ``sink`` (default ``sys.stderr``).
    quiet : bool
        Print nothing.
    """

    def __init__(self, sink: Callable[[str], None] | None = None, stream: TextIO | None = None,
                 quiet: bool = False) -> None:
        self.sink = sink
        self.stream = stream if stream is not None else sys.stderr
        self.quiet = bool(quiet)
        self.start = time.perf_counter()

    @property
    def elapsed(self) -> float:
        """Seconds since the loop started."""
        return time.perf_counter() - self.start

    def __call__(self, message: str) -> None:
        if self.quiet:
            return
        line = f"[{self.elapsed:6.1f} s] {message}"
        if self.sink is not None:
            self.sink(line)
            return
        self.stream.write(line + "\n")
        self.stream.flush()
