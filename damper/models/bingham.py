"""Bingham model of an MR damper (Stanway et al. 1987; as compared in Spencer et al. 1997).

.. math::

   F = f_c(v)\\,\\mathrm{sgn}(\\dot x) + c_0(v)\\,\\dot x + f_0

A Coulomb friction element in parallel with a dashpot, plus a force offset (accumulator).
No internal state: it cannot reproduce the roll-off at low velocity or the hysteresis of the
force-velocity loop. ``f_c`` [N] > 0, ``c0`` [N·s/m] > 0 (numbers or voltage laws), ``f0`` [N].
``sgn(0) = 0``.

:meth:`Bingham.spencer_1997` gives the values Spencer et al. (1997) fitted to their 1.5 kN
prototype at 1.5 V (f_c = 670 N, c0 = 50 N·s/cm, f0 = -95 N), quoted from memory of the paper
(**unverified**).

References
----------
Stanway R., Sproston J.L., Stevens N.G. (1987) *Non-linear modelling of an electro-rheological
vibration damper*, J. Electrostatics 20:167-184.
Spencer B.F. Jr. et al. (1997) J. Eng. Mech. 123(3):230-238.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from damper.models.base import DamperModel, KERNEL_BINGHAM, register_model
from benchmark.foundation.errors import ParameterError
from damper.models.bouc_wen import _check_voltage_range
from damper.models.voltage_laws import ParameterLike, VoltageLaw, as_law, check_law, law_length, law_value

__all__ = ["Bingham", "bingham_step", "bingham_force"]



@register_model
@dataclass(frozen=True)
class Bingham(DamperModel):
    """Bingham model ``F = f_c sgn(xdot) + c0 xdot + f0`` (see module docstring).

    Parameters
    ----------
    f_c : ParameterLike
        Friction force f_c [N], a number or a voltage law.
    c0 : ParameterLike
        Viscous coefficient c₀ [N·s/m], a number or a voltage law.
    f0 : float, optional
        Force offset f₀ [N] (accumulator).
    voltage_range : tuple[float, float], optional
        Admissible coil inputs ``(min, max)`` [V] (or [A]); the voltage laws are checked over it.
    """

    f_c: ParameterLike
    c0: ParameterLike
    f0: float = 0.0
    voltage_range: tuple[float, float] = (0.0, 1.0)

    name: ClassVar[str] = "bingham"
    kernel: ClassVar[int] = KERNEL_BINGHAM
    n_states: ClassVar[int] = 0
    state_names: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        for name in ("f_c", "c0"):
            law = as_law(getattr(self, name), f"Bingham.{name}")
            check_law(law, name, self.voltage_range, lower=0.0)
            if not isinstance(getattr(self, name), VoltageLaw):
                object.__setattr__(self, name, float(getattr(self, name)))
        try:
            f0 = float(self.f0)
        except (TypeError, ValueError):
            raise ParameterError(f"Bingham.f0: expected a number, got {self.f0!r}") from None
        if not math.isfinite(f0):
            raise ParameterError(f"Bingham.f0: expected a finite number, got {f0}")
        object.__setattr__(self, "f0", f0)

    @classmethod
    def spencer_1997(cls) -> "Bingham":
        """Spencer et al. (1997) Bingham fit of the 1.5 kN prototype at 1.5 V (unverified)."""
        return cls(f_c=670.0, c0=50.0e2, f0=-95.0, voltage_range=(0.0, 2.25))

    def to_array(self) -> np.ndarray:
        """``[law(f_c), law(c0), f0]``."""
        return np.concatenate((as_law(self.f_c).to_array(), as_law(self.c0).to_array(), [self.f0]))

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
        return float(as_law(self.f_c)(v) * np.sign(xdot) + as_law(self.c0)(v) * xdot + self.f0)


@numba.njit(cache=True)
def bingham_force(params, state, x, xd, v):
    """Force [N] of the packed Bingham model.

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
    fc = law_value(params, 0, v)
    off = law_length(params, 0)
    c0 = law_value(params, off, v)
    off += law_length(params, off)
    s = 1.0 if xd > 0.0 else (-1.0 if xd < 0.0 else 0.0)
    return fc * s + c0 * xd + params[off]


@numba.njit(cache=True)
def bingham_step(params, state, x0, x1, xd0, xd1, v, dt):
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
    return bingham_force(params, state, x1, xd1, v)
