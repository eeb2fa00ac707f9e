"""The damper model contract: what every model in :mod:`damper.models.registry` implements.

A damper model is a frozen, validated dataclass of SI parameters that subclasses
:class:`DamperModel`. It declares

* ``name`` — the one name it is registered and looked up under (``sbib damper test --model``,
  JSON files, reports);
* ``kernel`` — the compiled kernel family that advances it (:data:`KERNELS`): the building's
  stepping kernel and :func:`damper.simulate` dispatch on this number, so a model that packs
  its parameters into an existing family's layout needs no kernel edit;
* ``n_states`` and ``state_names`` — its internal states;
* ``voltage_range`` — the admissible coil voltages ``(v_min, v_max)`` [V];
* ``to_array()`` — its parameters packed for its kernel family, and ``initial_state()`` —
  its states at rest;
* ``rates(state, x, xdot, v)`` and ``force(state, x, xdot, v)`` — plain-numpy equations, for
  oracles and readers.

Adding a model is one class decorated with :func:`register_model` (see ``docs/ARCHITECTURE.md``,
"Where things go"; the registry is :data:`MODELS`, a :class:`benchmark.foundation.registry.Registry`);
a new kernel family also adds one branch to each of :func:`damper.models.registry.device_step` and
:func:`damper.models.registry.device_force`.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from typing import ClassVar

import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.foundation.registry import Registry

__all__ = ["DamperModel", "MODELS", "register_model", "with_coarser_substeps", "KERNEL_BOUC_WEN", "KERNEL_SPENCER_TYPE", "KERNEL_BINGHAM",
           "KERNEL_HYPERBOLIC_TANGENT", "KERNEL_FORCE_TERMS", "KERNELS"]

#: Bouc-Wen family (normalized, extended, Dahl): :func:`damper.models.bouc_wen.bouc_wen_step`.
KERNEL_BOUC_WEN = 1
#: Spencer-type family (Spencer, the virtual damper, Bouc-Wen with a series dashpot):
#: :func:`damper.models.spencer.spencer_type_step`.
KERNEL_SPENCER_TYPE = 2
#: Stateless Bingham law: :func:`damper.models.bingham.bingham_step`.
KERNEL_BINGHAM = 3
#: Stateless hyperbolic-tangent law: :func:`damper.models.hyperbolic_tangent.hyperbolic_tangent_step`.
KERNEL_HYPERBOLIC_TANGENT = 4
#: Memoryless force terms around another family's model (a diagnosed model's effects in the
#: building): :mod:`damper.models.force_terms`.
KERNEL_FORCE_TERMS = 5
#: Kernel families by id.
KERNELS: dict[int, str] = {KERNEL_BOUC_WEN: "bouc_wen", KERNEL_SPENCER_TYPE: "spencer_type",
                           KERNEL_BINGHAM: "bingham", KERNEL_HYPERBOLIC_TANGENT: "hyperbolic_tangent",
                           KERNEL_FORCE_TERMS: "force_terms"}


class DamperModel(abc.ABC):
    """Base class of every registered damper model (module docstring)."""

    name: ClassVar[str]
    kernel: ClassVar[int]
    n_states: ClassVar[int]
    state_names: ClassVar[tuple[str, ...]] = ()
    voltage_range: tuple[float, float]

    @abc.abstractmethod
    def to_array(self) -> np.ndarray:
        """Parameters packed for the model's kernel family (float64)."""

    @abc.abstractmethod
    def initial_state(self) -> np.ndarray:
        """Internal states at rest, shape ``(n_states,)``."""

    @abc.abstractmethod
    def rates(self, state: np.ndarray, x: float, xdot: float, v: float) -> np.ndarray:
        """Time derivatives of the internal states.

        Parameters
        ----------
        state : np.ndarray
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """

    @abc.abstractmethod
    def force(self, state: np.ndarray, x: float, xdot: float, v: float) -> float:
        """Force [N] at ``state``, displacement ``x`` [m], velocity ``xdot`` [m/s], voltage ``v`` [V].

        Parameters
        ----------
        state : np.ndarray
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """


def with_coarser_substeps(model, factor: float):
    """``model`` with its ``substep_tolerance`` multiplied by ``factor`` (at most 1), or ``model``.

    The sub-step rules of the hysteretic kernels (:mod:`damper.models.bouc_wen`,
    :mod:`damper.models.spencer`) take :math:`\\lceil\\lambda\\,\\Delta/\\mathrm{tol}\\rceil` RK4 sub-steps
    (``lambda`` the stiffness of the hysteresis, ``Delta`` the step's time or stroke) with an
    error of order :math:`\\mathrm{tol}^4`, so a stiff model fitted to a long test costs about
    ``1/tol`` per second of test whatever its sampling. The residual loop's coarse pass
    (:mod:`damper.diagnosis.coarse`) simulates at a coarser tolerance for that reason; every error
    it reports is computed again at the model's own. A model without a ``substep_tolerance``, or
    ``factor == 1``, is returned as it is. No check runs again: only the tolerance changes.

    Parameters
    ----------
    model : DamperModel
        Any registered model instance.
    factor : float
        Multiplier of the tolerance (>= 1).
    """
    tol = getattr(model, "substep_tolerance", None)
    if tol is None or factor == 1.0:
        return model
    coarse = min(1.0, float(tol) * float(factor))
    if coarse == tol:
        return model
    out = object.__new__(type(model))
    for f in dataclasses.fields(model):
        object.__setattr__(out, f.name, getattr(model, f.name))
    object.__setattr__(out, "substep_tolerance", coarse)
    return out


def _check_kernel(cls: type) -> str | None:
    if getattr(cls, "kernel", None) not in KERNELS:
        return (f"kernel {getattr(cls, 'kernel', None)!r} is not a kernel family; expected one of "
                + ", ".join(f"{k} ({v})" for k, v in KERNELS.items()))
    return None


#: Registered damper models by name (filled by :func:`register_model`).
MODELS: Registry = Registry("damper model", DamperModel, _check_kernel)


def register_model(cls):
    """Register a damper model class under its ``name`` (a class decorator) and return it.

    Parameters
    ----------
    cls : type
        A :class:`DamperModel` subclass with a ``name`` and a ``kernel`` of :data:`KERNELS`.

    Returns
    -------
    type
        ``cls``.

    Raises
    ------
    InputError
        If ``cls`` is not a :class:`DamperModel` subclass, names an unknown kernel family, or
        its name is already taken by another class.
    """
    MODELS.register(cls)
    _check_arguments_on_init(cls)
    return cls


def _check_arguments_on_init(cls: type[DamperModel]) -> None:
    """Make ``cls(...)`` with missing or unknown parameters fail with one line that names them.

    The dataclass ``__init__`` would raise a bare ``TypeError`` (``missing 3 required positional
    arguments``); the wrapper raises :class:`ParameterError` listing every missing parameter and
    the accepted names instead. Classes that are not dataclasses are left alone.
    """
    init = cls.__dict__.get("__init__")
    if init is None or not dataclasses.is_dataclass(cls) or getattr(init, "_sbib_checked", False):
        return
    fields = [f for f in dataclasses.fields(cls) if f.init]
    names = [f.name for f in fields]
    required = [f.name for f in fields
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]

    @functools.wraps(init)
    def checked_init(self, *args, **kwargs):
        given = set(names[:len(args)]) | set(kwargs)
        unknown = sorted(set(kwargs) - set(names))
        missing = [n for n in required if n not in given]
        if unknown or missing or len(args) > len(names):
            problems = []
            if missing:
                problems.append(f"missing required parameter{'s' if len(missing) > 1 else ''} "
                                + ", ".join(missing))
            if unknown:
                problems.append("unknown parameter" + ("s " if len(unknown) > 1 else " ") + ", ".join(unknown))
            if len(args) > len(names):
                problems.append(f"{len(args)} positional values for {len(names)} parameters")
            raise ParameterError(f"damper model {cls.name!r} ({cls.__name__}): " + "; ".join(problems)
                                 + "; its parameters (SI units) are " + ", ".join(names))
        init(self, *args, **kwargs)

    checked_init._sbib_checked = True  # type: ignore[attr-defined]
    cls.__init__ = checked_init  # type: ignore[method-assign]
