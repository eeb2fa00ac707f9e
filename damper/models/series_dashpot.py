"""Extended Bouc-Wen model in series with a dashpot: the low-velocity roll-off of real MR dampers.

.. math::

   F &= c_s\\,\\dot y + \\kappa_x x, \\qquad
   c_s = \\kappa_w / v_r \\\\
   \\dot y &= \\frac{\\kappa_w w + \\kappa_{\\dot x}\\dot x}{\\kappa_{\\dot x} + c_s} \\\\
   \\dot w &= \\rho\\left(\\dot r - \\sigma|\\dot r||w|^{n-1}w + (\\sigma-1)\\dot r|w|^n\\right),
      \\qquad \\dot r = \\dot x - \\dot y

The Bouc-Wen element (force scale :math:`\\kappa_w`) and the viscous dashpot
:math:`\\kappa_{\\dot x}` act on the relative motion :math:`x - y`; the series dashpot
:math:`c_s` carries their force, and the accumulator spring :math:`\\kappa_x` acts in parallel.
This is Spencer et al.'s (1997) phenomenological structure with the series spring
:math:`k_0 = 0`, written with the extended model's names. At high speed the dashpot hardly
moves and the force is the extended Bouc-Wen force
:math:`\\kappa_x x + \\kappa_{\\dot x}\\dot x + \\kappa_w w`; below about the **roll-off
velocity** :math:`v_r = \\kappa_w / c_s` the element cannot reach its yield force and the force
falls viscously towards zero with the velocity (the "roll-off" of measured force-velocity
loops, which a rate-independent Bouc-Wen element cannot produce). As :math:`v_r \\to 0` the
model tends to the extended Bouc-Wen model (:class:`damper.models.bouc_wen.ExtendedBoucWen`); the
normalized model is the case :math:`\\kappa_x = 0`.

Parametrizing the dashpot by :math:`v_r` rather than :math:`c_s` keeps the parameter on the
scale of the test velocities and makes it independent of the force level, so one roll-off
velocity can serve every coil input while :math:`c_s(v) = \\kappa_w(v)/v_r` follows the yield
force.

Numerics: the compiled Spencer-type kernel (:func:`damper.models.spencer.spencer_type_step`: exact
field update, RK4 sub-steps along the step's Hermite path, sub-step size from the stiffness
estimate). The field follows the coil input without lag unless ``field_lag``
is set (in an augmented model a lag is the ``voltage_lag`` effect of :mod:`damper.diagnosis.effects`,
applied to the input).

References
----------
Spencer B.F. Jr., Dyke S.J., Sain M.K., Carlson J.D. (1997), *Phenomenological model for
magnetorheological dampers*, J. Eng. Mech. 123(3):230-238 (the series dashpot :math:`c_1`).
Bahar A., Pozo F., Acho L., Rodellar J., Barbat A. (2009), the seed paper (the extended model).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import ClassVar

import numpy as np

from damper.models.base import register_model
from benchmark.foundation.errors import ParameterError
from damper.models.bouc_wen import _check_voltage_range
from damper.models.spencer import SpencerTypeModel, pack_spencer_type
from damper.models.voltage_laws import (Constant, Exponential, ParameterLike, Polynomial, Saturating,
                                 SeedKappaW, Tabulated, VoltageLaw, _finite, as_law, check_law)

__all__ = ["SeriesDashpotBoucWen", "SpencerBoucWen", "DEFAULT_SERIES_SUBSTEP_TOLERANCE", "scaled_law"]

#: Default RK4 sub-step size (``lambda * h``) before the branch margin (see
#: :meth:`SeriesDashpotBoucWen.kernel_tolerance`).
DEFAULT_SERIES_SUBSTEP_TOLERANCE = 0.25
#: Field rate of the kernel [1/s]: the field follows the input within a microsecond (no lag).
_NO_LAG_RATE = 1.0e6


def scaled_law(law: VoltageLaw, factor: float) -> VoltageLaw:
    """``factor`` times ``law``, as a law of the same kind.

    Every law kind of :mod:`damper.models.voltage_laws` is linear in its amplitude coefficients
    (constant, polynomial and seed-κ_w coefficients, tabulated values, ``a`` and ``b`` of the
    exponential and saturating laws), so the scaled law is exact.

    Parameters
    ----------
    law : VoltageLaw
        The law.
    factor : float
        Dimensionless multiplier.

    Raises
    ------
    ParameterError
        For a non-finite or non-positive factor, or an unknown kind of law.
    """
    factor = float(factor)
    if not (math.isfinite(factor) and factor > 0.0):
        raise ParameterError(f"scaled_law: expected a finite factor > 0, got {factor!r}")
    if isinstance(law, Constant):
        return Constant(law.value * factor)
    if isinstance(law, Polynomial):
        return Polynomial(tuple(c * factor for c in law.coefficients))
    if isinstance(law, Tabulated):
        return replace(law, values=tuple(v * factor for v in law.values))
    if isinstance(law, SeedKappaW):
        return SeedKappaW(tuple(c * factor for c in law.k))
    if isinstance(law, (Exponential, Saturating)):
        return replace(law, a=law.a * factor, b=law.b * factor)
    raise ParameterError(f"scaled_law: a {type(law).__name__} law cannot be scaled; use a "
                         "constant, polynomial, tabulated, exponential, saturating or seed law")


def _constant(value, name: str) -> float:
    """A parameter that must not depend on the coil input (a number, or a law with one value)."""
    if isinstance(value, VoltageLaw):
        if value.is_constant:
            return float(value(0.0))
        raise ParameterError(f"SeriesDashpotBoucWen.{name}: expected a value independent of the "
                             f"coil input, got a {type(value).__name__} law")
    return _finite(value, f"SeriesDashpotBoucWen.{name}")


@register_model
@dataclass(frozen=True)
class SeriesDashpotBoucWen(SpencerTypeModel):
    """Extended Bouc-Wen element in series with a dashpot (equations in the module docstring).

    Parameters
    ----------
    kappa_x : float
        Parallel (accumulator) stiffness [N/m], >= 0.
    kappa_xdot : float or VoltageLaw
        Viscous coefficient of the element [N·s/m], > 0.
    kappa_w : float or VoltageLaw
        Force scale of the hysteretic variable [N], > 0.
    rho, sigma, n : float
        Bouc-Wen shape (ρ [1/m] > 0, σ >= 1/2, n >= 1), independent of the coil input.
    roll_off_velocity : float
        :math:`v_r = \\kappa_w / c_s` [m/s], > 0.
    voltage_range : tuple of float
        Admissible coil inputs [V] (or [A]).
    substep_tolerance : float
        RK4 sub-step size as ``lambda * h`` (default :data:`DEFAULT_SERIES_SUBSTEP_TOLERANCE`),
        widened by the branch margin of :meth:`kernel_tolerance`.
    field_lag : float
        Time constant :math:`\\tau` [s] of the field's first-order response to the coil input,
        :math:`\\tau\\dot u = v - u` (Spencer et al.'s :math:`\\eta = 1/\\tau`), >= 0; 0 (default):
        the field follows the input at once. The kernel updates the field exactly over each step,
        so the model with a lag runs in the building as it does in :func:`damper.simulate` (the
        ``voltage_lag`` effect of an augmented model, made part of the model).

    Examples
    --------
    >>> m = SeriesDashpotBoucWen(2e5, 1e5, 1e6, 100.0, 1.0, 1.5, roll_off_velocity=0.02)
    >>> round(m.series_damping(0.0) / 1e6, 3)  # c_s = kappa_w / v_r [MN s/m]
    50.0
    """

    kappa_x: float
    kappa_xdot: ParameterLike
    kappa_w: ParameterLike
    rho: float
    sigma: float
    n: float
    roll_off_velocity: float
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SERIES_SUBSTEP_TOLERANCE
    field_lag: float = 0.0

    name: ClassVar[str] = "series_dashpot_bouc_wen"
    n_states: ClassVar[int] = 3
    state_names: ClassVar[tuple[str, ...]] = ("y", "w", "u")
    parameter_names: ClassVar[tuple[str, ...]] = ("kappa_x", "kappa_xdot", "kappa_w", "rho", "sigma",
                                                  "n", "roll_off_velocity")

    def __post_init__(self) -> None:
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        for f in fields(self):
            if f.name in ("kappa_xdot", "kappa_w"):
                law = as_law(getattr(self, f.name), f"SeriesDashpotBoucWen.{f.name}")
                check_law(law, f.name, self.voltage_range, lower=0.0, strict=True)
                object.__setattr__(self, f.name, law if not isinstance(law, Constant) else law.value)
            elif f.name != "voltage_range":
                object.__setattr__(self, f.name, _constant(getattr(self, f.name), f.name))
        checks = (("kappa_x", self.kappa_x >= 0, ">= 0"), ("rho", self.rho > 0, "> 0"),
                  ("sigma", self.sigma >= 0.5, ">= 1/2"), ("n", self.n >= 1, ">= 1"),
                  ("roll_off_velocity", self.roll_off_velocity > 0, "> 0 m/s (0 is the extended model)"),
                  ("substep_tolerance", 0 < self.substep_tolerance <= 1, "in (0, 1]"),
                  ("field_lag", self.field_lag >= 0, ">= 0 s"))
        for name, ok, expected in checks:
            if not ok:
                raise ParameterError(f"SeriesDashpotBoucWen.{name}: expected {expected}, "
                                     f"got {getattr(self, name):g}")
        try:
            scaled_law(as_law(self.kappa_w), 1.0 / self.roll_off_velocity)
        except ParameterError as exc:
            raise ParameterError(f"SeriesDashpotBoucWen.kappa_w: the series dashpot "
                                 f"c_s = kappa_w / v_r needs a law it can scale: {exc}") from None

    @classmethod
    def from_bouc_wen(cls, base, roll_off_velocity: float,
                      substep_tolerance: float = DEFAULT_SERIES_SUBSTEP_TOLERANCE,
                      field_lag: float = 0.0) -> "SeriesDashpotBoucWen":
        """The series-dashpot model built on a normalized or extended Bouc-Wen ``base``.

        ``base`` keeps its parameters (``kappa_x = 0`` for the normalized model) and its
        voltage laws; its ρ, σ and n must not depend on the coil input. (The base's own
        sub-step tolerance belongs to another kernel and is not carried over.)

        Parameters
        ----------
        base
            A normalized or extended Bouc-Wen model.
        roll_off_velocity : float
            v_r = κ_w / c_s [m/s] (> 0).
        substep_tolerance : float, optional
            RK4 sub-step size as ``lambda * h``.
        field_lag : float, optional
            Time constant τ [s] of the field's response to the coil input (0: none).
        """
        return cls(kappa_x=getattr(base, "kappa_x", 0.0), kappa_xdot=base.kappa_xdot,
                   kappa_w=base.kappa_w, rho=base.rho, sigma=base.sigma, n=base.n,
                   roll_off_velocity=roll_off_velocity, voltage_range=base.voltage_range,
                   substep_tolerance=substep_tolerance, field_lag=field_lag)

    def series_damping(self, v: float) -> float:
        """:math:`c_s(v) = \\kappa_w(v) / v_r` [N·s/m].

        Parameters
        ----------
        v : float
            Coil input [V].
        """
        return float(as_law(self.kappa_w)(float(v))) / self.roll_off_velocity

    def kernel_tolerance(self) -> float:
        """The sub-step size of the kernel's bound that covers both branches:
        ``substep_tolerance * max(1, 2 sigma - 1)``, at most 1.

        The Spencer-type kernel's bound takes the unloading factor max(1, 2σ − 1); for σ > 1 it
        first tries a step on the loading rate alone at ``substep_tolerance`` (packed as its
        ``loading_tol``), and a step that meets the unloading branch, briefly after each
        reversal, is redone in sub-steps sized by the rate where each starts, at
        ``substep_tolerance`` too (:func:`damper.models.spencer._integrate_local`). This bound
        then only decides whether a step can be taken at all (at most
        :data:`damper.models.spencer.MAX_SUBSTEPS` sub-steps) and serves the steps whose loading
        count equals its own. Measured: at σ = 0.5 (no margin) the default 0.25 errs by 1e-4 at
        the peak where 1.0 would err by 1.3 %; at σ = 20 on a triangular stroke, by 4e-5 of the
        peak force (``tests/damper/test_series_dashpot.py``).
        """
        return min(1.0, self.substep_tolerance * max(1.0, 2.0 * self.sigma - 1.0))

    def to_array(self) -> np.ndarray:
        """Packed parameters (:func:`damper.models.spencer.pack_spencer_type` layout)."""
        return pack_spencer_type(self.kernel_tolerance(), **self._kernel_parameters(),
                                 loading_tol=self.substep_tolerance)

    def _kernel_parameters(self) -> dict:
        kappa_w = as_law(self.kappa_w)
        eta = 1.0 / self.field_lag if self.field_lag > 1.0 / _NO_LAG_RATE else _NO_LAG_RATE
        return dict(k0=0.0, k1=self.kappa_x, x0=0.0, eta=eta, rho=self.rho,
                    sigma=self.sigma, n=self.n, alpha_w=kappa_w, c0=as_law(self.kappa_xdot),
                    c1=scaled_law(kappa_w, 1.0 / self.roll_off_velocity))


@register_model
@dataclass(frozen=True)
class SpencerBoucWen(SpencerTypeModel):
    """Spencer et al.'s (1997) phenomenological model with the loop's names and voltage laws.

    .. math::

       F &= c_1(u)\\,\\dot y + \\kappa_x x, \\qquad
       \\dot y = \\frac{\\kappa_w(u)\\,w + \\kappa_{\\dot x}(u)\\,\\dot x + k_0 (x - y)}
                        {\\kappa_{\\dot x}(u) + c_1(u)} \\\\
       \\dot w &= \\rho\\left(\\dot r - \\sigma|\\dot r||w|^{n-1}w + (\\sigma-1)\\dot r|w|^n\\right),
          \\quad \\dot r = \\dot x - \\dot y, \\qquad \\tau\\dot u = v - u

    The Bouc-Wen element (force scale :math:`\\kappa_w = \\alpha z_0`, Spencer's
    :math:`\\alpha`), its viscous dashpot :math:`\\kappa_{\\dot x} = c_0` and spring
    :math:`k_0` act on :math:`x - y`; the dashpot :math:`c_1` in series carries their force
    (the low-velocity roll-off); :math:`\\kappa_x = k_1` is the accumulator spring in parallel;
    the field :math:`u` follows the command :math:`v` through a first-order filter of time
    constant :math:`\\tau` (Spencer's :math:`\\eta = 1/\\tau`). Unlike
    :class:`SeriesDashpotBoucWen` (``c_1 = kappa_w / v_r``, ``k_0 = 0``, the ``roll_off``
    effect), the series dashpot has its own voltage law and the element its spring, as in the
    original model; Spencer's force offset :math:`-k_1 x_0` is the loop's ``offset`` effect.
    It is the ``spencer`` base of the residual loop (``sbib diagnose --model spencer``), with
    :class:`~damper.models.voltage_laws.Tabulated` laws on two nodes (linear in the field) or three
    (a saturating shape), chosen by the data (:mod:`damper.diagnosis.base_fit`).

    Parameters
    ----------
    kappa_x : float
        Accumulator stiffness :math:`k_1` [N/m], >= 0.
    k0 : float
        Element stiffness [N/m], >= 0.
    kappa_xdot, kappa_w, c1 : float or VoltageLaw
        Element dashpot [N·s/m], hysteretic force scale [N] and series dashpot [N·s/m], > 0.
    rho, sigma, n : float
        Bouc-Wen shape (ρ [1/m] > 0, σ >= 1/2, n >= 1), independent of the field.
    field_lag : float
        :math:`\\tau` [s], >= 0 (0: the field follows the command at once).
    voltage_range : tuple of float
        Admissible commands [V] (or [A]).
    substep_tolerance : float
        RK4 sub-step size as ``lambda * h`` (see :meth:`SeriesDashpotBoucWen.kernel_tolerance`).

    Examples
    --------
    >>> m = SpencerBoucWen(500.0, 4.7e3, 2.1e3, 1.2e3, 2.8e4, 1e3, 1.0, 2.0, field_lag=0.005,
    ...                    voltage_range=(0.0, 2.25))
    >>> m.n_states
    3
    """

    kappa_x: float
    k0: float
    kappa_xdot: ParameterLike
    kappa_w: ParameterLike
    c1: ParameterLike
    rho: float
    sigma: float
    n: float
    field_lag: float = 0.0
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SERIES_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "spencer_bouc_wen"
    n_states: ClassVar[int] = 3
    state_names: ClassVar[tuple[str, ...]] = ("y", "w", "u")
    parameter_names: ClassVar[tuple[str, ...]] = ("kappa_x", "k0", "kappa_xdot", "kappa_w", "c1",
                                                  "rho", "sigma", "n", "field_lag")
    #: Parameters that cannot depend on the coil input (the kernel's constants).
    shared_parameters: ClassVar[frozenset] = frozenset(("kappa_x", "k0", "rho", "sigma", "n",
                                                        "field_lag"))

    def __post_init__(self) -> None:
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        for f in fields(self):
            if f.name in ("kappa_xdot", "kappa_w", "c1"):
                law = as_law(getattr(self, f.name), f"SpencerBoucWen.{f.name}")
                check_law(law, f.name, self.voltage_range, lower=0.0, strict=True)
                object.__setattr__(self, f.name, law if not isinstance(law, Constant) else law.value)
            elif f.name != "voltage_range":
                object.__setattr__(self, f.name, _finite(getattr(self, f.name), f"SpencerBoucWen.{f.name}"))
        checks = (("kappa_x", self.kappa_x >= 0, ">= 0"), ("k0", self.k0 >= 0, ">= 0"),
                  ("rho", self.rho > 0, "> 0"), ("sigma", self.sigma >= 0.5, ">= 1/2"),
                  ("n", self.n >= 1, ">= 1"), ("field_lag", self.field_lag >= 0, ">= 0 s"),
                  ("substep_tolerance", 0 < self.substep_tolerance <= 1, "in (0, 1]"))
        for name, ok, expected in checks:
            if not ok:
                raise ParameterError(f"SpencerBoucWen.{name}: expected {expected}, "
                                     f"got {getattr(self, name):g}")

    def kernel_tolerance(self) -> float:
        """As :meth:`SeriesDashpotBoucWen.kernel_tolerance`."""
        return min(1.0, self.substep_tolerance * max(1.0, 2.0 * self.sigma - 1.0))

    def to_array(self) -> np.ndarray:
        """Packed parameters (:func:`damper.models.spencer.pack_spencer_type` layout)."""
        return pack_spencer_type(self.kernel_tolerance(), **self._kernel_parameters(),
                                 loading_tol=self.substep_tolerance)

    def _kernel_parameters(self) -> dict:
        eta = 1.0 / self.field_lag if self.field_lag > 1.0 / _NO_LAG_RATE else _NO_LAG_RATE
        return dict(k0=self.k0, k1=self.kappa_x, x0=0.0, eta=eta, rho=self.rho,
                    sigma=self.sigma, n=self.n, alpha_w=as_law(self.kappa_w),
                    c0=as_law(self.kappa_xdot), c1=as_law(self.c1))
