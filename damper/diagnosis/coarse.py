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
from damper.diagnosis.dataset import DiagnosisData, _dominant_frequency
from damper.diagnosis.effects import Motion

__all__ = ["decimation_factor", "decimate", "coarse_pass", "Progress", "DEFAULT_COARSE_SAMPLES",
           "MIN_SAMPLES_PER_PERIOD", "COARSE_SUBSTEP_SCALE"]

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
    if max_samples is None:
        return 1
    if isinstance(max_samples, bool) or not isinstance(max_samples, (int, np.integer)) or max_samples < 100:
        raise InputError(f"coarse_samples: expected None or an integer >= 100, got {max_samples!r}")
    fitted = sum(int(k.sum()) for k in data.train)
    q = int(math.ceil(fitted / int(max_samples)))
    if q <= 1:
        return 1
    limit = q
    for m in data.motions:
        dt = float(m.t[-1] - m.t[0]) / (m.n_samples - 1)
        f = _dominant_frequency(m.t, m.x)
        per_period = (1.0 / f) / (MIN_SAMPLES_PER_PERIOD * dt) if f > 0 else limit
        per_lag = FASTEST_LAG / (MIN_SAMPLES_PER_LAG * dt)
        limit = min(limit, int(per_period), int(per_lag))
    return max(1, limit)


def _take(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a)[idx])


def coarse_pass(data: DiagnosisData, q: int) -> DiagnosisData:
    """The tests the loop's coarse pass fits: one sample in ``q`` (:func:`decimate`) and, even when
    ``q = 1``, simulated at :data:`COARSE_SUBSTEP_SCALE` times the models' sub-step tolerance.

    Parameters
    ----------
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    q : int
        Keep one sample in ``q`` (≥ 1, :func:`decimation_factor`).
    """
    if q > 1:
        return decimate(data, q)
    motions = tuple(dataclasses.replace(m, substep_scale=COARSE_SUBSTEP_SCALE) for m in data.motions)
    return dataclasses.replace(data, motions=motions)


def decimate(data: DiagnosisData, q: int) -> DiagnosisData:
    """``data`` with one sample in ``q`` of every test (the first and last samples kept).

    The decimated motions are simulated at :data:`COARSE_SUBSTEP_SCALE` times the models' sub-step
    tolerance (``Motion.substep_scale``). The motion signals (the acceleration already smoothed on
    the full rate), the forces and the training and held-out masks are sampled alike; the
    coil-input levels (hence the law nodes and the input range) stay those of ``data``. ``q = 1``
    returns ``data`` itself.

    Parameters
    ----------
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    q : int
        Keep one sample in ``q`` (≥ 1).
    """
    if q <= 1:
        return data
    motions, forces, train, held = [], [], [], []
    for m, f, tr, ho in zip(data.motions, data.forces, data.train, data.heldout):
        idx = np.arange(0, m.n_samples, q)
        if idx[-1] != m.n_samples - 1:
            idx = np.append(idx, m.n_samples - 1)
        motions.append(Motion(_take(m.t, idx), _take(m.x, idx), _take(m.xdot, idx),
                              _take(m.xddot, idx), _take(m.v, idx), name=m.name,
                              substep_scale=COARSE_SUBSTEP_SCALE))
        forces.append(_take(f, idx))
        train.append(_take(tr, idx))
        held.append(_take(ho, idx))
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
