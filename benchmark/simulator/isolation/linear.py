r"""Linear elastomeric bearing: :math:`f = k u + c \dot u` in each horizontal direction.

The named configuration ``linear`` uses :math:`k = 919.422` kN/m and :math:`c = 27.717`
kN·s/m per bearing (the values of published re-implementations of the benchmark, e.g.
the FDZ repository; stored in ``structure.json`` as ``fdz_linear_bearing``), which give
isolated periods of about 3.4/3.2/2.7 s with about 3 % damping.

Parameter array (``to_array()``): ``[k, c]``. No internal states; the whole force is the
linear part, so the kernel's hysteretic force is zero.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from benchmark.simulator.isolation.base import (BearingParameters, KERNEL_LINEAR, register_bearing, require_nonnegative,
                                                 require_positive)

__all__ = ["LinearBearing", "N_PARAMS", "linear_step"]

N_PARAMS = 2


@register_bearing
@dataclass(frozen=True)
class LinearBearing(BearingParameters):
    """Linear elastomeric bearing.

    Parameters
    ----------
    k : float
        Horizontal stiffness per direction [N/m] (> 0).
    c : float
        Viscous damping coefficient per direction [N·s/m] (>= 0).
    """

    k: float
    c: float = 0.0

    name: ClassVar[str] = "linear"
    kernel: ClassVar[int] = KERNEL_LINEAR
    n_states: ClassVar[int] = 0

    def __post_init__(self) -> None:
        require_positive(self, "k")
        require_nonnegative(self, "c")

    def to_array(self) -> np.ndarray:
        return np.array([self.k, self.c], dtype=np.float64)

    def rates(self, state, ux, uy, vx, vy):
        return np.zeros(0)

    def force(self, state, ux, uy, vx, vy):
        return self.k * ux + self.c * vx, self.k * uy + self.c * vy


@numba.njit(cache=True)
def linear_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out):
    """Linear bearing: no states; the hysteretic (non-linear) force is zero.

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
    force_out[0] = 0.0
    force_out[1] = 0.0
