"""Resample a record onto another uniform time step.

Two cases, chosen by the ratio of the new step ``h`` to the record's step ``dt``:

* ``h <= dt`` (finer, or equal): **linear interpolation** between the record's samples. This
  is exactly the ground motion the simulator integrates (its first-order hold treats the
  acceleration as linear between samples, :mod:`benchmark.simulator.stepping`), so a record
  resampled this way and the original give the same building response up to the
  integration step's own error.
* ``h > dt`` (coarser): a zero-phase low-pass filter first (4th-order Butterworth run forward
  and backward, :func:`scipy.signal.sosfiltfilt`, corner at 80 % of the new Nyquist frequency
  ``1 / (2h)``), then linear interpolation: without it, content above the new Nyquist
  frequency would fold back into the band the building responds to (aliasing). The peak
  ground acceleration drops by what lay above the corner; the metadata says so.

The new grid starts at the record's first sample and ends at the last grid point not after
the record's last sample, ``t_k = k h``, ``k = 0 … floor((n − 1) dt / h)``. Units stay SI (m/s²).
"""

from __future__ import annotations

import math

import numpy as np

from benchmark.foundation.errors import InputError
from records.record import Record

__all__ = ["resample", "resampled_grid", "interpolate_onto", "STEP_RTOL"]

#: Two steps closer than this (relative) are the same step: no resampling.
STEP_RTOL = 1e-9


def resampled_grid(n_samples: int, dt: float, step: float) -> np.ndarray:
    """Times [s] of the new grid ``k * step`` covering ``(n_samples - 1) * dt`` (see module docstring).

    Parameters
    ----------
    n_samples : int
        Samples of the original record.
    dt : float
        The original sampling step [s].
    step : float
        The new step [s].

    Returns
    -------
    ndarray
        ``0, step, 2 step, ...`` up to the record's end (to :data:`STEP_RTOL`).
    """
    end = (n_samples - 1) * dt
    n_new = int(math.floor(end / step * (1 + STEP_RTOL) + STEP_RTOL)) + 1
    return np.arange(n_new) * step


def interpolate_onto(acceleration: np.ndarray, dt: float, step: float) -> np.ndarray:
    """Linear interpolation of ``acceleration`` sampled at ``dt`` onto the grid of ``step``.

    Parameters
    ----------
    acceleration : ndarray, shape (n,) or (n, m)
        Ground acceleration, any units (kept).
    dt : float
        Its sampling step [s].
    step : float
        The new step [s] (:func:`resampled_grid`).

    Returns
    -------
    ndarray, shape (n_new, m)
        C-contiguous, same units.
    """
    acc = _acc_2d(acceleration)
    t_old = np.arange(acc.shape[0]) * dt
    t_new = resampled_grid(acc.shape[0], dt, step)
    t_new = np.minimum(t_new, t_old[-1])  # the last point may sit a rounding error past the end
    out = np.empty((t_new.size, acc.shape[1]))
    for c in range(acc.shape[1]):
        out[:, c] = np.interp(t_new, t_old, acc[:, c])
    return out


def _acc_2d(acceleration: np.ndarray) -> np.ndarray:
    acc = np.asarray(acceleration, dtype=float)
    return acc[:, None] if acc.ndim == 1 else acc


def _low_pass(acc: np.ndarray, dt: float, corner_hz: float) -> np.ndarray:
    from scipy.signal import butter, sosfiltfilt  # scipy.signal is slow to import; only a coarsening needs it

    sos = butter(4, corner_hz, btype="low", fs=1.0 / dt, output="sos")
    padlen = min(acc.shape[0] - 1, 3 * (2 * len(sos) + 1))
    return sosfiltfilt(sos, acc, axis=0, padlen=padlen)


def resample(record: Record, step: float) -> Record:
    """The record on a uniform grid of step ``step`` [s] (module docstring for the method).

    Parameters
    ----------
    record : Record
        Any record [m/s²].
    step : float
        New time step [s], positive and finite; at most half the record's length.

    Returns
    -------
    Record
        Same name, labels, source and synthetic flag; ``dt = step``; ``metadata["resampled"]``
        says from which step, to which step and how (and the original PGA when a low-pass was
        applied). A ``step`` equal to the record's step returns the record itself.

    Raises
    ------
    InputError
        A step that is not positive and finite, or so long that the record would keep fewer
        than two samples.
    """
    try:
        h = float(step)
    except (TypeError, ValueError):
        raise InputError(f"resample step {step!r}: expected a positive time step in s") from None
    if not (math.isfinite(h) and h > 0):
        raise InputError(f"resample step {step!r}: expected a positive finite time step in s")
    dt = record.dt
    if abs(h - dt) <= STEP_RTOL * dt:
        return record
    if (record.n_samples - 1) * dt < h * (1 - STEP_RTOL):
        raise InputError(f"record {record.name!r}: step {h:g} s is longer than the record "
                         f"({(record.n_samples - 1) * dt:g} s between its first and last samples); "
                         "expected a step that keeps at least two samples")
    acc = np.asarray(record.acceleration, dtype=float)
    if h < dt:
        method = f"linear interpolation from {dt:g} s to {h:g} s"
    else:
        corner = 0.8 / (2.0 * h)
        acc = _low_pass(acc, dt, corner)
        method = (f"zero-phase 4th-order Butterworth low-pass at {corner:.4g} Hz (80 % of the new Nyquist "
                  f"frequency), then linear interpolation from {dt:g} s to {h:g} s; PGA "
                  + " / ".join(f"{p:.4g}" for p in record.pga) + " m/s2 before, "
                  + " / ".join(f"{p:.4g}" for p in np.max(np.abs(acc), axis=0)) + " m/s2 after the filter")
    new = interpolate_onto(acc, dt, h)
    meta = dict(record.metadata)
    meta["resampled"] = method
    meta["resampled_from_dt_s"] = dt
    return record.replace(dt=h, acceleration=new, metadata=meta)
