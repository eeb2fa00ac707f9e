"""Hyperbolic-tangent model of an MR damper (Kwok et al. 2006).

.. math::

   F = c(v)\\,\\dot x + k(v)\\,x + \\alpha(v)\\tanh\\left(\\beta\\dot x + \\delta\\,\\mathrm{sgn}(x)\\right) + f_0

A smooth stateless hysteresis: ``tanh`` gives the yield around zero velocity, ``delta sgn x``
shifts it between the two halves of the stroke. Units: ``c`` [N·s/m] > 0, ``k`` [N/m] >= 0,
``alpha`` [N] > 0 (numbers or voltage laws), ``beta`` [s/m] > 0, ``delta`` [-], ``f0`` [N].

:meth:`HyperbolicTangent.virtual_0V` is a documented calibration to the virtual benchmark damper's
0 V loops as read off with :mod:`damper.lab.loops` (``k`` = 207 kN/m mid-line slope,
``c`` = 98 kN·s/m and ``alpha`` = 57 kN from the plastic branches, ``beta`` = 60 s/m for a
yield over about ±0.03 m/s, ``delta = 0``, ``f0 = 0``).

References
----------
Kwok N.M., Ha Q.P., Nguyen T.H., Li J., Samali B. (2006) *A novel hysteretic model for
magnetorheological fluid dampers and parameter identification using particle swarm
optimization*, Sensors and Actuators A 132:441-451.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from damper.models.base import DamperModel, KERNEL_HYPERBOLIC_TANGENT, register_model
from benchmark.foundation.errors import ParameterError
from damper.models.bouc_wen import _check_voltage_range
from damper.models.voltage_laws import ParameterLike, VoltageLaw, as_law, check_law, law_length, law_value

__all__ = ["HyperbolicTangent", "hyperbolic_tangent_step",
           "hyperbolic_tangent_force"]



@register_model
@dataclass(frozen=True)
class HyperbolicTangent(DamperModel):
    """``F = c xdot + k x + alpha tanh(beta xdot + delta sgn x) + f0`` (see module docstring).

    Parameters
    ----------
    c : ParameterLike
        Viscous coefficient c [N·s/m], a number or a voltage law.
    k : ParameterLike
        Stiffness k [N/m], a number or a voltage law.
    alpha : ParameterLike
        Hysteretic force scale α [N], a number or a voltage law.
    beta : float
        Velocity scale β [s/m] of the tanh.
    delta : float, optional
        Displacement term δ (dimensionless) of the tanh argument.
    f0 : float, optional
        Force offset f₀ [N].
    voltage_range : tuple[float, float], optional
        Admissible coil inputs ``(min, max)`` [V] (or [A]); the voltage laws are checked over it.
    """

    c: ParameterLike
    k: ParameterLike
    alpha: ParameterLike
    beta: float
    delta: float = 0.0
    f0: float = 0.0
    voltage_range: tuple[float, float] = (0.0, 1.0)

    name: ClassVar[str] = "hyperbolic_tangent"
    kernel: ClassVar[int] = KERNEL_HYPERBOLIC_TANGENT
    kernel: ClassVar[int] = KERNEL_HYPERBOLIC_TANGENT
    n_states: ClassVar[int] = 0
    state_names: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        for name, strict in (("c", True), ("k", False), ("alpha", True)):
            law = as_law(getattr(self, name), f"HyperbolicTangent.{name}")
            check_law(law, name, self.voltage_range, lower=0.0, strict=strict)
            if not isinstance(getattr(self, name), VoltageLaw):
                object.__setattr__(self, name, float(getattr(self, name)))
        for name in ("beta", "delta", "f0"):
            try:
                value = float(getattr(self, name))
            except (TypeError, ValueError):
                raise ParameterError(f"HyperbolicTangent.{name}: expected a number, "
                                     f"got {getattr(self, name)!r}") from None
            if not math.isfinite(value):
                raise ParameterError(f"HyperbolicTangent.{name}: expected a finite number, got {value}")
            object.__setattr__(self, name, value)
        if self.beta <= 0:
            raise ParameterError(f"HyperbolicTangent.beta: expected beta > 0, got {self.beta:g}")

    @classmethod
    def virtual_0V(cls) -> "HyperbolicTangent":
        """Calibration to the virtual benchmark damper at 0 V (module docstring)."""
        return cls(c=98.0e3, k=207.0e3, alpha=57.0e3, beta=60.0)

    def to_array(self) -> np.ndarray:
        """``[law(c), law(k), law(alpha), beta, delta, f0]``."""
        return np.concatenate((as_law(self.c).to_array(), as_law(self.k).to_array(),
                               as_law(self.alpha).to_array(), [self.beta, self.delta, self.f0]))

    def initial_state(self) -> np.ndarray:
        """No internal state."""
        return np.zeros(0)

    def rates(self, state, x: float, xdot: float, v: float) -> np.ndarray:
        """No internal state: an empty array.

        Parameters
        ----------
        state
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        return np.zeros(0)

    def force(self, state, x: float, xdot: float, v: float) -> float:
        """Force [N].

        Parameters
        ----------
        state
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        return float(as_law(self.c)(v) * xdot + as_law(self.k)(v) * x
                     + as_law(self.alpha)(v) * np.tanh(self.beta * xdot + self.delta * np.sign(x))
                     + self.f0)


@numba.njit(cache=True)
def hyperbolic_tangent_force(params, state, x, xd, v):
    """Force [N] of the packed hyperbolic-tangent model.

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x
        Displacement [m].
    xd
        Velocity [m/s].
    v
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    """
    c = law_value(params, 0, v)
    off = law_length(params, 0)
    k = law_value(params, off, v)
    off += law_length(params, off)
    alpha = law_value(params, off, v)
    off += law_length(params, off)
    s = 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)
    return c * xd + k * x + alpha * math.tanh(params[off] * xd + params[off + 1] * s) + params[off + 2]


@numba.njit(cache=True)
def hyperbolic_tangent_step(params, state, x0, x1, xd0, xd1, v, dt):
    """Stateless: the force at the end of the step.

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x0
        Displacement at the start of the step [m].
    x1
        Displacement at the end of the step [m].
    xd0
        Velocity at the start of the step [m/s].
    xd1
        Velocity at the end of the step [m/s].
    v
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    dt
        Step length [s].
    """
    return hyperbolic_tangent_force(params, state, x1, xd1, v)
