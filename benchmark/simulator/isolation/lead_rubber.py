r"""Lead-rubber (bilinear elastomeric) bearing with biaxial Park–Wen interaction.

In each horizontal direction :math:`j \in \{x, y\}`

.. math::

    f_j = \alpha k\, u_j + c\, \dot u_j + (1 - \alpha) F_y\, z_j

with :math:`k` the pre-yield (elastic) stiffness, :math:`\alpha` the post-yield stiffness
ratio, :math:`F_y` the yield force, :math:`Y = F_y / k` the yield displacement, and
:math:`z = (z_x, z_y)` the biaxial hysteretic vector of :mod:`benchmark.simulator.isolation.park_wen`
(Park, Wen & Ang 1986; the lead-rubber model of 3D-BASIS, Nagarajaiah et al. 1991). The
characteristic strength is :math:`Q_d = (1 - \alpha) F_y` and the post-yield stiffness
:math:`k_d = \alpha k`.

Linear part (handled exactly by the building): :math:`k_\mathrm{lin} = \alpha k`,
:math:`c_\mathrm{lin} = c`. The kernel returns the hysteretic force
:math:`(1 - \alpha) F_y z`.

Parameter array (``to_array()``)::

    [alpha*k, c, (1-alpha)*F_y, Y, A, beta, gamma, substep_tolerance]

States: ``[z_x, z_y]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.simulator.isolation.base import (BearingParameters, KERNEL_LEAD_RUBBER, register_bearing, require_nonnegative, require_positive,
                                      require_range)
from benchmark.simulator.isolation.park_wen import (lockstep_coefficients, park_wen_advance, park_wen_closed_form, park_wen_rates,
                                                   park_wen_tangent)

__all__ = ["LeadRubberBearing", "N_PARAMS", "lead_rubber_step", "lead_rubber_step_closed_form"]

N_PARAMS = 8


@register_bearing
@dataclass(frozen=True)
class LeadRubberBearing(BearingParameters):
    """Lead-rubber bearing (bilinear, biaxial Park–Wen hysteresis).

    Parameters
    ----------
    k_initial : float
        Pre-yield (elastic) stiffness k [N/m] (> 0).
    alpha : float
        Post-yield to pre-yield stiffness ratio, in [0, 1).
    yield_force : float
        Yield force F_y [N] (> 0); the yield displacement is Y = F_y / k.
    c : float
        Viscous damping of the rubber [N·s/m] (>= 0, default 0).
    A, beta, gamma : float
        Park–Wen shape parameters (defaults 1, 0.1, 0.9: A = beta + gamma, so |z| saturates at 1;
        gamma >= beta and beta + gamma > 0 are required for bounded z).
    substep_tolerance : float
        Sub-step tolerance ``tol`` of the kernel (product of the local hysteretic stiffness and
        the sub-step length, default 0.75: hysteretic-force errors <= 5e-5 relative in the oracle tests,
        see :mod:`benchmark.simulator.isolation.park_wen`; smaller is more accurate and slower).
    """

    k_initial: float
    alpha: float
    yield_force: float
    c: float = 0.0
    A: float = 1.0
    beta: float = 0.1
    gamma: float = 0.9
    substep_tolerance: float = 0.75

    name: ClassVar[str] = "lead-rubber"
    kernel: ClassVar[int] = KERNEL_LEAD_RUBBER
    n_states: ClassVar[int] = 2

    def __post_init__(self) -> None:
        require_positive(self, "k_initial")
        require_range(self, "alpha", 0.0, 1.0, high_open=True)
        require_positive(self, "yield_force")
        require_nonnegative(self, "c")
        require_positive(self, "A")
        require_range(self, "substep_tolerance", 0.0, 2.0, low_open=True)
        if not (self.beta + self.gamma > 0.0 and self.gamma >= self.beta):
            raise ParameterError(f"LeadRubberBearing.beta = {self.beta!r}, gamma = {self.gamma!r}: "
                                 "expected beta + gamma > 0 and gamma >= beta (bounded hysteresis)")

    @property
    def yield_displacement(self) -> float:
        """Y = F_y / k [m]."""
        return self.yield_force / self.k_initial

    @property
    def post_yield_stiffness(self) -> float:
        """k_d = alpha k [N/m]."""
        return self.alpha * self.k_initial

    @property
    def characteristic_strength(self) -> float:
        """Q_d = (1 - alpha) F_y [N], the force intercept of the post-yield branch."""
        return (1.0 - self.alpha) * self.yield_force

    def to_array(self) -> np.ndarray:
        return np.array([self.alpha * self.k_initial, self.c, self.characteristic_strength,
                         self.yield_displacement, self.A, self.beta, self.gamma,
                         self.substep_tolerance], dtype=np.float64)

    @staticmethod
    def lockstep_form(params: np.ndarray) -> np.ndarray:
        """The bearing's column of the lock-step form (:data:`park_wen.LOCKSTEP_FORM`) from its
        packed parameters: the characteristic strength Q_d on z (mu0 = 1, no rate dependence).

        Parameters
        ----------
        params : ndarray
            Packed parameters (:meth:`to_array`).
        """
        return np.array([*lockstep_coefficients(*params[3:8]), params[2], 1.0, 0.0, 0.0])

    def rates(self, state, ux, uy, vx, vy):
        rzx, rzy = park_wen_rates(float(state[0]), float(state[1]), float(vx), float(vy),
                                  self.yield_displacement, self.A, self.beta, self.gamma)
        return np.array([rzx, rzy])

    def force(self, state, ux, uy, vx, vy):
        kd = self.post_yield_stiffness
        q = self.characteristic_strength
        return (kd * ux + self.c * vx + q * state[0], kd * uy + self.c * vy + q * state[1])


@numba.njit(cache=True, inline="always")
def lead_rubber_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out):
    """Advance ``state = [z_x, z_y]`` over one step and write the hysteretic force Q_d z [N].

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
                     params[3], params[4], params[5], params[6], params[7])
    force_out[0] = params[2] * state[0]
    force_out[1] = params[2] * state[1]


@numba.njit(cache=True, inline="always")
def lead_rubber_tangent(params, state, dx, dy, vx1, vy1, tangent):
    """Write the hysteretic force's tangent at the end of a step into ``tangent`` (2 x 4):
    ``[:, 0:2]`` = d f / d u [N/m] (Q_d dz/du, :func:`park_wen_tangent`), ``[:, 2:4]`` = d f / d v = 0."""
    kxx, kxy, kyx, kyy = park_wen_tangent(state[0], state[1], dx, dy, params[3], params[4], params[5], params[6])
    q = params[2]
    tangent[0, 0] = q * kxx
    tangent[0, 1] = q * kxy
    tangent[1, 0] = q * kyx
    tangent[1, 1] = q * kyy
    tangent[0, 2] = 0.0
    tangent[0, 3] = 0.0
    tangent[1, 2] = 0.0
    tangent[1, 3] = 0.0


@numba.njit(cache=True, inline="always")
def lead_rubber_step_closed_form(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out, tangent):
    """Closed-form update (:func:`park_wen_closed_form`: exact flow along the chords of the path) of
    ``state = [z_x, z_y]`` over one step: writes the hysteretic force Q_d z [N] into
    ``force_out`` and its tangent (2 x 4, d f/d u1 [N/m], d f/d v1 = 0) into ``tangent``.

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
                                           params[3], params[4], params[5], params[6])
    q = params[2]
    force_out[0] = q * state[0]
    force_out[1] = q * state[1]
    tangent[0, 0] = q * kxx
    tangent[0, 1] = q * kxy
    tangent[1, 0] = q * kyx
    tangent[1, 1] = q * kyy
    tangent[0, 2] = 0.0
    tangent[0, 3] = 0.0
    tangent[1, 2] = 0.0
    tangent[1, 3] = 0.0
