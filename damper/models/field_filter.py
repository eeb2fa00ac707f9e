"""The first-order field filter of an MR damper: :math:`\\tau\\dot u = v - u`.

The magnetic field the fluid sees (``u``) follows the commanded voltage or current (``v``) with a
first-order lag (Spencer et al. 1997, :math:`\\dot u = -\\eta(u - v)`, :math:`\\tau = 1/\\eta`):
the seed paper's refinement (:mod:`damper.identification.voltage_lag`), the residual loop's
``voltage_lag`` effect (:mod:`damper.diagnosis.effects`) and the earthquake validation filter
command histories with it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from benchmark.foundation.errors import InputError, ParameterError

__all__ = ["first_order_filter"]


@numba.njit(cache=True)
def _first_order_filter(t, v, tau, out):
    out[0] = v[0]
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        if tau <= 0.0:
            out[k + 1] = v[k + 1]
            continue
        e = math.exp(-h / tau)
        # exact solution of tau u' = v - u for v linear over the step
        out[k + 1] = e * out[k] + (1.0 - e) * v[k] + (v[k + 1] - v[k]) * (1.0 - tau * (1.0 - e) / h)


def first_order_filter(t: np.ndarray, v: np.ndarray, tau: float) -> np.ndarray:
    """Output of :math:`\\tau\\dot u = v - u`, :math:`u(t_0) = v(t_0)`, for ``v`` linear between samples.

    Over a step of length :math:`h` with :math:`e = e^{-h/\\tau}`:

    .. math:: u_{k+1} = e\\,u_k + (1-e)\\,v_k + (v_{k+1}-v_k)\\Big(1 - \\frac{\\tau(1-e)}{h}\\Big),

    exact for piecewise-linear input; ``tau = 0`` returns ``v``.

    Parameters
    ----------
    t : ndarray (n,)
        Strictly increasing times [s].
    v : ndarray (n,)
        Input samples.
    tau : float
        Time constant [s], >= 0.

    Returns
    -------
    ndarray (n,)
    """
    t = np.ascontiguousarray(t, dtype=np.float64)
    v = np.ascontiguousarray(v, dtype=np.float64)
    if t.shape != v.shape or t.ndim != 1:
        raise InputError(f"first_order_filter: t and v must be 1-D of equal length, got "
                         f"{t.shape} and {v.shape}")
    if not (math.isfinite(tau) and tau >= 0.0):
        raise ParameterError(f"voltage_lag.tau: expected a finite value >= 0 s, got {tau!r}")
    out = np.empty_like(v)
    _first_order_filter(t, v, float(tau), out)
    return out
