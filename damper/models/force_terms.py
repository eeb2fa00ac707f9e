"""Memoryless force terms around a registered damper model: how a diagnosed model runs in the building.

The residual loop (:mod:`damper.diagnosis.loop`) adds effects to a base model
(:mod:`damper.diagnosis.effects`, composed in :mod:`damper.diagnosis.augmented`). The effects
that are algebraic in the device's force, displacement and velocity run here, around the base
model's own kernel, so that the building (and :func:`damper.simulate`) carries them:

.. math::

   F = F_\\text{inner}\\,\\big(1 + a\\,\\mathrm{sgn}F_\\text{inner}\\big)
       + \\kappa\\,x + k\\,s(\\dot x)\\max(|\\dot x|, v_\\varepsilon)^{m} + c_2\\,\\dot x|\\dot x|,
   \\qquad s(\\dot x) = \\min\\big(1, \\max(-1, \\dot x / v_\\varepsilon)\\big)

with :math:`F_\\text{inner}` the inner model's force (its own states and voltage laws), ``a`` the
``asymmetry`` ratio (extension / compression force level), ``kappa`` a parallel spring
(``stiffness``, added after the factor as the augmented model adds it), ``k`` the
``shear_thinning`` coefficient with flow index :data:`SHEAR_THINNING_EXPONENT` and ``c2`` the
``quadratic_damping`` coefficient: the equations of :class:`damper.diagnosis.effects.Asymmetry`,
``Stiffness``, ``ShearThinning`` and ``QuadraticDamping``, in that composition
(``tests/damper/test_force_terms.py`` holds the two together on the same motions).

The terms have no state: the device's states are the inner model's. ``sgn(0) = 0``.

**The shear-thinning term's sign is linear within** :math:`|\\dot x| < v_\\varepsilon` =
:data:`REGULARIZATION_VELOCITY` (0.1 mm/s): the unbounded slope of :math:`|\\dot x|^{1/2}` at
rest is a force the building's step cannot iterate (its fixed point stopped converging at the
first step of a kobe run from rest). The same definition is the effect's
(:func:`shear_thinning_force`), so a fitted model and its building model agree. 0.1 mm/s is under
1 % of the smallest velocity amplitude of the measured tests in shared/ (UTFSM, 25 mm at 0.1 Hz:
16 mm/s); it changes the force only while the piston turns.

The ``direction`` effect (the force level switching with the sign of the velocity) is not one of
these terms: a jump of :math:`2dF` at every reversal, which at building scale (a 1-MN device,
d = 0.2) the step's iteration did not converge on, sharp or smoothed over 0.1 mm/s, by fixed
point or by Newton (kobe, 16 devices, 2026-11-27).

Packed parameters (:meth:`WithForceTerms.to_array`): ``[inner kernel family, m, inner's m
packed parameters, a, kappa, k, exponent, c2, v_eps]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError
from damper.models.base import KERNEL_FORCE_TERMS, KERNELS, DamperModel, register_model

__all__ = ["WithForceTerms", "SHEAR_THINNING_EXPONENT", "REGULARIZATION_VELOCITY", "TERM_COUNT", "force_terms",
           "force_terms_tangent", "shear_thinning_force"]

#: Flow index ``m`` of the shear-thinning (Herschel-Bulkley) post-yield term, the one
#: :class:`damper.diagnosis.effects.ShearThinning` fits.
SHEAR_THINNING_EXPONENT = 0.5
#: Velocity [m/s] within which the sign of the velocity is linear (module docstring).
REGULARIZATION_VELOCITY = 1.0e-4
#: Number of packed values after the inner model's parameters.
TERM_COUNT = 6
# the factor term's admissible ratio (as damper.diagnosis.effects.Asymmetry)
_RATIO_LIMIT = 0.9


@register_model
@dataclass(frozen=True)
class WithForceTerms(DamperModel):
    """A registered model with memoryless force terms around it (module docstring).

    Parameters
    ----------
    inner : DamperModel
        Any registered model but another :class:`WithForceTerms`.
    asymmetry : float, optional
        ``a`` [-], ``|a| <= 0.9``: the inner force times ``1 + a`` in extension, ``1 - a`` in
        compression.
    stiffness : float, optional
        Parallel spring ``kappa`` [N/m], >= 0.
    shear_thinning : float, optional
        ``k`` [N·(s/m)^0.5], >= 0.
    quadratic_damping : float, optional
        ``c2`` [N·s²/m²], >= 0.
    """

    inner: DamperModel
    asymmetry: float = 0.0
    stiffness: float = 0.0
    shear_thinning: float = 0.0
    quadratic_damping: float = 0.0
    voltage_range: tuple[float, float] = field(init=False)

    name: ClassVar[str] = "with_force_terms"
    kernel: ClassVar[int] = KERNEL_FORCE_TERMS
    n_states: ClassVar[int] = 0  # the instance's count is the inner model's (set on construction)

    def __post_init__(self) -> None:
        inner = self.inner
        if not isinstance(inner, DamperModel) or isinstance(inner, WithForceTerms):
            raise ParameterError(f"WithForceTerms.inner: expected a registered damper model other than "
                                 f"{self.name}, got {type(inner).__name__}")
        if getattr(type(inner), "kernel", None) not in KERNELS or type(inner).kernel == KERNEL_FORCE_TERMS:
            raise ParameterError(f"WithForceTerms.inner: {type(inner).__name__} has no kernel family")
        for name, lower, upper in (("asymmetry", -_RATIO_LIMIT, _RATIO_LIMIT),
                                   ("stiffness", 0.0, math.inf), ("shear_thinning", 0.0, math.inf),
                                   ("quadratic_damping", 0.0, math.inf)):
            raw = getattr(self, name)
            try:
                value = float(raw)
            except (TypeError, ValueError):
                raise ParameterError(f"WithForceTerms.{name}: expected a number, got {raw!r}") from None
            if isinstance(raw, bool) or not math.isfinite(value) or not lower <= value <= upper:
                raise ParameterError(f"WithForceTerms.{name}: expected a finite number in "
                                     f"[{lower:g}, {upper:g}], got {raw!r}")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "voltage_range", tuple(inner.voltage_range))
        object.__setattr__(self, "n_states", int(type(inner).n_states))
        object.__setattr__(self, "state_names", tuple(getattr(type(inner), "state_names", ())))
        # packed once: force() runs at every right-hand side of the solve_ivp oracle
        inner_packed = np.asarray(inner.to_array(), dtype=np.float64)
        packed = np.concatenate(([float(type(inner).kernel), float(inner_packed.size)], inner_packed,
                                 [self.asymmetry, self.stiffness, self.shear_thinning, SHEAR_THINNING_EXPONENT,
                                  self.quadratic_damping, REGULARIZATION_VELOCITY]))
        object.__setattr__(self, "_packed", packed)

    @property
    def terms(self) -> dict[str, float]:
        """The terms that are not neutral, by their effect names (:mod:`damper.diagnosis.effects`)."""
        values = {"asymmetry": self.asymmetry, "stiffness": self.stiffness,
                  "shear_thinning": self.shear_thinning, "quadratic_damping": self.quadratic_damping}
        return {k: v for k, v in values.items() if v != 0.0}

    def to_array(self) -> np.ndarray:
        """``[inner kernel, m, inner.to_array() (m values), a, kappa, k, exponent, c2, v_eps]``."""
        return self._packed.copy()

    def initial_state(self) -> np.ndarray:
        """The inner model's states at rest."""
        return self.inner.initial_state()

    def rates(self, state, x: float, xdot: float, v: float) -> np.ndarray:
        """The inner model's state rates (the terms have no state).

        Parameters
        ----------
        state
            Internal states of the inner model.
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        return self.inner.rates(state, x, xdot, v)

    def force(self, state, x: float, xdot: float, v: float) -> float:
        """Force [N]: the inner model's with the terms (module docstring).

        Parameters
        ----------
        state
            Internal states of the inner model.
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        f = float(self.inner.force(state, x, xdot, v))
        return float(force_terms(self._packed, f, float(x), float(xdot)))


def _regularized_sign(xd) -> np.ndarray:
    """:math:`s(\\dot x)`: the sign of the velocity ``xd`` [m/s], linear within
    :data:`REGULARIZATION_VELOCITY` (module docstring).

    Parameters
    ----------
    xd : array_like
        Velocity [m/s].
    """
    return np.clip(np.asarray(xd, dtype=float) / REGULARIZATION_VELOCITY, -1.0, 1.0)


def shear_thinning_force(k: float, xd) -> np.ndarray:
    """The shear-thinning term :math:`k\\,s(\\dot x)\\max(|\\dot x|, v_\\varepsilon)^{m}` [N].

    Parameters
    ----------
    k : float
        Coefficient [N·(s/m)^m], m = :data:`SHEAR_THINNING_EXPONENT`.
    xd : array_like
        Velocity [m/s].
    """
    xd = np.asarray(xd, dtype=float)
    return k * _regularized_sign(xd) * np.maximum(np.abs(xd), REGULARIZATION_VELOCITY) ** SHEAR_THINNING_EXPONENT


@numba.njit(cache=True)
def _sign(a):
    return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)


@numba.njit(cache=True)
def force_terms(params, f_inner, x, xd):
    """The total force [N] from the inner model's force ``f_inner`` [N] at displacement ``x`` [m]
    and velocity ``xd`` [m/s] (module docstring); ``params`` packed as :meth:`WithForceTerms.to_array`.

    Parameters
    ----------
    params
        Packed parameters of the :class:`WithForceTerms` model.
    f_inner
        The inner model's force [N].
    x
        Displacement [m].
    xd
        Velocity [m/s].
    """
    o = 2 + int(params[1])
    eps = params[o + 5]
    s = min(1.0, max(-1.0, xd / eps))
    return (f_inner * (1.0 + params[o] * _sign(f_inner)) + params[o + 1] * x
            + params[o + 2] * s * max(abs(xd), eps) ** params[o + 3] + params[o + 4] * xd * abs(xd))


@numba.njit(cache=True)
def force_terms_tangent(params, f_inner, dfdx, dfdxd, xd):
    """``(dF/dx, dF/dxd)`` of the total force from the inner model's tangent (the asymmetry
    factor's kink at zero force left out: the building's Newton iteration only needs a tangent
    that speeds it up).

    Parameters
    ----------
    params
        Packed parameters of the :class:`WithForceTerms` model.
    f_inner
        The inner model's force [N].
    dfdx, dfdxd
        The inner model's tangent [N/m], [N·s/m].
    xd
        Velocity [m/s].
    """
    o = 2 + int(params[1])
    g = 1.0 + params[o] * _sign(f_inner)
    k = params[o + 2]
    m = params[o + 3]
    eps = params[o + 5]
    v = abs(xd)
    thinning = k * eps ** (m - 1.0) if v < eps else k * m * v ** (m - 1.0)
    return g * dfdx + params[o + 1], g * dfdxd + thinning + 2.0 * params[o + 4] * v
