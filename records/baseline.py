"""Optional baseline correction (off by default: the benchmark is reproduced as distributed).

An uncorrected record whose acceleration carries a small offset or slow trend (e.g. the
benchmark copies of ``jiji.txt`` and column 2 of ``rinaldi.txt``) integrates to a velocity
that does not return to zero and a displacement that drifts by metres. The correction here
is the classical polynomial one: integrate the record to displacement :math:`d(t)`, fit

.. math:: p(t) = \\sum_{j=2}^{m} c_j t^j

by least squares (no constant or linear term, so :math:`p(0) = \\dot p(0) = 0` and the
record still starts from rest) under the constraint :math:`\\dot p(T) = v(T)` (the ground is
at rest at the end; a permanent displacement is allowed), and subtract its second derivative
from the acceleration:

.. math:: a_c(t) = a(t) - \\ddot p(t) = a(t) - \\sum_{j=2}^{m} j (j-1) c_j t^{j-2}.

The corrected displacement is :math:`d - p`. Default degree 3 (removes an offset and a
linear trend in acceleration). Boore & Bommer (2005)
discuss this and other schemes; none recovers true permanent displacement.

Reference
---------
Boore, D. M. & Bommer, J. J. (2005) Processing of strong-motion accelerograms: needs,
options and consequences. *Soil Dyn. Earthq. Eng.* 25, 93–115.
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import InputError
from records.record import Record, cumulative_trapezoid

__all__ = ["baseline_correct", "baseline_correction_acceleration", "end_condition_correction"]


def baseline_correction_acceleration(acceleration: np.ndarray, dt: float, degree: int = 3) -> np.ndarray:
    """Return the acceleration correction :math:`\\ddot p(t)` [same units] to subtract, per component.

    Parameters
    ----------
    acceleration : ndarray, shape (n,) or (n, m)
        Acceleration.
    dt : float
        Time step [s].
    degree : int
        Degree m ≥ 2 of the displacement polynomial (the correction has degree m − 2).

    Notes
    -----
    The fit is done on the discrete integrals actually used (trapezoidal rule): each basis
    acceleration :math:`j(j-1)t^{j-2}` is integrated the same way as the record, and the
    constraint makes the corrected final velocity zero to rounding.
    """
    if int(degree) != degree or degree < 2 or degree > 8:
        raise InputError(f"baseline correction degree = {degree}; expected an integer between 2 and 8")
    degree = int(degree)
    a = np.asarray(acceleration, dtype=float)
    squeeze = a.ndim == 1
    a2 = a[:, None] if squeeze else a
    n = a2.shape[0]
    if n < degree + 2:
        raise InputError(f"baseline correction: {n} samples are too few for degree {degree}")
    tau = np.arange(n) / (n - 1)  # scaled time keeps the system well conditioned
    powers = np.arange(2, degree + 1)
    basis = (powers * (powers - 1))[None, :] * tau[:, None] ** (powers - 2)[None, :]   # p'' in scaled time
    basis_v = cumulative_trapezoid(basis, dt)
    basis_d = cumulative_trapezoid(basis_v, dt)
    v = cumulative_trapezoid(a2, dt)
    d = cumulative_trapezoid(v, dt)
    # minimise |basis_d c - d|^2 subject to g·c = v(T), g = basis_v[-1]: null-space method
    g = basis_v[-1]
    c0 = np.outer(g / (g @ g), v[-1])                      # particular solution, (k, m)
    null = np.linalg.svd(g[None, :])[2][1:].T              # (k, k-1), orthonormal, g·null = 0
    coef = c0
    if null.shape[1]:
        z = np.linalg.lstsq(basis_d @ null, d - basis_d @ c0, rcond=None)[0]
        coef = c0 + null @ z
    corr = basis @ coef
    return corr[:, 0] if squeeze else corr


def baseline_correct(record: Record, degree: int = 3) -> Record:
    """Return ``record`` with a polynomial baseline correction applied to every component.

    Parameters
    ----------
    record : Record
        The record.
    degree : int
        Degree of the displacement polynomial (see the module docstring).

    Returns
    -------
    Record
        The corrected record; its metadata gains ``baseline_correction`` describing it.
    """
    corr = baseline_correction_acceleration(record.acceleration, record.dt, degree)
    meta = dict(record.metadata)
    meta["baseline_correction"] = f"polynomial of degree {degree} fitted to displacement (least squares)"
    return record.replace(acceleration=record.acceleration - corr, metadata=meta)


def end_condition_correction(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """Return the linear correction :math:`c_0 + c_1 t` that brings final velocity and displacement to zero.

    :math:`c_0, c_1` solve the 2×2 linear system that makes the trapezoidal integrals of
    :math:`a - c_0 - c_1 t` end at :math:`v(T) = d(T) = 0` exactly (the same discrete
    integration as :meth:`records.Record.velocity`). Used for generated noise, which has no
    permanent displacement; not suitable for records with a true static offset.

    Parameters
    ----------
    acceleration : ndarray, shape (n,) or (n, m)
        Acceleration.
    dt : float
        Time step [s].
    """
    a = np.asarray(acceleration, dtype=float)
    squeeze = a.ndim == 1
    a2 = a[:, None] if squeeze else a
    n = a2.shape[0]
    t = np.arange(n) * dt
    basis = np.column_stack([np.ones(n), t])

    def ends(x: np.ndarray) -> np.ndarray:
        v = cumulative_trapezoid(x, dt)
        return np.vstack([v[-1], cumulative_trapezoid(v, dt)[-1]])

    coef = np.linalg.solve(ends(basis), ends(a2))  # (2, m)
    corr = basis @ coef
    return corr[:, 0] if squeeze else corr
