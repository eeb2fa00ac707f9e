r"""Biaxial Bouc-Wen (Park–Wen) hysteresis shared by the lead-rubber and friction-pendulum bearings.

The dimensionless hysteretic vector :math:`z = (z_x, z_y)` of one bearing evolves with the
bearing's displacement :math:`u = (u_x, u_y)` as (Park, Wen & Ang 1986)

.. math::

    Y \dot z_x &= A \dot u_x - z_x^2 (\gamma\,\mathrm{sgn}(\dot u_x z_x) + \beta)\,\dot u_x
                 - z_x z_y (\gamma\,\mathrm{sgn}(\dot u_y z_y) + \beta)\,\dot u_y \\
    Y \dot z_y &= A \dot u_y - z_x z_y (\gamma\,\mathrm{sgn}(\dot u_x z_x) + \beta)\,\dot u_x
                 - z_y^2 (\gamma\,\mathrm{sgn}(\dot u_y z_y) + \beta)\,\dot u_y

with :math:`Y` the yield displacement [m]. With :math:`A = \beta + \gamma = 1` the resultant
:math:`\|z\|` saturates at 1 along any sliding direction (the biaxial interaction: on a circular
orbit the resultant force saturates at the yield/friction force, not :math:`\sqrt 2` times it).

The model is rate independent: :math:`dz/du` depends on the direction of motion only. The
kernel therefore integrates in the path parameter :math:`s \in [0, 1]` of one structural
step, along the cubic Hermite path through :math:`(u_0, \dot u_0)` and :math:`(u_1, \dot u_1)`
(so the path is consistent with both end displacements and velocities), with classical RK4
on :math:`N` equal sub-steps,

.. math::

    N = \left\lceil \frac{\rho\,(L_x + L_y)}{\mathrm{tol}} \right\rceil,\qquad
    \rho = \frac{\max(A,\ 2(\beta + \gamma))}{Y},\qquad
    L_j = \max\!\left(|\Delta u_j|,\ \tfrac12(|\dot u_{j,0}| + |\dot u_{j,1}|)\,\Delta t\right),

the displacement-based rule of DOMAIN.md §5 (:math:`\rho` bounds
:math:`\|\partial (dz/du) / \partial z\|`, so ``tol`` is the largest product of the local
stiffness and the sub-step length; RK4 gives force errors <= 3e-5 (tol = 0.5, the default) to ~1e-6
(tol = 0.1) relative on the oracle tests, and is
stable up to ~2.8).

References
----------
Park, Y. J., Wen, Y. K., Ang, A. H.-S. (1986). Random vibration of hysteretic systems under
bi-directional ground motions. *Earthquake Eng. Struct. Dyn.* 14, 543–557.
Nagarajaiah, S., Reinhorn, A. M., Constantinou, M. C. (1991). Nonlinear dynamic analysis of
3-D base-isolated structures. *J. Struct. Eng.* 117(7), 2035–2054.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["park_wen_rates", "park_wen_advance", "park_wen_substeps", "MAX_SUBSTEPS"]

#: Hard cap on the sub-steps of one structural step (guards against NaN/inf path lengths).
MAX_SUBSTEPS = 200_000


@numba.njit(cache=True, inline="always")
def _sign(x: float) -> float:
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@numba.njit(cache=True)
def park_wen_rates(zx: float, zy: float, dux: float, duy: float,
                   yield_displacement: float, A: float, beta: float, gamma: float):
    r"""Return :math:`(\dot z_x, \dot z_y)` for displacement rates ``(dux, duy)`` (any time scale).

    Parameters
    ----------
    zx, zy : float
        Hysteretic state (dimensionless).
    dux, duy : float
        Displacement rates [m/s] (or displacement increments [m]: the model is rate independent).
    yield_displacement, A, beta, gamma : float
        Park–Wen parameters (``yield_displacement`` = Y [m]).
    """
    gx = gamma * _sign(dux * zx) + beta
    gy = gamma * _sign(duy * zy) + beta
    rzx = (A * dux - zx * zx * gx * dux - zx * zy * gy * duy) / yield_displacement
    rzy = (A * duy - zx * zy * gx * dux - zy * zy * gy * duy) / yield_displacement
    return rzx, rzy


@numba.njit(cache=True)
def park_wen_substeps(ux0: float, uy0: float, ux1: float, uy1: float,
                      vx0: float, vy0: float, vx1: float, vy1: float, dt: float,
                      yield_displacement: float, A: float, beta: float, gamma: float,
                      tolerance: float) -> int:
    """Number of RK4 sub-steps for one structural step (the rule in the module docstring).

    Parameters
    ----------
    ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt : float
        Path of the step (displacements [m], velocities [m/s], duration [s]).
    yield_displacement, A, beta, gamma : float
        Park–Wen parameters (Y [m]).
    tolerance : float
        Largest product of the hysteretic stiffness bound and the sub-step length.
    """
    lx = max(abs(ux1 - ux0), 0.5 * (abs(vx0) + abs(vx1)) * dt)
    ly = max(abs(uy1 - uy0), 0.5 * (abs(vy0) + abs(vy1)) * dt)
    rho = max(A, 2.0 * (beta + gamma)) / yield_displacement
    x = rho * (lx + ly) / tolerance
    if not (x <= MAX_SUBSTEPS):  # also catches NaN: the tolerance cannot be met
        return MAX_SUBSTEPS + 1
    n = int(math.ceil(x))
    return max(n, 1)


@numba.njit(cache=True, inline="always")
def _hermite_rate(s: float, u0: float, u1: float, d0: float, d1: float) -> float:
    # derivative w.r.t. s of the cubic Hermite through (u0, d0) at s=0 and (u1, d1) at s=1,
    # where d = velocity * dt
    return ((6.0 * s * s - 6.0 * s) * (u0 - u1)
            + (3.0 * s * s - 4.0 * s + 1.0) * d0
            + (3.0 * s * s - 2.0 * s) * d1)


@numba.njit(cache=True)
def park_wen_advance(state: np.ndarray, offset: int,
                     ux0: float, uy0: float, ux1: float, uy1: float,
                     vx0: float, vy0: float, vx1: float, vy1: float, dt: float,
                     yield_displacement: float, A: float, beta: float, gamma: float,
                     tolerance: float) -> int:
    """Advance ``state[offset:offset+2]`` = (z_x, z_y) in place along one step's Hermite path.

    Parameters
    ----------
    state : ndarray
        State array holding (z_x, z_y) at ``offset``.
    offset : int
    ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt : float
        Path of the step (displacements [m], velocities [m/s], duration [s]).
    yield_displacement, A, beta, gamma : float
        Park–Wen parameters (Y [m]).
    tolerance : float
        Sub-step tolerance (:func:`park_wen_substeps`).

    Returns
    -------
    int
        The number of sub-steps used (for diagnostics).
    """
    n = park_wen_substeps(ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt,
                          yield_displacement, A, beta, gamma, tolerance)
    if n > MAX_SUBSTEPS:
        # More than MAX_SUBSTEPS sub-steps would be needed: poison the state so that the caller
        # stops with a NumericalError rather than return an inaccurate force.
        state[offset] = math.nan
        state[offset + 1] = math.nan
        return n
    zx = state[offset]
    zy = state[offset + 1]
    dx0 = vx0 * dt
    dx1 = vx1 * dt
    dy0 = vy0 * dt
    dy1 = vy1 * dt
    h = 1.0 / n
    # direction of motion at the RK4 nodes (the midpoint is shared by stages 2 and 3; the end
    # of one sub-step is the start of the next)
    cx = dx0
    cy = dy0
    for i in range(n):
        s = i * h
        ax = cx
        ay = cy
        bx = _hermite_rate(s + 0.5 * h, ux0, ux1, dx0, dx1)
        by = _hermite_rate(s + 0.5 * h, uy0, uy1, dy0, dy1)
        cx = _hermite_rate(s + h, ux0, ux1, dx0, dx1)
        cy = _hermite_rate(s + h, uy0, uy1, dy0, dy1)
        k1x, k1y = park_wen_rates(zx, zy, ax, ay, yield_displacement, A, beta, gamma)
        k2x, k2y = park_wen_rates(zx + 0.5 * h * k1x, zy + 0.5 * h * k1y, bx, by,
                                  yield_displacement, A, beta, gamma)
        k3x, k3y = park_wen_rates(zx + 0.5 * h * k2x, zy + 0.5 * h * k2y, bx, by,
                                  yield_displacement, A, beta, gamma)
        k4x, k4y = park_wen_rates(zx + h * k3x, zy + h * k3y, cx, cy,
                                  yield_displacement, A, beta, gamma)
        zx += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
        zy += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y)
    state[offset] = zx
    state[offset + 1] = zy
    return n
