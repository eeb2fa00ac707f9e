"""Registry of damper models: one name and one integer id per model, and the one dispatch kernel.

Every damper model is a frozen parameter dataclass in its own module that subclasses
:class:`damper.base.DamperModel` (the contract: ``name``, ``model_id``, ``kernel``,
``n_states``, ``to_array()``, ``initial_state()``, ``voltage_range``, plain-numpy
``rates``/``force``). It is registered once, by :func:`register_model`, under its ``name``.
The building's stepping kernel and :func:`damper.simulate` call :func:`device_step` with the
model's *kernel family* (:data:`damper.base.KERNELS`), its packed parameters and its state, so
adding a model is one module plus one :func:`register_model` call (a test registers a toy model
and runs it in the building: ``tests/damper/test_model_registration.py``).
"""

from __future__ import annotations

import dataclasses
import functools

import numba
import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from damper.base import (KERNEL_BINGHAM, KERNEL_BOUC_WEN, KERNEL_HYPERBOLIC_TANGENT, KERNEL_SPENCER_TYPE,
                         KERNELS, DamperModel)
from damper.bouc_wen import ExtendedBoucWen, NormalizedBoucWen, bouc_wen_force, bouc_wen_step
from damper.spencer import (MEMO_LENGTH, Spencer, spencer_type_force_kernel, spencer_type_step,
                            spencer_type_step_memo, spencer_type_tangent, spencer_type_tangent_memo)
from damper.virtual import VirtualBenchmarkDamper
from damper.series_dashpot import SeriesDashpotBoucWen
from damper.bingham import Bingham, bingham_force, bingham_step
from damper.dahl import Dahl
from damper.hyperbolic_tangent import HyperbolicTangent, hyperbolic_tangent_force, hyperbolic_tangent_step

__all__ = [
    "MODELS",
    "MODELS_BY_ID",
    "register_model",
    "get_model_class",
    "model_id_of",
    "kernel_id_of",
    "device_step",
    "device_step_memo",
    "MEMO_LENGTH",
    "device_tangent",
    "device_tangent_memo",
    "device_force",
]

#: Model classes by name.
MODELS: dict[str, type[DamperModel]] = {}
#: Model classes by integer id.
MODELS_BY_ID: dict[int, type[DamperModel]] = {}


def register_model(cls: type[DamperModel]) -> type[DamperModel]:
    """Register a damper model class under its ``name`` and ``model_id`` and return it.

    Raises
    ------
    InputError
        If ``cls`` is not a :class:`~damper.base.DamperModel` subclass, names an unknown kernel
        family, or its name or id is already taken by another class.
    """
    if not (isinstance(cls, type) and issubclass(cls, DamperModel)):
        raise InputError(f"register_model: {cls!r} is not a damper.base.DamperModel subclass")
    name, model_id, kernel = getattr(cls, "name", None), getattr(cls, "model_id", None), getattr(cls, "kernel", None)
    if not isinstance(name, str) or not name:
        raise InputError(f"register_model: {cls.__name__} has no name")
    if not isinstance(model_id, int) or model_id <= 0:
        raise InputError(f"register_model: {cls.__name__}.model_id must be a positive int, got {model_id!r}")
    if kernel not in KERNELS:
        raise InputError(f"register_model: {cls.__name__}.kernel {kernel!r} is not a kernel family; expected "
                         "one of " + ", ".join(f"{k} ({v})" for k, v in KERNELS.items()))
    taken = MODELS.get(name) or MODELS_BY_ID.get(model_id)
    if taken is not None and taken is not cls:
        key = name if name in MODELS else model_id
        raise InputError(f"register_model: {cls.__name__}: {key!r} is already registered by {taken.__name__}")
    MODELS[name] = cls
    MODELS_BY_ID[model_id] = cls
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


for _cls in (NormalizedBoucWen, ExtendedBoucWen, Spencer, VirtualBenchmarkDamper, SeriesDashpotBoucWen,
             Bingham, Dahl, HyperbolicTangent):
    register_model(_cls)


def get_model_class(name: str) -> type[DamperModel]:
    """The model class registered as ``name`` (raises :class:`InputError` listing the names)."""
    try:
        return MODELS[name]
    except KeyError:
        raise InputError(f"damper model: unknown name {name!r}; expected one of "
                         + ", ".join(sorted(MODELS))) from None


def model_id_of(model: DamperModel) -> int:
    """The registered integer id of a model instance (checks it is registered)."""
    model_id = getattr(model, "model_id", None)
    if model_id not in MODELS_BY_ID or not isinstance(model, MODELS_BY_ID[model_id]):
        raise InputError(f"damper model: {type(model).__name__} is not a registered damper model; "
                         "expected one of " + ", ".join(sorted(MODELS)))
    return int(model_id)


def kernel_id_of(model: DamperModel) -> int:
    """The kernel family (:data:`damper.base.KERNELS`) of a registered model instance: the number
    :func:`device_step` dispatches on."""
    model_id_of(model)
    return int(type(model).kernel)


@numba.njit(cache=True)
def device_step(kernel_id, params, state, x0, x1, xd0, xd1, v, dt):
    """Advance one device over one step; return its force at the end of the step [N].

    Parameters
    ----------
    kernel_id : int
        The model's kernel family (:func:`kernel_id_of`).
    params : float64 array
        ``model.to_array()``.
    state : float64 array
        The device's internal states (``model.initial_state()`` at rest), advanced in place.
    x0, x1 : float
        Device displacement at the start and end of the step [m].
    xd0, xd1 : float
        Device velocity at the start and end of the step [m/s].
    v : float
        Commanded voltage [V], held over the step.
    dt : float
        Step length [s].

    Notes
    -----
    The motion inside the step is the cubic Hermite path through ``(x0, xd0)`` and
    ``(x1, xd1)``; each model sub-steps as its stiffness needs. An unknown ``kernel_id`` returns
    NaN (the caller turns it into a :class:`NumericalError`).
    """
    if kernel_id == KERNEL_BOUC_WEN:
        return bouc_wen_step(params, state, x0, x1, xd0, xd1, v, dt)
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_step(params, state, x0, x1, xd0, xd1, v, dt)
    if kernel_id == KERNEL_BINGHAM:
        return bingham_step(params, state, x0, x1, xd0, xd1, v, dt)
    if kernel_id == KERNEL_HYPERBOLIC_TANGENT:
        return hyperbolic_tangent_step(params, state, x0, x1, xd0, xd1, v, dt)
    return np.nan


@numba.njit(cache=True)
def device_step_memo(kernel_id, params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`device_step` with a per-device scratch array ``memo`` (float64, :data:`MEMO_LENGTH`,
    any initial content) in which a model may keep values that depend only on the step's start
    state and voltage (the Spencer-type voltage laws), reused when the same device is advanced
    again from the same state, as the building's fixed-point iteration does. Same results as
    :func:`device_step`; models without such values ignore ``memo``."""
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo)
    return device_step(kernel_id, params, state, x0, x1, xd0, xd1, v, dt)


@numba.njit(cache=True)
def device_force(kernel_id, params, state, x, xd, v):
    """Force [N] of a device at its current state, displacement ``x`` [m], velocity ``xd`` [m/s]
    and voltage ``v`` [V] (no state change); NaN for an unknown ``kernel_id``."""
    if kernel_id == KERNEL_BOUC_WEN:
        return bouc_wen_force(params, state, x, xd, v)
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_force_kernel(params, state, x, xd, v)
    if kernel_id == KERNEL_BINGHAM:
        return bingham_force(params, state, x, xd, v)
    if kernel_id == KERNEL_HYPERBOLIC_TANGENT:
        return hyperbolic_tangent_force(params, state, x, xd, v)
    return np.nan


@numba.njit(cache=True)
def device_tangent(kernel_id, params, state, x, xd, v):
    """``(dF/dx [N/m], dF/dxd [N·s/m])`` of a device at its current state (internal states held).

    The building's Newton iteration on the base uses them at the end of a step. Models without
    a tangent return ``(0, 0)``: the iteration then treats their force as given, which only
    slows its convergence (the fixed point and the convergence test are unchanged).
    """
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_tangent(params, state, x, xd)
    return 0.0, 0.0


@numba.njit(cache=True)
def device_tangent_memo(kernel_id, params, state, x, xd, v, memo):
    """:func:`device_tangent` after :func:`device_step_memo` with the same ``memo``: a model that
    stored its end-of-step tangent there (the Spencer types) returns it without evaluating its
    voltage laws again."""
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_tangent_memo(params, memo)
    return device_tangent(kernel_id, params, state, x, xd, v)
