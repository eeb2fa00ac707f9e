"""Registry of damper models: names and integer ids, and the one dispatch kernel.

Every damper model is a frozen parameter dataclass in its own module with ``name``,
``model_id``, ``n_states``, ``to_array()``, ``initial_state()``, ``voltage_range`` and
plain-numpy ``rates``/``force`` (see ``docs/ARCHITECTURE.md``). The building's stepping
kernel and :func:`damper.simulate` call :func:`device_step` with a model's id, its packed
parameters and its state vector. Adding a model means one module plus one entry in
``_MODEL_CLASSES`` and one branch in each of :func:`device_step` and :func:`device_force`.
"""

from __future__ import annotations

import numba
import numpy as np

from benchmark.errors import InputError
from damper.bouc_wen import (EXTENDED_BOUC_WEN_ID, NORMALIZED_BOUC_WEN_ID, ExtendedBoucWen,
                             NormalizedBoucWen, bouc_wen_force, bouc_wen_step)
from damper.spencer import (MEMO_LENGTH, SPENCER_ID, Spencer, spencer_type_force_kernel, spencer_type_tangent,
                            spencer_type_tangent_memo, spencer_type_step, spencer_type_step_memo)
from damper.virtual import VIRTUAL_DAMPER_ID, VirtualBenchmarkDamper
from damper.series_dashpot import SERIES_DASHPOT_ID, SeriesDashpotBoucWen
from damper.bingham import BINGHAM_ID, Bingham, bingham_force, bingham_step
from damper.dahl import DAHL_ID, Dahl
from damper.hyperbolic_tangent import (HYPERBOLIC_TANGENT_ID, HyperbolicTangent,
                                       hyperbolic_tangent_force, hyperbolic_tangent_step)

__all__ = [
    "MODELS",
    "MODELS_BY_ID",
    "get_model_class",
    "model_id_of",
    "device_step",
    "device_step_memo",
    "MEMO_LENGTH",
    "device_tangent",
    "device_tangent_memo",
    "device_force",
]

_MODEL_CLASSES = (
    NormalizedBoucWen,
    ExtendedBoucWen,
    Spencer,
    VirtualBenchmarkDamper,
    SeriesDashpotBoucWen,
    Bingham,
    Dahl,
    HyperbolicTangent,
)

#: Model classes by name.
MODELS: dict[str, type] = {cls.name: cls for cls in _MODEL_CLASSES}
#: Model classes by integer id (the id the kernels dispatch on).
MODELS_BY_ID: dict[int, type] = {cls.model_id: cls for cls in _MODEL_CLASSES}

if len(MODELS) != len(_MODEL_CLASSES) or len(MODELS_BY_ID) != len(_MODEL_CLASSES):
    raise RuntimeError("damper.registry: duplicate model name or id")  # a programming error


def get_model_class(name: str) -> type:
    """The model class registered as ``name`` (raises :class:`InputError` listing the names)."""
    try:
        return MODELS[name]
    except KeyError:
        raise InputError(f"damper model: unknown name {name!r}; expected one of "
                         + ", ".join(sorted(MODELS))) from None


def model_id_of(model) -> int:
    """The registered integer id of a model instance (checks it is registered)."""
    model_id = getattr(model, "model_id", None)
    if model_id not in MODELS_BY_ID or not isinstance(model, MODELS_BY_ID[model_id]):
        raise InputError(f"damper model: {type(model).__name__} is not a registered damper model; "
                         "expected one of " + ", ".join(sorted(MODELS)))
    return int(model_id)


@numba.njit(cache=True)
def device_step(model_id, params, state, x0, x1, xd0, xd1, v, dt):
    """Advance one device over one step; return its force at the end of the step [N].

    Parameters
    ----------
    model_id : int
        Registered model id (``model.model_id``).
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
    ``(x1, xd1)``; each model sub-steps as its stiffness needs (DOMAIN.md §5). An unknown
    ``model_id`` returns NaN (the caller turns it into a :class:`NumericalError`).
    """
    if (model_id == NORMALIZED_BOUC_WEN_ID or model_id == EXTENDED_BOUC_WEN_ID
            or model_id == DAHL_ID):
        return bouc_wen_step(params, state, x0, x1, xd0, xd1, v, dt)
    if model_id == SPENCER_ID or model_id == VIRTUAL_DAMPER_ID or model_id == SERIES_DASHPOT_ID:
        return spencer_type_step(params, state, x0, x1, xd0, xd1, v, dt)
    if model_id == BINGHAM_ID:
        return bingham_step(params, state, x0, x1, xd0, xd1, v, dt)
    if model_id == HYPERBOLIC_TANGENT_ID:
        return hyperbolic_tangent_step(params, state, x0, x1, xd0, xd1, v, dt)
    return np.nan


@numba.njit(cache=True)
def device_step_memo(model_id, params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`device_step` with a per-device scratch array ``memo`` (float64, :data:`MEMO_LENGTH`,
    any initial content) in which a model may keep values that depend only on the step's start
    state and voltage (the Spencer-type voltage laws), reused when the same device is advanced
    again from the same state, as the building's fixed-point iteration does. Same results as
    :func:`device_step`; models without such values ignore ``memo``."""
    if model_id == SPENCER_ID or model_id == VIRTUAL_DAMPER_ID or model_id == SERIES_DASHPOT_ID:
        return spencer_type_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo)
    return device_step(model_id, params, state, x0, x1, xd0, xd1, v, dt)


@numba.njit(cache=True)
def device_force(model_id, params, state, x, xd, v):
    """Force [N] of a device at its current state, displacement ``x`` [m], velocity ``xd`` [m/s]
    and voltage ``v`` [V] (no state change); NaN for an unknown ``model_id``."""
    if (model_id == NORMALIZED_BOUC_WEN_ID or model_id == EXTENDED_BOUC_WEN_ID
            or model_id == DAHL_ID):
        return bouc_wen_force(params, state, x, xd, v)
    if model_id == SPENCER_ID or model_id == VIRTUAL_DAMPER_ID or model_id == SERIES_DASHPOT_ID:
        return spencer_type_force_kernel(params, state, x, xd, v)
    if model_id == BINGHAM_ID:
        return bingham_force(params, state, x, xd, v)
    if model_id == HYPERBOLIC_TANGENT_ID:
        return hyperbolic_tangent_force(params, state, x, xd, v)
    return np.nan


@numba.njit(cache=True)
def device_tangent(model_id, params, state, x, xd, v):
    """``(dF/dx [N/m], dF/dxd [N·s/m])`` of a device at its current state (internal states held).

    The building's Newton iteration on the base uses them at the end of a step. Models without
    a tangent return ``(0, 0)``: the iteration then treats their force as given, which only
    slows its convergence (the fixed point and the convergence test are unchanged).
    """
    if model_id == SPENCER_ID or model_id == VIRTUAL_DAMPER_ID or model_id == SERIES_DASHPOT_ID:
        return spencer_type_tangent(params, state, x, xd)
    return 0.0, 0.0


@numba.njit(cache=True)
def device_tangent_memo(model_id, params, state, x, xd, v, memo):
    """:func:`device_tangent` after :func:`device_step_memo` with the same ``memo``: a model that
    stored its end-of-step tangent there (the Spencer types) returns it without evaluating its
    voltage laws again."""
    if model_id == SPENCER_ID or model_id == VIRTUAL_DAMPER_ID or model_id == SERIES_DASHPOT_ID:
        return spencer_type_tangent_memo(params, memo)
    return device_tangent(model_id, params, state, x, xd, v)
