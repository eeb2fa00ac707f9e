"""Augmented damper model: a base Bouc-Wen model composed with effect terms, and its joint refit.

An :class:`AugmentedModel` holds a base model from :mod:`damper.models.bouc_wen` (normalized or
extended, constant parameters or voltage laws) and a tuple of effects from
:mod:`damper.diagnosis.effects`. It does not copy the base model: the base force comes from
:func:`damper.simulate` (the same compiled kernels the building runs), and the effects are
applied around it,

.. math::

   u = \\mathcal{I}(v), \\qquad
   F = \\Big[\\prod_j g_j(F_\\text{base})\\Big] F_\\text{base}(x, \\dot x; u)
       + \\sum_k f_k(x, \\dot x, \\ddot x, t),

with :math:`F_\\text{base}` the base model, or the base model in series with the ``roll_off``
dashpot (:class:`~damper.models.series_dashpot.SeriesDashpotBoucWen`) when that effect is present,
:math:`\\mathcal I` the input effects (``voltage_lag``), :math:`g_j` the factor effects
(``asymmetry``, ``fade``) and :math:`f_k` the additive ones (``stiffness``, ``offset``,
``inertia``, ``quadratic_damping``).

:class:`Parametrization` maps the free parameters of an augmented model (the base model's
parameters, constant or as node values of :class:`~damper.models.voltage_laws.Tabulated` laws, and one
value per effect) to a flat vector and back, with bounds and scales; :func:`refit` adjusts them
all jointly by bounded nonlinear least squares (:func:`scipy.optimize.least_squares`, trust-region
reflective) on a set of tests, counting only the samples a mask selects (the training part)
while every test is simulated from its start.

References
----------
Bahar, Pozo, Acho, Rodellar, Barbat (2009): the extended model is the normalized model
composed with ``stiffness``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np

from damper.fitting import least_squares_fit
from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.models.base import DamperModel, with_coarser_substeps
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.diagnosis.effects import EFFECTS, Effect, Motion, effect_names, get_effect
from damper.models.force_terms import WithForceTerms
from damper.models.series_dashpot import SeriesDashpotBoucWen, SpencerBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Tabulated, VoltageLaw

__all__ = [
    "Motion",
    "AugmentedModel", "BaseForceMemo",
    "AugmentedResponse",
    "Parametrization",
    "RefitResult",
    "refit",
    "refit_from_starts",
    "START_NFEV",
    "base_at_bounds",
    "BASE_MODELS",
    "make_base",
    "BASE_DECLARES",
    "TERM_EFFECTS",
    "NOT_IN_BUILDING",
]

#: Base model kinds accepted by the loop.
BASE_MODELS: dict[str, type] = {"normalized": NormalizedBoucWen, "extended": ExtendedBoucWen,
                                "spencer": SpencerBoucWen}
#: Effects a base kind already carries in its own equations (never added to it): the extended
#: and Spencer-type bases have kappa_x x; the Spencer-type base has its series dashpot c1 and
#: its field filter.
BASE_DECLARES: dict[str, tuple[str, ...]] = {"normalized": (), "extended": ("stiffness",),
                                             "spencer": ("stiffness", "roll_off", "voltage_lag")}

#: Effects that run in the building as force terms (:class:`~damper.models.force_terms.WithForceTerms`,
#: whose field names are the effect names): :meth:`AugmentedModel.building_model`.
TERM_EFFECTS = ("asymmetry", "shear_thinning", "quadratic_damping")
#: Why the building leaves an effect out (:meth:`AugmentedModel.building_model`); a
#: ``voltage_lag`` without ``roll_off`` has no field state in the Bouc-Wen kernels.
NOT_IN_BUILDING = {
    "offset": ("a constant force (an accumulator's preload, or the load cell's zero in the tests): not run, "
               "a damper is installed in the building at rest"),
    "fade": ("the force level's drift over a test (the fluid heating) depends on that test's history and "
             "length, not on the building's motion: not run"),
    "inertia": "the building's devices have no mass of their own: not run",
    "direction": ("a force level that jumps by 2*ratio*F at every reversal, which the building's step "
                  "does not converge on at building scale (damper/models/force_terms.py): not run"),
}

_ROLE_ORDER = {"series": 0, "input": 1, "factor": 2, "additive": 3}
#: Base parameters a series effect needs independent of the coil input.
_SERIES_SHARED = ("kappa_x", "rho", "sigma", "n")
# Admissible class of the base parameters (bouc_wen: kappa > 0, sigma >= 1/2, n >= 1); n is capped
# to keep the kernel's sub-stepping affordable.
_BASE_LOWER_REL = 1e-9
_BASE_BOUNDS = {"sigma": (0.5, 50.0), "n": (1.0, 10.0)}
# Base parameters whose admissible class starts at zero (springs, the field lag).
_BASE_ZERO_LOWER = ("kappa_x", "k0", "field_lag")
# The field lag [s] is bounded by a second: a longer one is no MR damper's coil.
_BASE_UPPER = {"field_lag": 1.0}


@dataclass(frozen=True)
class AugmentedResponse:
    """Response of an augmented model to a prescribed motion (SI).

    Attributes
    ----------
    force : ndarray (n,)
        Total force [N].
    base_force : ndarray (n,)
        Force of the base model (under the transformed input; with a ``series`` effect, of the
        base model in series with it) [N].
    model_input : ndarray (n,)
        Coil input the base model saw (after input effects) [V or A].
    terms : dict of str to ndarray
        Each factor and additive effect's contribution to the force [N] (for a factor effect:
        :math:`(g_j - 1)` times the force it scaled); a series effect changes ``base_force``
        itself and has no entry.
    """

    force: np.ndarray
    base_force: np.ndarray
    model_input: np.ndarray
    terms: dict = field(default_factory=dict)


def make_base(kind: str, parameters: dict, voltage_range: tuple[float, float] = (0.0, 1.0)):
    """The base model of ``kind`` ("normalized" or "extended") from a parameter dict (SI).

    Values may be numbers or :class:`~damper.models.voltage_laws.VoltageLaw` objects; extra keys
    (``kappa_x`` for the normalized model) are ignored.

    Parameters
    ----------
    kind : str
        ``"normalized"`` or ``"extended"``.
    parameters : dict
        Parameter values by name (SI): numbers or :class:`~damper.models.voltage_laws.VoltageLaw` objects.
    voltage_range : tuple[float, float], optional
        Admissible coil inputs ``(min, max)`` [V] (or [A]); the voltage laws are checked over it.
    """
    try:
        cls = BASE_MODELS[kind]
    except KeyError:
        raise InputError(f"model: expected one of {', '.join(BASE_MODELS)}, got {kind!r}") from None
    values = {k: parameters[k] for k in cls.parameter_names}
    return cls(**values, voltage_range=tuple(voltage_range))


def _base_kind(base) -> str:
    for kind, cls in BASE_MODELS.items():
        if type(base) is cls:
            return kind
    raise InputError(f"augmented model: base must be NormalizedBoucWen, ExtendedBoucWen or SpencerBoucWen, got "
                     f"{type(base).__name__}")


class BaseForceMemo:
    """The last few base-force histories simulated under one motion, by base model and input.

    A finite-difference Jacobian perturbs one parameter at a time, and two kinds of column need
    no new simulation:

    * the parameters of the additive and factor effects (stiffness, offset, inertia, ..., fade):
      the base model and its input are the ones of the centre point, whose force the kernel has
      just computed. The memo returns that history: the same numbers, bit for bit (the key is
      everything the kernel reads: its family, packed parameters, initial state, voltage range
      and input; the motion is the memo's own);
    * the base parameters that only read the force off the state (a Bouc-Wen base's κ_x, κ_ẋ,
      κ_w at each voltage node): a base whose ``state_parameters`` (the ones its state's evolution
      reads, :meth:`damper.models.bouc_wen.NormalizedBoucWen.state_parameters`), initial state
      and input are those of a history held here follows the same state history. The memo
      returns that history's kernel force plus the change of ``force_history`` between the two
      bases: equal to the kernel's force to rounding (1e-16 of the force), far below what a
      Jacobian's step of 1e-6 can see. These are 2 of the normalized base's 5 parameters and 3
      of the extended base's 6.

    Keys are the bytes of what they compare, looked up in a dictionary: a refit calls the memo
    tens of thousands of times with histories of thousands of samples, and comparing arrays
    entry by entry cost a third of the closed loop's refits (measured 2026-11-26).

    Parameters
    ----------
    size : int
        Histories kept (least recently used first out). A Jacobian's columns for the base
        parameters come before the effects' (:class:`Parametrization`), so the centre point must
        survive one new history per base parameter: :func:`refit` keeps two more than it has
        free parameters.
    """

    def __init__(self, size: int = 8) -> None:
        self.size = int(size)
        self._entries: dict = {}   # exact key -> (force, state key, base, response), oldest first
        self._by_state: dict = {}  # state key -> exact key of the latest such history
        self.hits = 0
        self.misses = 0
        #: Histories read off a held state history (a base differing only in its force's parameters).
        self.reads = 0

    def base_force(self, base, motion: Motion, u) -> np.ndarray:
        """The base model's force [N] under ``motion`` with coil input ``u`` (read-only array).

        Parameters
        ----------
        base : damper model
            The base model as the kernel simulates it (series effects and coarsening applied).
        motion : Motion
            The motion this memo belongs to.
        u : float or ndarray
            The coil input the base sees (after the input effects).
        """
        u_arr = np.asarray(u, dtype=float)
        common = (type(base), tuple(base.voltage_range),
                  np.asarray(base.initial_state(), dtype=float).tobytes(), u_arr.shape, u_arr.tobytes())
        key = common + (base.to_array().tobytes(),)
        entry = self._entries.pop(key, None)
        if entry is not None:
            self.hits += 1
            self._entries[key] = entry  # most recently used last
            return entry[0]
        split = getattr(base, "state_parameters", None)
        state_key = None if split is None else common + (split().tobytes(),)
        held = self._entries.get(self._by_state.get(state_key)) if state_key is not None else None
        if held is not None:
            self.reads += 1
            return self._read_off(held, base, motion)
        self.misses += 1
        response = simulate(base, motion.t, motion.x, motion.xdot, u)
        force = response.force
        force.setflags(write=False)
        # the state history is kept only where a later base may read its force off it
        self._entries[key] = (force, state_key, base, response if state_key is not None else None, {})
        if state_key is not None:
            self._by_state[state_key] = key
        if len(self._entries) > self.size:
            oldest = next(iter(self._entries))
            old_state = self._entries.pop(oldest)[1]
            if old_state is not None and self._by_state.get(old_state) == oldest:
                del self._by_state[old_state]
        return force

    @staticmethod
    def _read_off(entry, base, motion: Motion) -> np.ndarray:
        """The force of ``base``, whose state history is ``entry``'s: the entry's kernel force plus
        the change of the force read off that history (see the class docstring)."""
        force, _, held_base, response, cache = entry
        if "force" not in cache:
            cache["force"] = held_base.force_history(motion.x, motion.xdot, response.voltage, response.states)
        force = force + (base.force_history(motion.x, motion.xdot, response.voltage, response.states) - cache["force"])
        force.setflags(write=False)
        return force


@dataclass(frozen=True)
class AugmentedModel:
    """A base damper model composed with effect terms (see the module docstring).

    Parameters
    ----------
    base : NormalizedBoucWen, ExtendedBoucWen or SpencerBoucWen
        The base model (constant parameters or voltage laws).
    effects : sequence of Effect
        Effect terms, at most one of each name; a term the base already carries is refused
        (:data:`BASE_DECLARES`: ``stiffness`` on the extended base, ...). They are kept in
        composition order (series, input, factor, additive; library order within a role).
    held : tuple of str
        Base parameters that :func:`refit` holds at their values (e.g. the Spencer-type base's
        field lag when the coil input never changes within a test: it cannot be seen there).

    Examples
    --------
    >>> from damper.models.bouc_wen import NormalizedBoucWen
    >>> from damper.diagnosis.effects import Stiffness
    >>> m = AugmentedModel(NormalizedBoucWen(1e3, 5e3, 300.0, 1.0, 1.0), (Stiffness(2e4),))
    >>> m.effect_names
    ('stiffness',)
    """

    base: object
    effects: tuple = ()
    held: tuple = ()

    def __post_init__(self) -> None:
        kind = _base_kind(self.base)
        effects = tuple(self.effects)
        for e in effects:
            if not isinstance(e, Effect):
                raise ParameterError(f"augmented model: effects: expected Effect instances, got "
                                     f"{type(e).__name__}")
        names = [e.name for e in effects]
        if len(set(names)) != len(names):
            raise ParameterError(f"augmented model: effects: each effect at most once, got {names}")
        for name in BASE_DECLARES[kind]:
            if name in names:
                term = {"stiffness": "kappa_x*x", "roll_off": "its series dashpot c1",
                        "voltage_lag": "its field lag"}.get(name, name)
                raise ParameterError(f"augmented model: the {kind} base already has {term}; "
                                     f"do not add the {name} effect")
        order = {n: i for i, n in enumerate(effect_names())}
        effects = tuple(sorted(effects, key=lambda e: (_ROLE_ORDER[e.role], order[e.name])))
        object.__setattr__(self, "effects", effects)
        held = tuple(str(p) for p in self.held)
        unknown = [p for p in held if p not in self.base.parameter_names]
        if unknown:
            raise ParameterError(f"augmented model: held: {unknown} are not parameters of the base")
        object.__setattr__(self, "held", held)

    # -- description ------------------------------------------------------------------------
    @property
    def base_kind(self) -> str:
        """``"normalized"``, ``"extended"`` or ``"spencer"``."""
        return _base_kind(self.base)

    @property
    def effect_names(self) -> tuple[str, ...]:
        """Names of the effects, in composition order."""
        return tuple(e.name for e in self.effects)

    @property
    def name(self) -> str:
        """``base kind`` followed by ``+ effect`` for each effect."""
        return " + ".join((self.base_kind, *self.effect_names))

    def effect(self, name: str) -> Effect | None:
        """The effect named ``name``, or ``None``.

        Parameters
        ----------
        name : str
            Effect name (:data:`damper.diagnosis.effects.EFFECTS`).
        """
        get_effect(name)
        for e in self.effects:
            if e.name == name:
                return e
        return None

    def with_effect(self, effect: Effect) -> "AugmentedModel":
        """A copy with ``effect`` added (replacing an effect of the same name).

        Parameters
        ----------
        effect : Effect
            The effect to add.
        """
        kept = tuple(e for e in self.effects if e.name != effect.name)
        return AugmentedModel(self.base, kept + (effect,), self.held)

    def with_base(self, base) -> "AugmentedModel":
        """A copy with another base model.

        Parameters
        ----------
        base
            The new base model (normalized or extended Bouc-Wen).
        """
        return AugmentedModel(base, self.effects, self.held)

    def base_parameters(self) -> dict:
        """The base model's parameters (numbers or voltage laws), by name."""
        return {k: getattr(self.base, k) for k in self.base.parameter_names}

    def building_model(self) -> tuple[DamperModel, list[str]]:
        """The registered model the building runs for this model, and the effects it cannot run.

        ``stiffness`` becomes κ_x of the extended model; ``roll_off`` the series dashpot
        (:class:`~damper.models.series_dashpot.SeriesDashpotBoucWen`, with ``voltage_lag`` as its
        field lag); :data:`TERM_EFFECTS` run as force terms around that model
        (:class:`~damper.models.force_terms.WithForceTerms`; ``stiffness`` joins them beside
        ``asymmetry``, since :meth:`response` adds it after the factors). The result runs on the
        compiled kernels, in :func:`damper.simulate` and in the building alike, and gives
        :meth:`force` under the same motion (``tests/damper/test_force_terms.py``).

        Returns
        -------
        model : DamperModel
            A registered model.
        dropped : list of str
            One line per effect left out, with its value and why (:data:`NOT_IN_BUILDING`).

        Raises
        ------
        ParameterError
            The series dashpot cannot be built from the base (its ρ, σ or n depend on the input).
        """
        model = self.base
        effects = {e.name: e for e in self.effects}
        terms = {name: effects.pop(name).value for name in TERM_EFFECTS if name in effects}
        if "stiffness" in effects and "asymmetry" in terms:
            terms["stiffness"] = effects.pop("stiffness").value
        if "stiffness" in effects:  # a normalized base (the others declare it)
            model = model.extended(effects.pop("stiffness").value)
        if "roll_off" in effects:
            lag = effects.pop("voltage_lag").value if "voltage_lag" in effects else 0.0
            model = SeriesDashpotBoucWen.from_bouc_wen(model, effects.pop("roll_off").value, field_lag=lag)
        if terms:
            model = WithForceTerms(model, **terms)
        dropped = [f"{e.name} ({e.parameter_name} = {e.value:.4g} {e.unit}): "
                   f"{NOT_IN_BUILDING.get(e.name, 'no kernel in the building, not run')}" for e in effects.values()]
        return model, dropped

    def to_dict(self) -> dict:
        """Plain description: base kind, base parameters (laws as node lists), effects."""
        def plain(value):
            if isinstance(value, Tabulated):
                return {"voltages": list(value.voltages), "values": list(value.values)}
            if isinstance(value, VoltageLaw):
                return repr(value)
            return float(value)
        return {"base": self.base_kind,
                "base_parameters": {k: plain(v) for k, v in self.base_parameters().items()},
                "effects": [{"name": e.name, "parameters": e.parameters} for e in self.effects]}

    # -- simulation ---------------------------------------------------------------------------
    def response(self, motion: Motion, memo: "BaseForceMemo | None" = None) -> AugmentedResponse:
        """Force history under the prescribed ``motion`` (base force, input and terms too).

        Parameters
        ----------
        motion : Motion
            The prescribed motion of one test (:class:`damper.diagnosis.effects.Motion`: time, displacement, velocity,
            acceleration, coil input; SI).
        memo : BaseForceMemo, optional
            Recent base forces under this same ``motion``: a base (after its series and input
            effects) it holds is not simulated again (:class:`BaseForceMemo`).

        Raises
        ------
        InputError
            The coil input leaves the base model's ``voltage_range``.
        NumericalError
            The base model's force is not finite.
        """
        u = motion.v
        base = self.base
        for e in self.effects:
            if e.role == "series":
                base = e.series_base(base)
            elif e.role == "input":
                u = e.transform_input(motion, u)
        base = with_coarser_substeps(base, motion.substep_scale)  # 1 outside the loop's coarse pass
        if memo is None:
            base_force = simulate(base, motion.t, motion.x, motion.xdot, u).force
        else:
            base_force = memo.base_force(base, motion, u)
        force = base_force.copy()
        terms: dict[str, np.ndarray] = {}
        for e in self.effects:
            if e.role == "factor":
                g = e.factor(motion, base_force)
                terms[e.name] = (g - 1.0) * force
                force = force * g
        for e in self.effects:
            if e.role == "additive":
                f = e.force(motion)
                terms[e.name] = f
                force = force + f
        return AugmentedResponse(force=force, base_force=base_force, model_input=u, terms=terms)

    def force(self, motion: Motion, memo: "BaseForceMemo | None" = None) -> np.ndarray:
        """Total force [N] under ``motion``.

        Parameters
        ----------
        motion : Motion
            The prescribed motion of one test (:class:`damper.diagnosis.effects.Motion`: time, displacement, velocity,
            acceleration, coil input; SI).
        memo : BaseForceMemo, optional
            See :meth:`response`.
        """
        return self.response(motion, memo).force

    def simulate(self, t, x, xdot=None, xddot=None, v=0.0) -> AugmentedResponse:
        """Force history under displacement ``x(t)`` [m] and coil input ``v(t)``.

        Parameters
        ----------
        t : array_like (n,)
            Strictly increasing times [s].
        x : array_like (n,)
            Displacement [m].
        xdot, xddot : array_like (n,), optional
            Velocity [m/s] and acceleration [m/s²]; default to finite differences
            (``numpy.gradient``, second order) of ``x`` and ``xdot``.
        v : float or array_like (n,)
            Coil input [V] (or [A] for a model identified on currents).

        Returns
        -------
        AugmentedResponse
        """
        t = np.asarray(t, dtype=float)
        x = np.asarray(x, dtype=float)
        if t.ndim != 1 or t.size < 3 or x.shape != t.shape:
            raise InputError(f"simulate: t and x must be 1-D of equal length >= 3, got shapes "
                             f"{t.shape} and {x.shape}")
        xdot = np.gradient(x, t, edge_order=2) if xdot is None else np.asarray(xdot, dtype=float)
        xddot = np.gradient(xdot, t, edge_order=2) if xddot is None else np.asarray(xddot, dtype=float)
        return self.response(Motion(t, x, xdot, xddot, v))


# ------------------------------------------------------------------------------ parametrization

def _law_nodes(value, nodes: np.ndarray) -> np.ndarray:
    if isinstance(value, VoltageLaw):
        return np.array([float(value(float(v))) for v in nodes])
    return np.full(nodes.size, float(value))


class Parametrization:
    """Free parameters of an augmented model as one flat vector, with bounds and scales.

    Layout: the base parameters in ``parameter_names`` order, each a single value (constant
    parameters, ``nodes is None``) or its values at the voltage ``nodes`` (a
    :class:`~damper.models.voltage_laws.Tabulated` law, PCHIP between nodes); then one value per effect
    in composition order. With a ``series`` effect (``roll_off``) the shape parameters ρ, σ, n
    and κ_x stay single values even with nodes (the series model needs them independent of the
    coil input; a template whose laws vary there starts from their mean over the nodes).

    Parameters
    ----------
    template : AugmentedModel
        Gives the base kind, the effects and the voltage range.
    nodes : sequence of float, optional
        Voltage nodes of the base parameters' laws (``None``: constant parameters).
    scales : dict of str to float, optional
        Typical size of each base parameter and effect (name -> value) to scale the search;
        defaults to the template's values.
    fixed_base : bool
        Keep the base parameters at the template's values (only the effects are free); the
        template's ``held`` base parameters stay at its values in any case.
    """

    def __init__(self, template: AugmentedModel, nodes: Sequence[float] | None = None,
                 scales: dict | None = None, fixed_base: bool = False) -> None:
        self.template = template
        self.kind = template.base_kind
        self.all_base_names = tuple(template.base.parameter_names)
        self.fixed = tuple(p for p in template.held if p in self.all_base_names)
        self.base_names = tuple(p for p in self.all_base_names if p not in self.fixed)
        self.voltage_range = tuple(template.base.voltage_range)
        self.nodes = None if nodes is None else np.unique(np.asarray(nodes, dtype=float))
        if self.nodes is not None and self.nodes.size < 2:
            self.nodes = None
        self.fixed_base = bool(fixed_base)
        self.effect_classes = tuple(type(e) for e in template.effects)
        # A series effect runs the base on the Spencer-type kernel, whose Bouc-Wen shape and
        # parallel stiffness cannot depend on the coil input: one value each over the nodes.
        self.shared = (frozenset(_SERIES_SHARED) & frozenset(self.base_names)
                       if self.nodes is not None and any(c.role == "series" for c in self.effect_classes)
                       else frozenset())
        if self.nodes is not None:  # the Spencer-type base's kernel constants
            self.shared |= frozenset(getattr(type(template.base), "shared_parameters", ()))
        scales = dict(scales or {})
        names, lower, upper, scale = [], [], [], []
        if not self.fixed_base:
            base_values = template.base_parameters()
            for p in self.base_names:
                typical = abs(float(scales.get(p, 0.0))) or float(np.max(np.abs(
                    _law_nodes(base_values[p], self._nodes_or_zero()))))
                typical = typical if typical > 0 else 1.0
                lo, hi = _BASE_BOUNDS.get(p, (0.0 if p in _BASE_ZERO_LOWER else _BASE_LOWER_REL * typical,
                                              _BASE_UPPER.get(p, math.inf)))
                labels = ([p] if self.nodes is None or p in self.shared
                          else [f"{p}@{v:g}" for v in self.nodes])
                for label in labels:
                    names.append(label)
                    lower.append(lo)
                    upper.append(hi)
                    scale.append(typical if p not in _BASE_BOUNDS else 1.0)
        for e in template.effects:
            cls = type(e)
            names.append(f"{cls.name}.{cls.parameter_name}")
            lower.append(cls.lower)
            upper.append(cls.upper)
            typical = abs(float(scales.get(cls.name, 0.0))) or abs(e.value) or 1.0
            scale.append(typical)
        self.names = tuple(names)
        self.lower = np.array(lower, dtype=float)
        self.upper = np.array(upper, dtype=float)
        self.scale = np.array(scale, dtype=float)

    def _nodes_or_zero(self) -> np.ndarray:
        return self.nodes if self.nodes is not None else np.array([self.voltage_range[0]])

    @property
    def size(self) -> int:
        """Number of free parameters."""
        return len(self.names)

    @property
    def n_base(self) -> int:
        """Number of free base-model values."""
        if self.fixed_base:
            return 0
        per = 1 if self.nodes is None else self.nodes.size
        return sum(1 if p in self.shared else per for p in self.base_names)

    def vector(self, model: AugmentedModel) -> np.ndarray:
        """The free parameters of ``model`` (same base kind and effect names as the template).

        Parameters
        ----------
        model : AugmentedModel
            An augmented model of the template's form.
        """
        if model.base_kind != self.kind or tuple(type(e) for e in model.effects) != self.effect_classes:
            raise InputError(f"parametrization: model {model.name!r} does not match "
                             f"{self.template.name!r}")
        out = []
        if not self.fixed_base:
            values = model.base_parameters()
            for p in self.base_names:
                if p in self.shared:
                    out.append(float(np.mean(_law_nodes(values[p], self.nodes))))
                elif self.nodes is None:
                    v = values[p]
                    out.append(float(v(self.voltage_range[0])) if isinstance(v, VoltageLaw) else float(v))
                else:
                    out.extend(_law_nodes(values[p], self.nodes))
        out.extend(e.value for e in model.effects)
        return np.array(out, dtype=float)

    def model(self, vector: np.ndarray, validate: bool = True) -> AugmentedModel:
        """The augmented model with the free parameters ``vector`` (raises ParameterError).

        ``validate=False`` (used inside the optimiser) skips the base model's check of its
        voltage laws over the whole voltage range: the bounds keep every node value in the
        admissible class, and a PCHIP law stays between its node values, so the check cannot fail
        there; it costs more than a simulation. Constant parameters are always checked.

        Parameters
        ----------
        vector : np.ndarray
            Free parameters, in the order of :meth:`vector`.
        validate : bool, optional
            Check the base model's voltage laws over the whole voltage range (False inside the optimiser).
        """
        vector = np.asarray(vector, dtype=float)
        if vector.shape != (self.size,):
            raise InputError(f"parametrization: expected {self.size} values, got {vector.shape}")
        if self.fixed_base:
            base = self.template.base
            k = 0
        else:
            params, k = {}, 0
            template_values = self.template.base_parameters()
            for p in self.fixed:
                params[p] = template_values[p]
            for p in self.base_names:
                if self.nodes is None or p in self.shared:
                    params[p] = float(vector[k])
                    k += 1
                else:
                    vals = vector[k:k + self.nodes.size]
                    params[p] = Tabulated(tuple(self.nodes), tuple(float(x) for x in vals))
                    k += self.nodes.size
            if validate or self.nodes is None:
                base = make_base(self.kind, params, self.voltage_range)
            else:
                base = _unchecked_base(self.kind, params, self.voltage_range,
                                       self.template.base.substep_tolerance, vector[:k],
                                       self.lower[:k], self.upper[:k])
        effects = tuple(cls(float(vector[k + j])) for j, cls in enumerate(self.effect_classes))
        return AugmentedModel(base, effects, self.template.held)


#: Relative distance to a bound of the search below which a shape parameter counts as at it.
AT_BOUND_TOLERANCE = 1e-3


def base_at_bounds(model: AugmentedModel) -> dict[str, str]:
    """The base model's shape parameters that sit at a bound of the loop's search.

    σ and n are searched in [0.5, 50] and [1, 10], the field lag below 1 s (the bounds of
    :class:`Parametrization`). A value at one of them was not identified by the data: the fit
    would have moved it further (σ at 50: the force turns at a reversal more sharply than the
    search lets the model; n at 1: the transition is smoother than a Bouc-Wen element with n >= 1).
    The springs' lower bound, zero, is a value of the model, not a limit of the search, and is
    not reported. Cf. :func:`damper.identification.refine.parameters_at_bounds` for
    ``sbib identify --data``.

    Parameters
    ----------
    model : AugmentedModel
        A fitted model; its ``held`` parameters were not fitted and are never reported.

    Returns
    -------
    dict
        ``{name: "upper 50" | "lower 1" ...}``.
    """
    out = {}
    for name in ("sigma", "n", "field_lag"):
        if name in model.held or name not in model.base.parameter_names:
            continue
        value = getattr(model.base, name)
        if not isinstance(value, (int, float)):
            continue
        lo, hi = _BASE_BOUNDS.get(name, (None, _BASE_UPPER.get(name, math.inf)))
        for side, bound in (("lower", lo), ("upper", hi)):
            if bound is not None and math.isfinite(bound) and abs(value - bound) <= AT_BOUND_TOLERANCE * abs(bound):
                out[name] = f"{side} {bound:g}"
    return out


def _unchecked_base(kind, params, voltage_range, tolerance, values, lower, upper):
    """Base model with Tabulated laws built without the law check (values within bounds)."""
    if not (np.all(np.isfinite(values)) and np.all(values >= lower) and np.all(values <= upper)):
        raise ParameterError("base parameters outside their bounds")
    cls = BASE_MODELS[kind]
    obj = object.__new__(cls)
    for name in cls.parameter_names:
        object.__setattr__(obj, name, params[name])
    object.__setattr__(obj, "voltage_range", tuple(float(v) for v in voltage_range))
    object.__setattr__(obj, "substep_tolerance", float(tolerance))
    return obj


# ------------------------------------------------------------------------------------ joint refit

@dataclass(frozen=True)
class RefitResult:
    """Result of :func:`refit`.

    Attributes
    ----------
    model : AugmentedModel
        The refitted model.
    relative_rms_error : float
        :math:`\\|F - \\hat F\\|_2/\\|F\\|_2` over the fitted samples.
    nfev : int
        Residual evaluations (each simulates every test once).
    success : bool
    message : str
    """

    model: AugmentedModel
    relative_rms_error: float
    nfev: int
    success: bool
    message: str


def _check_data(motions, forces, masks):
    motions = list(motions)
    forces = [np.asarray(f, dtype=float) for f in forces]
    if not motions or len(forces) != len(motions):
        raise InputError(f"refit: expected one force history per motion, got {len(motions)} "
                         f"motions and {len(forces)} forces")
    if masks is None:
        masks = [np.ones(m.n_samples, dtype=bool) for m in motions]
    masks = [np.asarray(k, dtype=bool) for k in masks]
    for m, f, k in zip(motions, forces, masks):
        if f.shape != m.t.shape or k.shape != m.t.shape:
            raise InputError(f"refit: test {m.name!r}: force and mask must have {m.n_samples} samples")
    if sum(int(k.sum()) for k in masks) < 2:
        raise InputError("refit: fewer than 2 samples selected for fitting")
    return motions, forces, masks


def _until_last_fitted(motions, forces, masks):
    """Each test cut after its last fitted sample: the simulation is causal, so the samples after
    it change nothing in the fit (the held-out end of a test is not simulated while fitting)."""
    out_m, out_f, out_k = [], [], []
    for m, f, k in zip(motions, forces, masks):
        idx = np.flatnonzero(k)
        end = max(int(idx[-1]) + 1, 2) if idx.size else 2
        if end < m.n_samples:
            m = replace(m, t=m.t[:end], x=m.x[:end], xdot=m.xdot[:end], xddot=m.xddot[:end],
                        v=m.v[:end])
            f, k = f[:end], k[:end]
        out_m.append(m)
        out_f.append(f)
        out_k.append(k)
    return out_m, out_f, out_k


def predict(model: AugmentedModel, motions: Sequence[Motion]) -> list[np.ndarray]:
    """The force histories of ``model`` for each motion."""
    return [model.force(m) for m in motions]


def refit(start: AugmentedModel, motions: Sequence[Motion], forces: Sequence[np.ndarray],
          masks: Sequence[np.ndarray] | None = None, nodes: Sequence[float] | None = None,
          scales: dict | None = None, fixed_base: bool = False, max_nfev: int = 200,
          tolerance: float = 1e-10, stall: tuple[int, float] | None = None) -> RefitResult:
    """Refit the base parameters and every effect's parameter jointly by least squares.

    Minimises :math:`\\sum_i \\sum_{k \\in \\mathcal M_i} (\\hat F_{ik}(p) - F_{ik})^2` over the
    free parameters :math:`p` (:class:`Parametrization`), with the admissible class as bounds,
    by the trust-region-reflective method on :math:`p/s` (``s`` the scales). Each test ``i`` is
    simulated from its first sample; only the samples of its mask :math:`\\mathcal M_i` count.

    Parameters
    ----------
    start : AugmentedModel
        Starting model (its effects define the terms that are fitted).
    motions : sequence of Motion
        Prescribed motions of the tests.
    forces : sequence of ndarray
        Measured forces [N], one per motion.
    masks : sequence of bool ndarray, optional
        Samples that count (default: all).
    nodes : sequence of float, optional
        Voltage nodes for the base parameters' laws (``None``: constant base parameters).
    scales : dict, optional
        Typical parameter sizes (see :class:`Parametrization`).
    fixed_base : bool
        Fit only the effects' parameters.
    max_nfev : int
        Cap on residual evaluations (the finite-difference Jacobian's evaluations not counted).
    tolerance : float
        ``ftol``, ``xtol`` and ``gtol`` of :func:`scipy.optimize.least_squares`. The residual loop
        uses a looser value (1e-6: a relative change of the cost far below what its held-out
        BIC can tell apart) to save iterations.
    stall : (int, float), optional
        Stop once that many iterations in a row lowered the cost by less than that share of it
        (:func:`damper.fitting.least_squares_fit`); the residual loop's trials use
        :data:`damper.diagnosis.selection.DEFAULT_STALL`. None: no such stop.

    Returns
    -------
    RefitResult

    Raises
    ------
    InputError
        Inconsistent data.
    NumericalError
        The model cannot be evaluated at the start.
    """
    motions, forces, masks = _until_last_fitted(*_check_data(motions, forces, masks))
    par = Parametrization(start, nodes=nodes, scales=scales, fixed_base=fixed_base)
    measured = np.concatenate([f[k] for f, k in zip(forces, masks)])
    norm = float(np.linalg.norm(measured))
    if not norm > 0:
        raise InputError("refit: the measured force is identically zero over the fitted samples")
    force_scale = norm / math.sqrt(measured.size)
    bad = np.full(measured.size, 1e3)
    count = {"n": 0}

    # the centre point's base force must outlive the Jacobian's columns for the base parameters
    memos = [BaseForceMemo(size=par.size + 2) for _ in motions]

    def residuals(q):
        count["n"] += 1
        try:
            model = par.model(q * par.scale, validate=False)
            pred = np.concatenate([model.force(m, memo)[k] for m, k, memo in zip(motions, masks, memos)])
        except (ParameterError, NumericalError, InputError):
            return bad
        r = (pred - measured) / force_scale
        return r if np.all(np.isfinite(r)) else bad

    p0 = par.vector(start)
    q0 = np.clip(p0 / par.scale, par.lower / par.scale, par.upper / par.scale)
    # keep strictly inside the bounds (trf needs an interior start)
    span = np.where(np.isfinite(par.upper - par.lower), (par.upper - par.lower) / par.scale, 1.0)
    q0 = np.clip(q0, par.lower / par.scale + 1e-9 * span, par.upper / par.scale - 1e-9 * span)
    r0 = residuals(q0)
    if r0 is bad:
        raise NumericalError(f"refit: the model {start.name!r} cannot be evaluated at its start",
                             hint="check the starting parameters")
    if par.size == 0:
        return RefitResult(start, float(np.linalg.norm(r0) * force_scale / norm), 1, True, "nothing to fit")
    sol = least_squares_fit(residuals, q0, par.lower / par.scale, par.upper / par.scale, tolerance=tolerance,
                            diff_step=1e-6, max_nfev=max_nfev, stall=stall)
    model = par.model(sol.x * par.scale)
    rel = float(np.linalg.norm(sol.fun) * force_scale / norm)
    return RefitResult(model=model, relative_rms_error=rel, nfev=count["n"],
                       success=bool(sol.success), message=str(sol.message))


#: Residual evaluations each start of :func:`refit_from_starts` gets before the best one goes on.
START_NFEV = 4


def refit_from_starts(starts: Sequence[AugmentedModel], motions: Sequence[Motion],
                      forces: Sequence[np.ndarray], masks: Sequence[np.ndarray] | None = None,
                      nodes: Sequence[float] | None = None, scales: dict | None = None,
                      max_nfev: int = 200, tolerance: float = 1e-10,
                      stall: tuple[int, float] | None = None,
                      on_start=None) -> RefitResult | None:
    """The global stage of a refit whose landscape may have several minima: a few steps from
    every start, then the best one to convergence.

    Each start takes :data:`START_NFEV` residual evaluations of :func:`refit`; the one with the
    least error goes on with ``max_nfev`` and ``stall``, unless its short refit has converged.
    The short refit stands when the long one fails or ends worse. A single start is refitted
    once, with ``max_nfev`` and ``stall``. Starts that cannot be evaluated are skipped. Used by
    the base fits (:mod:`damper.diagnosis.base_fit`: the grid's best shapes mostly reach the same
    optimum, and refining each to the end tripled the base fit's cost) and by the residual loop's
    joint refit of an effect with a start grid (:meth:`~damper.diagnosis.effects.Effect.start_grid`).

    Parameters
    ----------
    starts : sequence of AugmentedModel
        Starting models (the same parametrization).
    motions, forces, masks, nodes, scales, tolerance
        As in :func:`refit`.
    max_nfev : int
        Cap on the final refinement's residual evaluations.
    stall : (int, float), optional
        The final refinement's stall rule (:func:`refit`); the short refits run without one.
    on_start : callable, optional
        ``on_start(index, start, result)`` after each start's short refit.

    Returns
    -------
    RefitResult or None
        The best refit; ``None`` when no start could be evaluated.

    Raises
    ------
    InputError
        Inconsistent data (checked once, before any start).
    """
    starts = list(starts)
    _check_data(motions, forces, masks)
    failures = (NumericalError, ParameterError, InputError)
    if len(starts) == 1:
        try:
            return refit(starts[0], motions, forces, masks, nodes=nodes, scales=scales,
                         max_nfev=max_nfev, tolerance=tolerance, stall=stall)
        except failures:
            return None
    best: RefitResult | None = None
    for i, start in enumerate(starts):
        try:
            trial = refit(start, motions, forces, masks, nodes=nodes, scales=scales,
                          max_nfev=min(START_NFEV, max_nfev), tolerance=tolerance)
        except failures:
            continue
        if on_start is not None:
            on_start(i, start, trial)
        if best is None or trial.relative_rms_error < best.relative_rms_error:
            best = trial
    if best is None or best.success or max_nfev <= START_NFEV:
        return best
    try:
        more = refit(best.model, motions, forces, masks, nodes=nodes, scales=scales,
                     max_nfev=max_nfev, tolerance=tolerance, stall=stall)
    except failures:
        return best
    return more if more.relative_rms_error <= best.relative_rms_error else best
