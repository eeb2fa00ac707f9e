"""The one fitting engine: bounded least squares on scaled parameters, and its covariance.

Every fit in the package goes through :func:`least_squares_fit`: the identification's joint
refinement (:mod:`damper.identification.refine`), its shared-parameter fit, the residual loop's
refits of augmented models (:func:`damper.diagnosis.augmented.refit`) and the hysteretic oscillator's
identification (:mod:`damper.hysteresis.identification`). It is
:func:`scipy.optimize.least_squares` with the trust-region reflective method (Branch, Coleman &
Li 1999) on parameters ``q`` scaled to order one (``x_scale = 1``), a forward-difference Jacobian
(or one of a given sparsity) and one tolerance for ``xtol``, ``ftol`` and ``gtol``.
:func:`jacobian_covariance` turns the Jacobian at the optimum into parameter covariances.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from scipy.optimize import least_squares

__all__ = ["least_squares_fit", "jacobian_covariance"]


def least_squares_fit(residuals: Callable[[np.ndarray], np.ndarray], q0: np.ndarray, lower: np.ndarray,
                      upper: np.ndarray, *, tolerance: float = 1e-10, diff_step: float = 1e-5,
                      max_nfev: int | None = None, jac_sparsity: Any = None):
    """Minimise ``sum(residuals(q)**2)`` over ``lower <= q <= upper`` from ``q0``.

    Parameters
    ----------
    residuals : callable
        ``q -> r`` (weighted residuals; scaled so that ``q`` is of order one).
    q0, lower, upper : ndarray
        Start and bounds of the scaled parameters.
    tolerance : float
        ``xtol = ftol = gtol`` of :func:`scipy.optimize.least_squares`.
    diff_step : float
        Relative step of the finite-difference Jacobian.
    max_nfev : int, optional
        Cap on residual evaluations.
    jac_sparsity : array or sparse matrix, optional
        Sparsity of the Jacobian (block fits).

    Returns
    -------
    scipy.optimize.OptimizeResult
        ``x`` (the scaled optimum), ``fun``, ``jac``, ``success``, ``message``, ``nfev``.
    """
    return least_squares(residuals, q0, bounds=(lower, upper), method="trf", jac_sparsity=jac_sparsity,
                         x_scale=1.0, diff_step=diff_step, xtol=tolerance, ftol=tolerance, gtol=tolerance,
                         max_nfev=max_nfev)


def jacobian_covariance(jac: np.ndarray, fun: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Covariance :math:`s^2 (J^T J)^{-1}` of the parameters ``p = scale * q`` at a least-squares optimum.

    Parameters
    ----------
    jac : ndarray, shape (m, p)
        Jacobian of the residuals with respect to the scaled parameters ``q``.
    fun : ndarray, shape (m,)
        Residuals at the optimum; :math:`s^2 = \\mathrm{RSS}/(m - p)`.
    scale : ndarray, shape (p,)
        ``p = scale * q``.

    Returns
    -------
    ndarray, shape (p, p)
        In the units of ``p`` (NaN where the pseudo-inverse fails).
    """
    jac = np.asarray(jac) / np.asarray(scale, dtype=float)[None, :]
    m, p = jac.shape
    s2 = float(np.sum(np.asarray(fun) ** 2)) / max(m - p, 1)
    try:
        return np.linalg.pinv(jac.T @ jac) * s2
    except np.linalg.LinAlgError:
        return np.full((p, p), np.nan)
