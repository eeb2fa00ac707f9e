"""A library of physical effects that a base MR damper model may lack, each a term with its own parameter.

The residual loop (:mod:`damper.diagnosis`) extends a base model (normalized or extended
Bouc-Wen, :mod:`damper.models.bouc_wen`) by *composition* with these terms
(:class:`damper.diagnosis.augmented.AugmentedModel`). Every effect has one parameter, a *neutral* value at
which it vanishes (the base model is recovered exactly), physical bounds, and a role that says
where it enters the composition:

``series``
    puts the base model in series with another element (the base model is then simulated
    as that composite);
``input``
    transforms the coil input the base model sees;
``factor``
    multiplies the base model's force;
``additive``
    adds a force.

The augmented force is therefore

.. math::

   F = \\Big[\\prod_{\\text{factor}} g_j\\Big]\\,
       F_\\text{base}\\big(x, \\dot x;\\, u\\big) + \\sum_{\\text{additive}} f_k ,
   \\qquad u = \\text{input effects applied to } v .

The library (names are part of the command line and the JSON output):

=====================  ==========  ===============================================  ============
name                   role        term                                             parameter
=====================  ==========  ===============================================  ============
``stiffness``          additive    :math:`\\kappa_x\\,x` (accumulator, seed eq. 3)   ``kappa_x`` [N/m], >= 0
``offset``             additive    :math:`f_0` (accumulator preload)                ``f0`` [N]
``inertia``            additive    :math:`m\\,\\ddot x` (fluid and piston mass)      ``mass`` [kg], >= 0
``quadratic_damping``  additive    :math:`c_2\\,\\dot x|\\dot x|` (turbulent losses)  ``c2`` [N·s²/m²], >= 0
``asymmetry``          factor      :math:`1 + a\\,\\mathrm{sgn}(F_\\text{base})`      ``ratio`` [-], |a| < 1
``direction``          factor      :math:`1 + d\\,\\mathrm{sgn}\\,\\dot x`              ``ratio`` [-], |d| < 1
``fade``               factor      :math:`1 + \\phi\\,(t - t_0)`                     ``rate`` [1/s]
``voltage_lag``        input       :math:`\\tau\\dot u = v - u`                      ``tau`` [s], >= 0
``roll_off``           series      dashpot :math:`c_s = \\kappa_w/v_r` in series       ``velocity`` [m/s], >= 0
=====================  ==========  ===============================================  ============

* ``asymmetry``: extension (positive) forces are scaled by :math:`1 + a`, compression (negative)
  forces by :math:`1 - a`; :math:`F_\\text{base}(1 + a\\,\\mathrm{sgn}F_\\text{base}) =
  F_\\text{base} + a|F_\\text{base}|` is continuous in the force, so the term has no jump.
* ``shear_thinning``: a Herschel-Bulkley post-yield force (:math:`\\tau = \\tau_y +
  K\\dot\\gamma^m`, flow index :math:`m < 1`): refitted jointly with the base model's linear
  viscous term, :math:`\\kappa_{\\dot x}\\dot x + k\\,\\mathrm{sgn}\\dot x|\\dot x|^{1/2}` is a
  post-yield force that grows less than linearly with the velocity (concave), which the base
  model and ``quadratic_damping`` (convex) cannot express. The exponent is fixed at 1/2 (MR
  fluids' flow indices are about 0.3-0.9; a single coefficient keeps the term linear, so the
  loop's first-order screen sees it, and the mix with the linear term spans the range). It is
  also the law of a Bingham plastic in a valve gap near yield: in the slit form of the
  Buckingham-Reiner relation (the quasi-static parallel-plate model of MR valves, reviewed by
  Wang & Liao 2011) the flow rate grows with the square of the excess pressure, so the force
  above the yield force grows with :math:`|\\dot x|^{1/2}`. On the measured UTFSM damper joint
  refits with the exponent set to 0.1-0.75 held out best at 1/2 at 0, 0.5 and 1 A
  (docs/diagnosis.md).
* ``fade``: a slow linear change of the force level from the start :math:`t_0` of each test
  (heating thins the fluid); over one test a linear law is the first term of any smooth drift.
* ``roll_off``: the base model's Bouc-Wen element and viscous dashpot carry their force
  through a dashpot :math:`c_s = \\kappa_w / v_r` (Spencer et al.'s :math:`c_1`), so below about
  the roll-off velocity :math:`v_r` the force falls viscously instead of holding the yield
  force: the low-velocity roll-off of measured loops, which no rate-independent term
  produces (:class:`damper.models.series_dashpot.SeriesDashpotBoucWen`). ``velocity = 0`` is the
  base model itself.
* ``voltage_lag``: first-order field build-up (coil inductance, eddy currents). The filter is
  integrated exactly for an input that is linear between samples, so ``tau = 0`` returns the
  input unchanged.

References
----------
Bahar, Pozo, Acho, Rodellar, Barbat (2009): the elastic term :math:`\\kappa_x x` (seed eq. 3).
Spencer, Dyke, Sain, Carlson (1997), *Phenomenological model for magnetorheological dampers*,
J. Eng. Mech. 123(3): the first-order voltage filter :math:`\\dot u = -\\eta(u - v)` and the
series dashpot :math:`c_1` of the low-velocity roll-off.
Wang & Liao (2011), *Magnetorheological fluid dampers: a review of parametric modelling*,
Smart Mater. Struct. 20: accumulator stiffness and preload, fluid inertia, turbulence,
temperature, asymmetry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from benchmark.foundation.registry import Registry
from damper.models.field_filter import first_order_filter
from damper.models.force_terms import SHEAR_THINNING_EXPONENT, shear_thinning_force
from damper.models.series_dashpot import SeriesDashpotBoucWen

__all__ = [
    "Motion",
    "Effect",
    "Stiffness",
    "Offset",
    "Inertia",
    "VoltageLag",
    "RollOff",
    "QuadraticDamping",
    "ShearThinning",
    "Asymmetry",
    "Direction",
    "Fade",
    "EFFECTS",
    "EFFECT_NAMES",
    "FIELD_LAG_STARTS",
    "effect_names",
    "register_effect",
    "get_effect",
]


# ----------------------------------------------------------------------------- prescribed motion

@dataclass(frozen=True)
class Motion:
    """A prescribed motion of one test, the signals every model term may read (SI).

    Attributes
    ----------
    t : ndarray (n,)
        Strictly increasing time [s].
    x, xdot, xddot : ndarray (n,)
        Displacement [m], velocity [m/s], acceleration [m/s²].
    v : ndarray (n,)
        Coil input: voltage [V], or current [A] when the test gives a current (the model then
        reads the current as its input, in the same units).
    name : str
        Label of the test.
    substep_scale : float
        Factor on the base model's sub-step tolerance when this motion is simulated (>= 1; 1: the
        model's own). The residual loop's coarse pass sets it (:mod:`damper.diagnosis.coarse`,
        :func:`damper.models.base.with_coarser_substeps`).
    origin : float or None
        Time [s] at which the test began, when this motion is a window cut from a longer test
        (the coarse pass's windows, :mod:`damper.diagnosis.coarse`); ``None``: ``t[0]``. The time
        since the test began (:attr:`elapsed`, the ``fade`` effect's variable) counts from it.
    """

    t: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    v: np.ndarray
    name: str = ""
    substep_scale: float = 1.0
    origin: float | None = None

    def __post_init__(self) -> None:
        t = np.ascontiguousarray(np.asarray(self.t, dtype=np.float64))
        if t.ndim != 1 or t.size < 2:
            raise InputError(f"Motion {self.name!r}: t: expected a 1-D array of >= 2 samples, "
                             f"got shape {t.shape}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise InputError(f"Motion {self.name!r}: t: expected finite, strictly increasing times")
        object.__setattr__(self, "t", t)
        scale = self.substep_scale
        if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not (1.0 <= scale < math.inf):
            raise InputError(f"Motion {self.name!r}: substep_scale: expected a number >= 1, got {scale!r}")
        object.__setattr__(self, "substep_scale", float(scale))
        if self.origin is not None:
            origin = self.origin
            if isinstance(origin, bool) or not isinstance(origin, (int, float)) or not origin <= t[0]:
                raise InputError(f"Motion {self.name!r}: origin: expected a time <= t[0] = {t[0]:g} s, "
                                 f"got {origin!r}")
            object.__setattr__(self, "origin", float(origin))
        for field in ("x", "xdot", "xddot", "v"):
            arr = np.asarray(getattr(self, field), dtype=np.float64)
            if arr.ndim == 0:
                arr = np.full(t.size, float(arr))
            if arr.shape != t.shape:
                raise InputError(f"Motion {self.name!r}: {field}: expected {t.size} samples "
                                 f"(as many as t), got shape {arr.shape}")
            if not np.all(np.isfinite(arr)):
                i = int(np.argmax(~np.isfinite(arr)))
                raise InputError(f"Motion {self.name!r}: {field}: expected finite values, "
                                 f"sample {i} is {arr[i]}")
            object.__setattr__(self, field, np.ascontiguousarray(arr))

    @property
    def elapsed(self) -> np.ndarray:
        """Time since the start of the test, :math:`t - t_0` [s] (:math:`t_0` the ``origin``, if
        given, else the first sample's time)."""
        return self.t - (self.t[0] if self.origin is None else self.origin)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.t.size)


# ----------------------------------------------------------------------------------- base class

class Effect:
    """One physical effect: a term with one named parameter (see the module docstring).

    Subclasses are frozen dataclasses with a single field named ``parameter_name``. Class
    attributes: ``name`` (the library name), ``role`` (``"series"``, ``"input"``, ``"factor"``
    or ``"additive"``), ``unit``, ``neutral`` (the value at which the term vanishes), ``lower`` and
    ``upper`` (admissible interval), ``description``.
    """

    name: ClassVar[str]
    role: ClassVar[str]
    parameter_name: ClassVar[str]
    unit: ClassVar[str]
    neutral: ClassVar[float] = 0.0
    lower: ClassVar[float] = -math.inf
    upper: ClassVar[float] = math.inf
    description: ClassVar[str]
    #: Residual-trace variables (:data:`damper.diagnosis.trace.TRACE_VARIABLES`, plus ``mean``)
    #: where the missing term shows up: the loop tries the effect whenever the trace names one.
    traces: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        # every effect's one parameter is checked on construction (the dataclass __init__ calls this)
        self._validate()

    def _validate(self) -> None:
        raw = getattr(self, self.parameter_name)
        if isinstance(raw, bool):
            raise ParameterError(f"{self.name}.{self.parameter_name}: expected a number, got {raw!r}")
        try:
            value = float(raw)
        except (TypeError, ValueError):
            raise ParameterError(f"{self.name}.{self.parameter_name}: expected a number, "
                                 f"got {raw!r}") from None
        if not math.isfinite(value) or not (self.lower <= value <= self.upper):
            raise ParameterError(f"{self.name}.{self.parameter_name}: expected a finite value in "
                                 f"[{self.lower:g}, {self.upper:g}] {self.unit}, got {value!r}")
        object.__setattr__(self, self.parameter_name, value)

    # -- parameter access --------------------------------------------------------------------
    @property
    def value(self) -> float:
        """The parameter value (SI, unit ``self.unit``)."""
        return float(getattr(self, self.parameter_name))

    @property
    def parameters(self) -> dict[str, float]:
        """``{parameter_name: value}``."""
        return {self.parameter_name: self.value}

    def to_array(self) -> np.ndarray:
        """The parameter as a one-element ``float64`` array."""
        return np.array([self.value])

    @classmethod
    def from_value(cls, value: float) -> "Effect":
        """The effect with parameter ``value`` (clipped into ``[lower, upper]``).

        Parameters
        ----------
        value : float
            Parameter value of the effect (SI), clipped into ``[lower, upper]``.
        """
        return cls(float(min(max(float(value), cls.lower), cls.upper)))

    @classmethod
    def off(cls) -> "Effect":
        """The effect at its neutral value (the term vanishes)."""
        return cls(cls.neutral)

    @classmethod
    def scale(cls, motions: "list[Motion]", force_rms: float) -> float:
        """A typical parameter size for these data: the value whose term is about the force RMS.

        Used to scale the optimiser's variables and finite-difference steps.

        Parameters
        ----------
        motions : 'list[Motion]'
            The prescribed motions of the tests (:class:`damper.diagnosis.effects.Motion`).
        force_rms : float
            RMS of the measured force [N].
        """
        raise NotImplementedError

    @classmethod
    def start_grid(cls, motions: "list[Motion]") -> tuple[float, ...]:
        """Values from which the effect's joint refit also starts, for a parameter whose
        least-squares landscape has several minima (a few evaluations from each and from the
        effect-only refit's value, the best goes on: :mod:`damper.diagnosis.selection`); empty
        (the default): the effect-only refit's value alone.

        Parameters
        ----------
        motions : 'list[Motion]'
            The prescribed motions of the tests (:class:`damper.diagnosis.effects.Motion`).
        """
        return ()

    @classmethod
    def not_identifiable(cls, motions: "list[Motion]") -> str | None:
        """Why the effect cannot be seen in these data (``None`` when it can).

        Parameters
        ----------
        motions : 'list[Motion]'
            The prescribed motions of the tests (:class:`damper.diagnosis.effects.Motion`).
        """
        return None

    # -- the term ---------------------------------------------------------------------------
    def series_base(self, base):
        """Series role: the model simulated in place of the base model ``base``.

        Parameters
        ----------
        base
            The base model.
        """
        raise NotImplementedError

    def transform_input(self, motion: Motion, v: np.ndarray) -> np.ndarray:
        """Input role: the coil input the base model sees.

        Parameters
        ----------
        motion : Motion
            The prescribed motion of one test (:class:`damper.diagnosis.effects.Motion`: time, displacement, velocity,
            acceleration, coil input; SI).
        v : np.ndarray
            Coil input the test gives [V] (or [A]).
        """
        raise NotImplementedError

    def factor(self, motion: Motion, base_force: np.ndarray) -> np.ndarray:
        """Factor role: the multiplier of the base force.

        Parameters
        ----------
        motion : Motion
            The prescribed motion of one test (:class:`damper.diagnosis.effects.Motion`: time, displacement, velocity,
            acceleration, coil input; SI).
        base_force : np.ndarray
            Force of the base model [N] under ``motion``.
        """
        raise NotImplementedError

    def force(self, motion: Motion) -> np.ndarray:
        """Additive role: the added force [N].

        Parameters
        ----------
        motion : Motion
            The prescribed motion of one test (:class:`damper.diagnosis.effects.Motion`: time, displacement, velocity,
            acceleration, coil input; SI).
        """
        raise NotImplementedError

    def __str__(self) -> str:
        return f"{self.name}({self.parameter_name}={self.value:.6g} {self.unit})"


_ROLES = ("series", "input", "factor", "additive")


def _check_effect(cls: type) -> str | None:
    if getattr(cls, "role", None) not in _ROLES:
        return f"role {getattr(cls, 'role', None)!r}; expected one of {', '.join(_ROLES)}"
    for attr in ("parameter_name", "unit", "description"):
        if not isinstance(getattr(cls, attr, None), str):
            return f"no {attr} (a class attribute, a str)"
    return None


#: Registered effects by name, in the order the loop lists candidates (filled by :func:`register_effect`).
EFFECTS: Registry = Registry("effect", Effect, _check_effect)


def register_effect(cls):
    """Register an effect class under its ``name`` (a class decorator) and return it.

    A new effect is one decorated frozen dataclass deriving from :class:`Effect` (one field named
    by ``parameter_name``; ``role``, ``unit``, ``neutral``, bounds, ``description``, ``traces``):
    the residual loop then lists it among its candidates, the model file reads it and
    ``sbib diagnose --effects`` accepts it.

    Parameters
    ----------
    cls : type
        An :class:`Effect` subclass.

    Returns
    -------
    type
        ``cls`` itself.

    Raises
    ------
    InputError
        If ``cls`` is not an :class:`Effect` subclass, has no name, an unknown role, or its name
        is already taken by another class.
    """
    return EFFECTS.register(cls)


def _rms(a: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(a)))) if a.size else 0.0


def _pooled_rms(motions, field: str) -> float:
    values = np.concatenate([getattr(m, field) for m in motions])
    return _rms(values)


def _zero_throughout(motions, field: str, what: str) -> str | None:
    """The reason an effect driven by ``field`` cannot be seen, or ``None`` when it moves."""
    return f"the {what} is zero throughout" if _pooled_rms(motions, field) == 0.0 else None


# ------------------------------------------------------------------------------- the library

@register_effect
@dataclass(frozen=True)
class Stiffness(Effect):
    """Linear elastic force :math:`\\kappa_x x` [N] (accumulator stiffness; seed eq. 3).

    Parameters
    ----------
    kappa_x : float
        Stiffness [N/m], >= 0.
    """

    kappa_x: float
    name: ClassVar[str] = "stiffness"
    role: ClassVar[str] = "additive"
    parameter_name: ClassVar[str] = "kappa_x"
    unit: ClassVar[str] = "N/m"
    lower: ClassVar[float] = 0.0
    description: ClassVar[str] = "linear elastic force kappa_x*x (accumulator stiffness)"
    traces: ClassVar[tuple[str, ...]] = ("displacement", "loop")

    @classmethod
    def scale(cls, motions, force_rms):
        return force_rms / max(_pooled_rms(motions, "x"), 1e-12)

    def force(self, motion):
        return self.kappa_x * motion.x


@register_effect
@dataclass(frozen=True)
class Offset(Effect):
    """Constant force :math:`f_0` [N] (accumulator preload).

    Parameters
    ----------
    f0 : float
        Offset force [N].
    """

    f0: float
    name: ClassVar[str] = "offset"
    role: ClassVar[str] = "additive"
    parameter_name: ClassVar[str] = "f0"
    unit: ClassVar[str] = "N"
    description: ClassVar[str] = "constant force f0 (accumulator preload)"
    traces: ClassVar[tuple[str, ...]] = ("mean",)

    @classmethod
    def scale(cls, motions, force_rms):
        return force_rms

    def force(self, motion):
        return np.full(motion.n_samples, self.f0)


@register_effect
@dataclass(frozen=True)
class Inertia(Effect):
    """Inertial force :math:`m\\ddot x` [N] (fluid and piston mass).

    Parameters
    ----------
    mass : float
        Effective mass [kg], >= 0.
    """

    mass: float
    name: ClassVar[str] = "inertia"
    role: ClassVar[str] = "additive"
    parameter_name: ClassVar[str] = "mass"
    unit: ClassVar[str] = "kg"
    lower: ClassVar[float] = 0.0
    description: ClassVar[str] = "inertial force m*xddot (fluid and piston mass)"
    traces: ClassVar[tuple[str, ...]] = ("acceleration",)

    @classmethod
    def scale(cls, motions, force_rms):
        return force_rms / max(_pooled_rms(motions, "xddot"), 1e-12)

    @classmethod
    def not_identifiable(cls, motions):
        return _zero_throughout(motions, "xddot", "acceleration")

    def force(self, motion):
        return self.mass * motion.xddot


#: Field time constants [s] from which a field lag's fit starts (MR dampers' coils and eddy
#: currents: a few to a few tens of milliseconds): ``VoltageLag.start_grid`` and the Spencer-type
#: base's projection stage (:data:`damper.diagnosis.base_fit.TAU_GRID`).
FIELD_LAG_STARTS = (0.0025, 0.005, 0.01, 0.02, 0.04, 0.08)


@register_effect
@dataclass(frozen=True)
class VoltageLag(Effect):
    """First-order field dynamics: the base model sees :math:`u` with :math:`\\tau\\dot u = v - u`.

    Parameters
    ----------
    tau : float
        Time constant [s], >= 0 (``0``: no lag). Spencer et al. (1997) write
        :math:`\\eta = 1/\\tau`.
    """

    tau: float
    name: ClassVar[str] = "voltage_lag"
    role: ClassVar[str] = "input"
    parameter_name: ClassVar[str] = "tau"
    unit: ClassVar[str] = "s"
    lower: ClassVar[float] = 0.0
    upper: ClassVar[float] = 10.0
    description: ClassVar[str] = "first-order filter tau*du/dt = v - u on the coil input"
    traces: ClassVar[tuple[str, ...]] = ("voltage_rate", "voltage")

    @classmethod
    def scale(cls, motions, force_rms):
        return 0.01

    @classmethod
    def start_grid(cls, motions):
        # under a random command the joint refit of tau can stay in a minimum near one sample of
        # the coarse pass instead of the field's own (ranran_50: 0.7 ms against 8.6 ms, the
        # loop's error 0.21 against 0.113, docs/diagnosis.md); the grid spans MR dampers' lags.
        # Between tests at constant inputs the lag's landscape is that of the warm-ups: no grid
        if all(np.ptp(m.v) <= 1e-12 for m in motions):
            return ()
        return FIELD_LAG_STARTS

    @classmethod
    def not_identifiable(cls, motions):
        if all(np.ptp(m.v) == 0.0 for m in motions):
            return "the coil input is constant in every test"
        return None

    def transform_input(self, motion, v):
        return first_order_filter(motion.t, v, self.tau)


@register_effect
@dataclass(frozen=True)
class QuadraticDamping(Effect):
    """Turbulent (velocity-squared) loss :math:`c_2\\dot x|\\dot x|` [N].

    Parameters
    ----------
    c2 : float
        Quadratic damping coefficient [N·s²/m²], >= 0.
    """

    c2: float
    name: ClassVar[str] = "quadratic_damping"
    role: ClassVar[str] = "additive"
    parameter_name: ClassVar[str] = "c2"
    unit: ClassVar[str] = "N*s^2/m^2"
    lower: ClassVar[float] = 0.0
    description: ClassVar[str] = "turbulent loss c2*xdot*|xdot|"
    traces: ClassVar[tuple[str, ...]] = ("velocity",)

    @classmethod
    def scale(cls, motions, force_rms):
        return force_rms / max(_pooled_rms(motions, "xdot") ** 2, 1e-24)

    def force(self, motion):
        return self.c2 * motion.xdot * np.abs(motion.xdot)


@register_effect
@dataclass(frozen=True)
class ShearThinning(Effect):
    """Shear-thinning (Herschel-Bulkley) post-yield force :math:`k\\,\\mathrm{sgn}(\\dot x)|\\dot x|^{1/2}` [N].

    The sign is linear within 0.1 mm/s (:func:`damper.models.force_terms.shear_thinning_force`): the
    term's slope at rest is finite, as the building's step needs.

    Beside the base model's linear viscous term it makes the post-yield force grow less than
    linearly with the velocity (see the module docstring).

    Parameters
    ----------
    k : float
        Coefficient [N·(s/m)^½], >= 0.
    """

    k: float
    name: ClassVar[str] = "shear_thinning"
    role: ClassVar[str] = "additive"
    parameter_name: ClassVar[str] = "k"
    unit: ClassVar[str] = "N*(s/m)^0.5"
    lower: ClassVar[float] = 0.0
    #: Flow index of the term.
    exponent: ClassVar[float] = SHEAR_THINNING_EXPONENT
    description: ClassVar[str] = "shear-thinning post-yield force k*sgn(xdot)*|xdot|^0.5"
    traces: ClassVar[tuple[str, ...]] = ("velocity",)

    @classmethod
    def scale(cls, motions, force_rms):
        return force_rms / max(_pooled_rms(motions, "xdot") ** cls.exponent, 1e-12)

    @classmethod
    def not_identifiable(cls, motions):
        return _zero_throughout(motions, "xdot", "velocity")

    def force(self, motion):
        # the sign is linear within 0.1 mm/s, as in the building (damper.models.force_terms)
        return shear_thinning_force(self.k, motion.xdot)


@register_effect
@dataclass(frozen=True)
class Asymmetry(Effect):
    """Different force levels in extension and compression: factor :math:`1 + a\\,\\mathrm{sgn}F_\\text{base}`.

    Parameters
    ----------
    ratio : float
        :math:`a` [-], ``-0.9 <= a <= 0.9``: extension forces are scaled by ``1 + a``,
        compression forces by ``1 - a``.
    """

    ratio: float
    name: ClassVar[str] = "asymmetry"
    role: ClassVar[str] = "factor"
    parameter_name: ClassVar[str] = "ratio"
    unit: ClassVar[str] = "-"
    lower: ClassVar[float] = -0.9
    upper: ClassVar[float] = 0.9
    description: ClassVar[str] = "force level (1+a) in extension, (1-a) in compression"
    traces: ClassVar[tuple[str, ...]] = ("sign", "loop")

    @classmethod
    def scale(cls, motions, force_rms):
        return 0.1

    def factor(self, motion, base_force):
        return 1.0 + self.ratio * np.sign(base_force)


@register_effect
@dataclass(frozen=True)
class Direction(Effect):
    """Different force levels in the two directions of motion: factor :math:`1 + d\\,\\mathrm{sgn}\\,\\dot x`.

    A damper whose valves or seals differ between extension and compression strokes carries a
    larger force, at the same speed and voltage, in one direction of *motion*. ``asymmetry``
    scales by the sign of the force, which differs from the direction of motion after each
    reversal (until the hysteretic force has turned over); this term scales the whole force by
    the direction the piston moves in.

    Parameters
    ----------
    ratio : float
        :math:`d` [-], ``-0.9 <= d <= 0.9``: forces while :math:`\\dot x > 0` are scaled by
        ``1 + d``, while :math:`\\dot x < 0` by ``1 - d`` (``1`` at rest).
    """

    ratio: float
    name: ClassVar[str] = "direction"
    role: ClassVar[str] = "factor"
    parameter_name: ClassVar[str] = "ratio"
    unit: ClassVar[str] = "-"
    lower: ClassVar[float] = -0.9
    upper: ClassVar[float] = 0.9
    description: ClassVar[str] = "force level (1+d) while xdot > 0, (1-d) while xdot < 0"
    traces: ClassVar[tuple[str, ...]] = ("sign", "loop")

    @classmethod
    def scale(cls, motions, force_rms):
        return 0.1

    @classmethod
    def not_identifiable(cls, motions):
        return _zero_throughout(motions, "xdot", "velocity")

    def factor(self, motion, base_force):
        return 1.0 + self.ratio * np.sign(motion.xdot)


@register_effect
@dataclass(frozen=True)
class Fade(Effect):
    """Slow linear change of the force level over a test: factor :math:`1 + \\phi\\,(t - t_0)`.

    Parameters
    ----------
    rate : float
        :math:`\\phi` [1/s], the fractional change of the force level per second (negative
        when the force fades, e.g. as the fluid heats). The factor must stay positive over the
        test (checked when the term is evaluated).
    """

    rate: float
    name: ClassVar[str] = "fade"
    role: ClassVar[str] = "factor"
    parameter_name: ClassVar[str] = "rate"
    unit: ClassVar[str] = "1/s"
    description: ClassVar[str] = "force level changing linearly with the time since the test began"
    traces: ClassVar[tuple[str, ...]] = ("time",)

    @classmethod
    def scale(cls, motions, force_rms):
        longest = max(float(m.elapsed[-1]) for m in motions)
        return 0.1 / max(longest, 1e-9)

    def factor(self, motion, base_force):
        g = 1.0 + self.rate * motion.elapsed
        if np.any(g <= 0.0):
            raise ParameterError(f"fade.rate: {self.rate:g} 1/s drives the force level to zero "
                                 f"within test {motion.name!r}; expected rate > "
                                 f"{-1.0 / float(motion.elapsed[-1]):.4g} 1/s")
        return g


@register_effect
@dataclass(frozen=True)
class RollOff(Effect):
    """Low-velocity roll-off: the base model in series with a dashpot :math:`c_s = \\kappa_w / v_r`.

    Parameters
    ----------
    velocity : float
        Roll-off velocity :math:`v_r` [m/s], >= 0 (``0``: no roll-off, the base model). See
        :class:`damper.models.series_dashpot.SeriesDashpotBoucWen` for the equations; the base model's
        ρ, σ and n must not depend on the coil input.
    """

    velocity: float
    name: ClassVar[str] = "roll_off"
    role: ClassVar[str] = "series"
    parameter_name: ClassVar[str] = "velocity"
    unit: ClassVar[str] = "m/s"
    lower: ClassVar[float] = 0.0
    upper: ClassVar[float] = 10.0  # beyond any MR damper's velocity range
    description: ClassVar[str] = ("dashpot c_s = kappa_w/v_r in series with the base model "
                                  "(force rolls off viscously below about v_r)")
    traces: ClassVar[tuple[str, ...]] = ("velocity", "loop")

    @classmethod
    def scale(cls, motions, force_rms):
        return 0.5 * max(_pooled_rms(motions, "xdot"), 1e-12)

    @classmethod
    def not_identifiable(cls, motions):
        return _zero_throughout(motions, "xdot", "velocity")

    def series_base(self, base):
        """The model simulated in place of ``base``: ``base`` itself at ``velocity = 0``.

        Parameters
        ----------
        base
            The base model.
        """
        if self.velocity == 0.0:
            return base
        return SeriesDashpotBoucWen.from_bouc_wen(base, self.velocity)


#: The library (the effect names the residual loop lists, in their registration order).
EFFECT_NAMES: tuple[str, ...] = tuple(EFFECTS)


def effect_names() -> tuple[str, ...]:
    """Names of every registered effect: the library's, then those registered since.

    Returns
    -------
    tuple of str
        Registered names, in the order the residual loop lists its candidates.
    """
    return tuple(EFFECTS)


def get_effect(name: str) -> type[Effect]:
    """The effect class named ``name`` (raises :class:`InputError` listing the library).

    Parameters
    ----------
    name : str
        Effect name (:data:`damper.diagnosis.effects.EFFECTS`).
    """
    cls = EFFECTS.get(name) if isinstance(name, str) else None
    if cls is None:
        raise InputError(f"effect: unknown name {name!r}; expected one of " + ", ".join(effect_names()))
    return cls
