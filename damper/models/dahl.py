"""Dahl model of an MR damper (Dahl 1968; Ikhouane & Dyke 2007 for MR dampers).

.. math::

   F = \\kappa_x(v)\\,x + \\kappa_{\\dot x}(v)\\,\\dot x + \\kappa_w(v)\\,w, \\qquad
   \\dot w = \\rho\\,(\\dot x - |\\dot x|\\,w)

the normalized Bouc-Wen model with :math:`\\sigma = 1`, :math:`n = 1` (Spencer et al. 1997; Bahar et al. 2009): the
hysteretic force relaxes exponentially, :math:`w = \\pm 1 \\mp (1 \\mp w_r)e^{-\\rho|x - x_r|}`, after
each reversal. It runs on the Bouc-Wen kernel (:func:`damper.models.bouc_wen.bouc_wen_step`).
Units as in :class:`~damper.models.bouc_wen.ExtendedBoucWen`; ``kappa_x >= 0``, the others > 0.

:meth:`Dahl.virtual_0V` is a documented calibration to the virtual benchmark damper's 0 V
loops as read off with :mod:`damper.lab.loops` (``kappa_x`` = 207 kN/m, ``kappa_xdot`` =
98 kN·s/m, ``kappa_w`` = 57 kN, ``rho`` = 120 1/m).

References
----------
Dahl P.R. (1968) *A solid friction model*, Aerospace Corp. TOR-0158(3107-18)-1.
Ikhouane F., Dyke S.J. (2007) *Modeling and identification of a shear mode magnetorheological
damper*, Smart Mater. Struct. 16:605-616.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from damper.models.base import DamperModel, KERNEL_BOUC_WEN, register_model
from damper.models.bouc_wen import DEFAULT_SUBSTEP_TOLERANCE, ExtendedBoucWen
from damper.models.voltage_laws import ParameterLike

__all__ = ["Dahl"]



@register_model
@dataclass(frozen=True)
class Dahl(DamperModel):
    """Dahl model (normalized Bouc-Wen with sigma = 1, n = 1); see module docstring.

    Parameters
    ----------
    kappa_x : ParameterLike
        Elastic coefficient κ_x [N/m], a number or a voltage law.
    kappa_xdot : ParameterLike
        Viscous coefficient κ_ẋ [N·s/m], a number or a voltage law.
    kappa_w : ParameterLike
        Hysteretic force scale κ_w [N], a number or a voltage law.
    rho : ParameterLike
        Normalized Bouc-Wen rate parameter ρ [1/m] (> 0).
    voltage_range : tuple[float, float], optional
        Admissible coil inputs ``(min, max)`` [V] (or [A]); the voltage laws are checked over it.
    substep_tolerance : float, optional
        Sub-step size control of the integrator (``0 < tol <= 1``; smaller: more sub-steps, error O(tol⁴)).
    """

    kappa_x: ParameterLike
    kappa_xdot: ParameterLike
    kappa_w: ParameterLike
    rho: ParameterLike
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "dahl"
    kernel: ClassVar[int] = KERNEL_BOUC_WEN
    n_states: ClassVar[int] = 1
    state_names: ClassVar[tuple[str, ...]] = ("w",)

    def __post_init__(self) -> None:
        equivalent = self.as_bouc_wen()  # validates (ParameterError names the field)
        for name in ("kappa_x", "kappa_xdot", "kappa_w", "rho", "voltage_range", "substep_tolerance"):
            object.__setattr__(self, name, getattr(equivalent, name))

    @classmethod
    def virtual_0V(cls) -> "Dahl":
        """Calibration to the virtual benchmark damper at 0 V (module docstring)."""
        return cls(kappa_x=207.0e3, kappa_xdot=98.0e3, kappa_w=57.0e3, rho=120.0)

    def as_bouc_wen(self) -> ExtendedBoucWen:
        """The equivalent extended Bouc-Wen model (sigma = 1, n = 1)."""
        return ExtendedBoucWen(self.kappa_x, self.kappa_xdot, self.kappa_w, self.rho, 1.0, 1.0,
                               voltage_range=self.voltage_range,
                               substep_tolerance=self.substep_tolerance)

    def to_array(self) -> np.ndarray:
        """The Bouc-Wen kernel layout with sigma = n = 1."""
        return self.as_bouc_wen().to_array()

    def initial_state(self) -> np.ndarray:
        """``[w] = [0]``."""
        return np.zeros(1)

    def rates(self, state, x: float, xdot: float, v: float) -> np.ndarray:
        """``[wdot]`` (plain numpy).

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
        return self.as_bouc_wen().rates(state, x, xdot, v)

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
        return self.as_bouc_wen().force(state, x, xdot, v)

    def at_voltage(self, v: float) -> "Dahl":
        """Parameters frozen at voltage ``v``.

        Parameters
        ----------
        v : float
            Voltage [V].
        """
        c = self.as_bouc_wen().coefficients(v)
        return replace(self, kappa_x=c["kappa_x"], kappa_xdot=c["kappa_xdot"],
                       kappa_w=c["kappa_w"], rho=c["rho"])
