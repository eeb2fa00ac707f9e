r"""Friction pendulum bearing with velocity-dependent friction and biaxial interaction.

In each horizontal direction :math:`j \in \{x, y\}` (Mokha, Constantinou & Reinhorn 1990;
Constantinou, Mokha & Reinhorn 1990; 3D-BASIS, Nagarajaiah et al. 1991)

.. math::

    f_j = \frac{W}{R}\, u_j + c\,\dot u_j + \mu(\|\dot u\|)\, W\, z_j,\qquad
    \mu(v) = f_\max - (f_\max - f_\min)\, e^{-a v}

with :math:`W` the vertical load carried by the bearing [N], :math:`R` the radius of the
concave surface [m] (pendulum period :math:`2\pi\sqrt{R/g}` when the bearing carries its own
mass), :math:`\|\dot u\| = \sqrt{\dot u_x^2 + \dot u_y^2}` the sliding speed [m/s], and
:math:`z` the biaxial Park–Wen vector of :mod:`benchmark.simulator.isolation.park_wen` with a small
yield displacement :math:`Y` (the pre-sliding elastic deformation; a few tenths of a mm)
that makes :math:`z` a smooth, biaxially consistent sign function of the sliding direction.
The vertical load is taken as constant (no overturning or vertical-acceleration effect).

Linear part (handled exactly by the building): :math:`k_\mathrm{lin} = W/R`,
:math:`c_\mathrm{lin} = c`. The kernel returns the friction force
:math:`\mu(\|\dot u\|) W z` at the end of the step.

Parameter array (``to_array()``)::

    [W/R, c, W, mu_max, mu_min, a, Y, A, beta, gamma, substep_tolerance]

States: ``[z_x, z_y]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.simulator.isolation.base import (BearingParameters, KERNEL_FRICTION_PENDULUM, register_bearing, require_nonnegative, require_positive,
                                      require_range)
from benchmark.simulator.isolation.park_wen import (lockstep_coefficients, park_wen_advance, park_wen_closed_form, park_wen_rates,
                                                   park_wen_tangent)

__all__ = ["FrictionPendulumBearing", "N_PARAMS", "friction_pendulum_step",
           "friction_pendulum_step_closed_form", "friction_coefficient"]

N_PARAMS = 11


def friction_coefficient(speed: float | np.ndarray, mu_max: float, mu_min: float,
                         rate_parameter: float) -> float | np.ndarray:
    r"""Sliding friction coefficient :math:`\mu(v) = f_\max - (f_\max - f_\min) e^{-a |v|}`.

    Parameters
    ----------
    speed : float or ndarray
        Sliding speed :math:`v` [m/s].
    mu_max, mu_min : float
        Coefficients at high and vanishing speed.
    rate_parameter : float
        :math:`a` [s/m].
    """
    return mu_max - (mu_max - mu_min) * np.exp(-rate_parameter * np.abs(speed))


@register_bearing
@dataclass(frozen=True)
class FrictionPendulumBearing(BearingParameters):
    """Friction pendulum bearing.

    Parameters
    ----------
    weight : float
        Vertical load W carried by the bearing [N] (> 0).
    radius : float
        Radius R of the concave sliding surface [m] (> 0).
    mu_max, mu_min : float
        Friction coefficients at high and at vanishing sliding speed, 0 <= mu_min <= mu_max < 1.
    rate_parameter : float
        a [s/m] (>= 0): how fast friction rises from mu_min to mu_max with sliding speed.
    yield_displacement : float
        Y [m] (> 0): pre-sliding displacement of the Park–Wen element (default 0.5 mm).
    c : float
        Additional viscous damping [N·s/m] (>= 0, default 0).
    A, beta, gamma : float
        Park–Wen shape parameters (defaults 1, 0.1, 0.9; gamma >= beta, beta + gamma > 0).
    substep_tolerance : float
        Sub-step tolerance of the kernel (default 0.75; see :class:`LeadRubberBearing`).
    """

    weight: float
    radius: float
    mu_max: float
    mu_min: float
    rate_parameter: float
    yield_displacement: float = 5.0e-4
    c: float = 0.0
    A: float = 1.0
    beta: float = 0.1
    gamma: float = 0.9
    substep_tolerance: float = 0.75

    name: ClassVar[str] = "friction-pendulum"
    kernel: ClassVar[int] = KERNEL_FRICTION_PENDULUM
    n_states: ClassVar[int] = 2

    def __post_init__(self) -> None:
        require_positive(self, "weight")
        require_positive(self, "radius")
        require_range(self, "mu_max", 0.0, 1.0, high_open=True)
        require_range(self, "mu_min", 0.0, 1.0, high_open=True)
        if self.mu_min > self.mu_max:
            raise ParameterError(f"FrictionPendulumBearing.mu_min = {self.mu_min!r} > mu_max = "
                                 f"{self.mu_max!r}: expected mu_min <= mu_max")
        require_nonnegative(self, "rate_parameter")
        require_positive(self, "yield_displacement")
        require_nonnegative(self, "c")
        require_positive(self, "A")
        require_range(self, "substep_tolerance", 0.0, 2.0, low_open=True)
        if not (self.beta + self.gamma > 0.0 and self.gamma >= self.beta):
            raise ParameterError(f"FrictionPendulumBearing.beta = {self.beta!r}, gamma = {self.gamma!r}: "
                                 "expected beta + gamma > 0 and gamma >= beta (bounded hysteresis)")

    @property
    def pendulum_stiffness(self) -> float:
        """W / R [N/m]."""
        return self.weight / self.radius

    def to_array(self) -> np.ndarray:
        return np.array([self.pendulum_stiffness, self.c, self.weight, self.mu_max, self.mu_min,
                         self.rate_parameter, self.yield_displacement, self.A, self.beta,
                         self.gamma, self.substep_tolerance], dtype=np.float64)

    @staticmethod
    def lockstep_form(params: np.ndarray) -> np.ndarray:
        """The bearing's column of the lock-step form (:data:`park_wen.LOCKSTEP_FORM`) from its
        packed parameters: friction :math:`\\mu_{max} - (\\mu_{max} - \\mu_{min}) e^{-a|v|}` on W.

        Parameters
        ----------
        params : ndarray
            Packed parameters (:meth:`to_array`).
        """
        return np.array([*lockstep_coefficients(*params[6:11]), params[2], params[3], params[3] - params[4],
                         params[5]])

    def rates(self, state, ux, uy, vx, vy):
        rzx, rzy = park_wen_rates(float(state[0]), float(state[1]), float(vx), float(vy),
                                  self.yield_displacement, self.A, self.beta, self.gamma)
        return np.array([rzx, rzy])

    def force(self, state, ux, uy, vx, vy):
        mu = friction_coefficient(math.hypot(vx, vy), self.mu_max, self.mu_min, self.rate_parameter)
        kp = self.pendulum_stiffness
        return (kp * ux + self.c * vx + mu * self.weight * state[0],
                kp * uy + self.c * vy + mu * self.weight * state[1])


@numba.njit(cache=True, inline="always")
def friction_pendulum_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out):
    """Advance ``state = [z_x, z_y]`` over one step and write the friction force mu W z [N].

    Parameters
    ----------
    params
        Packed bearing parameters (``pack()`` of the bearing's parameters, float64).
    state
        Internal (hysteretic) states of the bearing.
    ux0
        Displacement in x at the start of the step [m].
    uy0
        Displacement in y at the start of the step [m].
    ux1
        Displacement in x at the end of the step [m].
    uy1
        Displacement in y at the end of the step [m].
    vx0
        Velocity in x at the start of the step [m/s].
    vy0
        Velocity in y at the start of the step [m/s].
    vx1
        Velocity in x at the end of the step [m/s].
    vy1
        Velocity in y at the end of the step [m/s].
    dt
        Step length [s].
    force_out
        Array of 2 the force (x, y) [N] is written into.
    """
    park_wen_advance(state, 0, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt,
                     params[6], params[7], params[8], params[9], params[10])
    speed = math.sqrt(vx1 * vx1 + vy1 * vy1)
    mu = params[3] - (params[3] - params[4]) * math.exp(-params[5] * speed)
    force_out[0] = mu * params[2] * state[0]
    force_out[1] = mu * params[2] * state[1]


@numba.njit(cache=True, inline="always")
def friction_pendulum_tangent(params, state, dx, dy, vx1, vy1, tangent):
    """Write the friction force's tangent at the end of a step into ``tangent`` (2 x 4):
    ``[:, 0:2]`` = d f / d u = mu W dz/du [N/m], ``[:, 2:4]`` = d f / d v = W z (d mu / d|v|) v/|v|
    [N s/m] (the velocity dependence of the friction coefficient)."""
    kxx, kxy, kyx, kyy = park_wen_tangent(state[0], state[1], dx, dy, params[6], params[7], params[8], params[9])
    speed = math.sqrt(vx1 * vx1 + vy1 * vy1)
    e = math.exp(-params[5] * speed)
    w = params[2] * (params[3] - (params[3] - params[4]) * e)
    tangent[0, 0] = w * kxx
    tangent[0, 1] = w * kxy
    tangent[1, 0] = w * kyx
    tangent[1, 1] = w * kyy
    if speed > 0.0:
        dmu = params[2] * (params[3] - params[4]) * params[5] * e / speed  # W dmu/ds / |v|
        tangent[0, 2] = dmu * state[0] * vx1
        tangent[0, 3] = dmu * state[0] * vy1
        tangent[1, 2] = dmu * state[1] * vx1
        tangent[1, 3] = dmu * state[1] * vy1
    else:
        tangent[0, 2] = 0.0
        tangent[0, 3] = 0.0
        tangent[1, 2] = 0.0
        tangent[1, 3] = 0.0


@numba.njit(cache=True, inline="always")
def friction_pendulum_step_closed_form(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out,
                                    tangent):
    """Closed-form update (:func:`park_wen_closed_form`) of ``state = [z_x, z_y]`` over one step: writes
    the friction force mu W z [N] into ``force_out`` and its tangent into ``tangent``
    (2 x 4, the layout of :func:`friction_pendulum_tangent`: d f/d u1 [N/m], d f/d v1 [N s/m]).

    Parameters
    ----------
    params : ndarray
        The bearing's packed parameters (its ``pack()``, float64, SI).
    state : ndarray
        Its hysteretic state ``[z_x, z_y]``, advanced in place.
    ux0, uy0, ux1, uy1 : float
        Bearing displacement (x, y) at the start and the end of the step [m].
    vx0, vy0, vx1, vy1 : float
        Bearing velocity (x, y) at the start and the end of the step [m/s].
    dt : float
        Step length [s].
    force_out : ndarray, shape (2,)
        Receives the hysteretic force (x, y) at the end of the step [N].
    tangent : ndarray, shape (2, 4)
        Receives d force / d (ux1, uy1) [N/m] and d force / d (vx1, vy1) [N s/m].
    """
    kxx, kxy, kyx, kyy = park_wen_closed_form(state, 0, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt,
                                           params[6], params[7], params[8], params[9])
    speed = math.sqrt(vx1 * vx1 + vy1 * vy1)
    e = math.exp(-params[5] * speed)
    w = params[2] * (params[3] - (params[3] - params[4]) * e)
    zx = state[0]
    zy = state[1]
    force_out[0] = w * zx
    force_out[1] = w * zy
    tangent[0, 0] = w * kxx
    tangent[0, 1] = w * kxy
    tangent[1, 0] = w * kyx
    tangent[1, 1] = w * kyy
    dmu = 0.0
    if speed > 0.0:
        dmu = params[2] * (params[3] - params[4]) * params[5] * e / speed  # W dmu/ds / |v|
    tangent[0, 2] = dmu * zx * vx1
    tangent[0, 3] = dmu * zx * vy1
    tangent[1, 2] = dmu * zy * vx1
    tangent[1, 3] = dmu * zy * vy1
