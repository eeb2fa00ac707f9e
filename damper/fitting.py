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

__all__ = ["least_squares_fit", "jacobian_covariance", "DEFAULT_STALL"]

#: A refit stops once 5 iterations in a row lowered its training cost by less than 0.1 % in all
#: (a relative RMS change of 0.05 %, 40 times below the residual loop's smallest gain worth an
#: effect, :data:`damper.diagnosis.selection.DEFAULT_MIN_GAIN`): at that pace it would need
#: hundreds of iterations to pay. On the UTFSM 1 A tests a joint refit with an inertial term
#: crawled like that for 55 iterations (8 s, a third of the loop) and lowered the cost by 0.6 %;
#: on the Dyke damper's ``ranran_50`` the Spencer base's refinement crawled for 200 s and its
#: three-node laws for 120 s (docs/diagnosis.md). The loop's trials and its base fits use it.
DEFAULT_STALL = (5, 1e-3)


def least_squares_fit(residuals: Callable[[np.ndarray], np.ndarray], q0: np.ndarray, lower: np.ndarray,
                      upper: np.ndarray, *, tolerance: float = 1e-10, diff_step: float = 1e-5,
                      max_nfev: int | None = None, jac_sparsity: Any = None,
                      stall: tuple[int, float] | None = None):
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
    stall : (int, float), optional
        ``(k, rel)``: stop once ``k`` iterations in a row have lowered the cost by less than
        ``rel`` of it in all (a crawl along an ill-conditioned valley, e.g. an inertial force
        traded against a pre-yield stiffness). The result is then the last iterate, with
        ``status`` -2 and ``success`` False, and its message says so. None: the tolerances and
        ``max_nfev`` alone end the fit.

    Returns
    -------
    scipy.optimize.OptimizeResult
        ``x`` (the scaled optimum), ``fun``, ``jac``, ``success``, ``message``, ``nfev``.
    """
    callback = None
    if stall is not None:
        window, rel = int(stall[0]), float(stall[1])
        if window < 1 or not rel > 0.0:
            raise ValueError(f"stall: expected (k >= 1, rel > 0), got {stall}")
        costs: list[float] = []

        def callback(intermediate_result):
            costs.append(float(intermediate_result.cost))
            if len(costs) > window and costs[-window - 1] - costs[-1] < rel * costs[-window - 1]:
                raise StopIteration

    sol = least_squares(residuals, q0, bounds=(lower, upper), method="trf", jac_sparsity=jac_sparsity,
                        x_scale=1.0, diff_step=diff_step, xtol=tolerance, ftol=tolerance, gtol=tolerance,
                        max_nfev=max_nfev, callback=callback)
    if stall is not None and sol.status == -2:
        sol.message = (f"stalled: the cost fell by less than {stall[1]:g} of itself over the last "
                       f"{stall[0]} iterations")
    return sol


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
