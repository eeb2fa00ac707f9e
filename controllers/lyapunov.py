"""Lyapunov control of MR dampers (Jansen & Dyke 2000), on the LQG design's state estimate.

With the Lyapunov function :math:`V = \\tfrac12 x^T P x` of the reduced building model, where
:math:`A^T P + P A = -Q` and :math:`Q = C_z^T W_z C_z` the design's output weighting
(:mod:`controllers.clipped_optimal`), the rate of change contains :math:`x^T P B f`; every
device is switched on when its force lowers it:

.. math:: v_i = V_{max} H\\big(-\\hat x^T P B_i\\, f_i\\big),

with :math:`\\hat x` the Kalman filter's current estimate. The compiled controller's "desired
force" output carries the sign term :math:`B_i^T P \\hat x` (law 3 of :mod:`controllers.compiled`).

References
----------
Jansen L.M., Dyke S.J. (2000) Semiactive control strategies for MR dampers: comparative
study. J. Eng. Mech. 126(8):795–803.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from benchmark.foundation.errors import NumericalError
from controllers.base import register_controller
from controllers.clipped_optimal import ClippedOptimal, LQGDesign, regulated_outputs
from controllers.compiled import LAW_LYAPUNOV
from controllers.lqg import observer_controller

__all__ = ["Lyapunov", "lyapunov_matrix"]


def lyapunov_matrix(A: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, float]:
    """Solve :math:`A^T P + P A = -Q`; return ``P`` and the relative residual.

    Parameters
    ----------
    A : ndarray (n, n)
        Hurwitz state matrix.
    Q : ndarray (n, n)
        Positive-definite weight.

    Raises
    ------
    NumericalError
        If ``A`` is not Hurwitz (no positive-definite solution).
    """
    if np.max(np.linalg.eigvals(A).real) >= 0:
        raise NumericalError("Lyapunov design: the design model is not asymptotically stable",
                             hint="use a model with damped isolation")
    P = scipy.linalg.solve_continuous_lyapunov(A.T, -Q)
    P = 0.5 * (P + P.T)
    residual = np.linalg.norm(A.T @ P + P @ A + Q) / max(np.linalg.norm(Q), np.finfo(float).tiny)
    return P, float(residual)


@register_controller
class Lyapunov(ClippedOptimal):
    """Lyapunov controller (``lyapunov``): parameters as :class:`ClippedOptimal` (the weights define Q).

    Parameters
    ----------
    weights : LQGWeights, optional
        Design weights (defaults in :class:`~controllers.clipped_optimal.LQGWeights`); they also define Q.
    plant : LinearPlant, optional
        Design model; default: :func:`controllers.plant.building_plant` of the run's building.
    voltage : float, optional
        Commanded "on" voltage [V]; default: each device's maximum.
    check_fit : bool, optional
        Compute the estimator fit at design time (shown in :meth:`LQGDesign.report`).
    dead_band : float, optional
        Dead band on the desired force as a fraction of the force scale f₀, in [0, 1) (default
        :data:`~controllers.clipped_optimal.DEFAULT_DEAD_BAND`).
    """

    name = "lyapunov"
    law_id = LAW_LYAPUNOV

    def controller_matrices(self, design: LQGDesign) -> tuple:
        p = design.reduced.plant
        Cz, _, Wz = regulated_outputs(p, design.force_rows.size, design.weights)
        P, residual = lyapunov_matrix(p.A, Cz.T @ Wz @ Cz)
        self.lyapunov_residual = residual
        G = p.B.T @ P
        Cs, Ds = p.C[design.sensor_rows], p.D[design.sensor_rows]
        Ad, Bd, _ = p.discretise(design.control_step)
        return observer_controller(Ad, Bd, Cs, Ds, design.kalman["M"], G, design.sensor_rows,
                                   design.force_rows, design.n_meas)
