"""The registered damper models by name, and the one dispatch kernel.

Every damper model is a frozen parameter dataclass in its own module that subclasses
:class:`damper.models.base.DamperModel` (the contract: ``name``, ``kernel``, ``n_states``,
``to_array()``, ``initial_state()``, ``voltage_range``, plain-numpy ``rates``/``force``) and is
decorated with :func:`~damper.models.base.register_model`, which files it under its ``name`` in
:data:`~damper.models.base.MODELS`. The building's stepping kernel and :func:`damper.simulate` call
:func:`device_step` with the model's *kernel family* (:data:`damper.models.base.KERNELS`), its
packed parameters and its state, so adding a model is one decorated class (a test registers a toy
model and runs it in the building: ``tests/damper/test_model_registration.py``). This module imports
the built-in model modules, which registers them.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from benchmark.foundation.errors import InputError
from damper.models.base import (KERNEL_BINGHAM, KERNEL_BOUC_WEN, KERNEL_FORCE_TERMS, KERNEL_HYPERBOLIC_TANGENT,
                                KERNEL_SPENCER_TYPE, MODELS, DamperModel, register_model)
from damper.models.bouc_wen import bouc_wen_force, bouc_wen_step, bouc_wen_step_memo
from damper.models.spencer import (LOCKSTEP_NODE_COLUMNS, MEMO_LENGTH, SPENCER_LOCKSTEP_ROWS,
                                   spencer_type_force_kernel, spencer_type_lockstep, spencer_type_step,
                                   spencer_type_step_memo, spencer_type_tangent, spencer_type_tangent_memo)
from damper.models.bingham import bingham_force, bingham_step
from damper.models.hyperbolic_tangent import hyperbolic_tangent_force, hyperbolic_tangent_step
from damper.models.force_terms import WithForceTerms, force_terms, force_terms_tangent
from damper.models import dahl, series_dashpot, virtual  # noqa: F401  (importing registers them)

__all__ = [
    "MODELS",
    "register_model",
    "get_model_class",
    "check_registered",
    "kernel_id_of",
    "device_step",
    "device_step_memo",
    "devices_step_memo",
    "DevicesWorkspace",
    "devices_workspace",
    "MEMO_LENGTH",
    "device_tangent",
    "device_tangent_memo",
    "device_force",
    "WithForceTerms",
]

def get_model_class(name: str) -> type[DamperModel]:
    """The model class registered as ``name``.

    Parameters
    ----------
    name : str
        A registered name (:data:`MODELS`).

    Returns
    -------
    type
        The :class:`~damper.models.base.DamperModel` subclass.

    Raises
    ------
    InputError
        For an unknown name (the message lists the names).
    """
    return MODELS.get_class(name)


def check_registered(model: DamperModel) -> None:
    """Check that ``model`` is an instance of a registered damper model class.

    Parameters
    ----------
    model : DamperModel
        A model instance.

    Raises
    ------
    InputError
        If its class is not registered.
    """
    cls = MODELS.get(getattr(model, "name", None)) if isinstance(getattr(model, "name", None), str) else None
    if cls is None or not isinstance(model, cls):
        raise InputError(f"damper model: {type(model).__name__} is not a registered damper model; "
                         "expected one of " + ", ".join(sorted(MODELS)))


def kernel_id_of(model: DamperModel) -> int:
    """The kernel family (:data:`damper.models.base.KERNELS`) of a registered model instance: the
    number :func:`device_step` dispatches on.

    Parameters
    ----------
    model : DamperModel
        A registered model instance.

    Returns
    -------
    int
        Its kernel family id.
    """
    check_registered(model)
    return int(type(model).kernel)


@numba.njit(cache=True)
def _inner(kernel_id, params):
    """The kernel family and packed parameters that advance the device's states: the inner model's
    for :data:`~damper.models.base.KERNEL_FORCE_TERMS` (:mod:`damper.models.force_terms`), else its own.
    One call site per dispatch keeps the compiled code small (every family inlined once)."""
    if kernel_id == KERNEL_FORCE_TERMS:
        return int(params[0]), params[2:2 + int(params[1])]
    return kernel_id, params[0:params.shape[0]]


@numba.njit(cache=True)
def _family_step(kernel_id, params, state, x0, x1, xd0, xd1, v, dt):
    """:func:`device_step` of the built-in kernel families."""
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
    kid, inner = _inner(kernel_id, params)
    f = _family_step(kid, inner, state, x0, x1, xd0, xd1, v, dt)
    return force_terms(params, f, x1, xd1) if kernel_id == KERNEL_FORCE_TERMS else f


@numba.njit(cache=True)
def _family_step_memo(kernel_id, params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`device_step_memo` of the built-in kernel families."""
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo)
    if kernel_id == KERNEL_BOUC_WEN:
        return bouc_wen_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo)
    return _family_step(kernel_id, params, state, x0, x1, xd0, xd1, v, dt)


@numba.njit(cache=True)
def device_step_memo(kernel_id, params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`device_step` with a per-device scratch array ``memo`` (float64, :data:`MEMO_LENGTH`,
    filled with NaN before the device's first step) in which a model keeps values that depend
    only on the step's start state and voltage, reused when the same device is advanced again
    from the same state (the building's fixed-point iteration) or at the same voltage (a
    simulation at constant or piecewise-constant voltage): the Spencer types' voltage laws, the
    Bouc-Wen coefficients (:func:`damper.models.bouc_wen.bouc_wen_step_memo`). Same results as
    :func:`device_step` to rounding (``tests/damper/test_bouc_wen_shortcuts.py``,
    ``tests/damper/test_spencer_memo.py``); models without such values ignore ``memo``.

    Parameters
    ----------
    kernel_id
        Kernel family of the device (:data:`damper.models.base.KERNELS`).
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
    memo
        Per-device scratch array (float64, :data:`damper.models.registry.MEMO_LENGTH` entries) shared by the step
        and tangent calls of one device.
    """
    kid, inner = _inner(kernel_id, params)
    f = _family_step_memo(kid, inner, state, x0, x1, xd0, xd1, v, dt, memo)
    return force_terms(params, f, x1, xd1) if kernel_id == KERNEL_FORCE_TERMS else f


@numba.njit(cache=True)
def _family_force(kernel_id, params, state, x, xd, v):
    """:func:`device_force` of the built-in kernel families."""
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
def device_force(kernel_id, params, state, x, xd, v):
    """Force [N] of a device at its current state, displacement ``x`` [m], velocity ``xd`` [m/s]
    and voltage ``v`` [V] (no state change); NaN for an unknown ``kernel_id``.

    Parameters
    ----------
    kernel_id
        Kernel family of the device (:data:`damper.models.base.KERNELS`).
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
    kid, inner = _inner(kernel_id, params)
    f = _family_force(kid, inner, state, x, xd, v)
    return force_terms(params, f, x, xd) if kernel_id == KERNEL_FORCE_TERMS else f


@numba.njit(cache=True)
def _family_tangent(kernel_id, params, state, x, xd, v):
    """:func:`device_tangent` of the built-in kernel families."""
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_tangent(params, state, x, xd)
    return 0.0, 0.0


@numba.njit(cache=True)
def device_tangent(kernel_id, params, state, x, xd, v):
    """``(dF/dx [N/m], dF/dxd [N·s/m])`` of a device at its current state (internal states held).

    The building's Newton iteration on the base uses them at the end of a step. Models without
    a tangent return ``(0, 0)``: the iteration then treats their force as given, which only
    slows its convergence (the fixed point and the convergence test are unchanged).

    Parameters
    ----------
    kernel_id
        Kernel family of the device (:data:`damper.models.base.KERNELS`).
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
    kid, inner = _inner(kernel_id, params)
    kx, kxd = _family_tangent(kid, inner, state, x, xd, v)
    if kernel_id == KERNEL_FORCE_TERMS:
        return force_terms_tangent(params, _family_force(kid, inner, state, x, xd, v), kx, kxd, xd)
    return kx, kxd


@numba.njit(cache=True)
def _family_tangent_memo(kernel_id, params, state, x, xd, v, memo):
    """:func:`device_tangent_memo` of the built-in kernel families."""
    if kernel_id == KERNEL_SPENCER_TYPE:
        return spencer_type_tangent_memo(params, memo)
    return _family_tangent(kernel_id, params, state, x, xd, v)


@numba.njit(cache=True)
def device_tangent_memo(kernel_id, params, state, x, xd, v, memo):
    """:func:`device_tangent` after :func:`device_step_memo` with the same ``memo``: a model that
    stored its end-of-step tangent there (the Spencer types) returns it without evaluating its
    voltage laws again.

    Parameters
    ----------
    kernel_id
        Kernel family of the device (:data:`damper.models.base.KERNELS`).
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
    memo
        Per-device scratch array (float64, :data:`damper.models.registry.MEMO_LENGTH` entries) shared by the step
        and tangent calls of one device.
    """
    kid, inner = _inner(kernel_id, params)
    kx, kxd = _family_tangent_memo(kid, inner, state, x, xd, v, memo)
    if kernel_id == KERNEL_FORCE_TERMS:
        return force_terms_tangent(params, _family_force(kid, inner, state, x, xd, v), kx, kxd, xd)
    return kx, kxd


class DevicesWorkspace(NamedTuple):
    """Scratch arrays of :func:`devices_step_memo` for ``n`` devices (made by :func:`devices_workspace`).

    Parameters
    ----------
    lock
        ``(n,)`` bool: the device is advanced in lock-step (a Spencer-type kernel).
    memo
        ``(n, MEMO_LENGTH)``: each device's memo (:func:`device_step_memo`).
    x0, x1, xd0, xd1
        ``(n,)``: the step's displacements [m] and velocities [m/s] at its start and end, per
        device, set by the caller before each :func:`devices_step_memo`.
    rows
        ``(SPENCER_LOCKSTEP_ROWS, n)``: the lock-step's per-device values, one column a device.
    nodes
        ``(n, LOCKSTEP_NODE_COLUMNS)``: the voltage laws at each device's RK4 nodes.
    order
        ``(n,)`` int64: the lock-step devices in the order of decreasing sub-step counts.
    n_subs
        ``(n,)`` int64: their sub-step counts, in that order.
    """

    lock: np.ndarray
    memo: np.ndarray
    x0: np.ndarray
    x1: np.ndarray
    xd0: np.ndarray
    xd1: np.ndarray
    rows: np.ndarray
    nodes: np.ndarray
    order: np.ndarray
    n_subs: np.ndarray


@numba.njit(cache=True)
def devices_workspace(kernel_ids, lockstep):
    """The workspace of :func:`devices_step_memo` for devices of the kernel families
    ``kernel_ids`` (``(n,)`` int), the Spencer types in lock-step if ``lockstep``; every memo
    filled with NaN (no step taken yet).

    Parameters
    ----------
    kernel_ids
        Kernel family of each device (:data:`damper.models.base.KERNELS`).
    lockstep
        Whether the Spencer-type devices are advanced in lock-step (else each on its own, the
        reference path).
    """
    n = kernel_ids.shape[0]
    lock = np.zeros(n, dtype=np.bool_)
    for j in range(n):
        lock[j] = lockstep and kernel_ids[j] == KERNEL_SPENCER_TYPE
    return DevicesWorkspace(lock, np.full((n, MEMO_LENGTH), np.nan), np.empty(n), np.empty(n), np.empty(n),
                            np.empty(n), np.empty((SPENCER_LOCKSTEP_ROWS, n)),
                            np.empty((n, LOCKSTEP_NODE_COLUMNS)), np.empty(n, dtype=np.int64),
                            np.empty(n, dtype=np.int64))


@numba.njit(cache=True)
def devices_step_memo(kernel_ids, params, state, v, dt, ws, force):
    """Advance every device over one step along the motion in ``ws.x0, ws.x1, ws.xd0, ws.xd1``;
    write the forces [N] into ``force``.

    :func:`device_step_memo` for each device, the Spencer-type devices marked in ``ws.lock``
    together (:func:`damper.models.spencer.spencer_type_lockstep`: the same arithmetic, their
    RK4 chains overlapped).

    Parameters
    ----------
    kernel_ids
        ``(n,)`` kernel family of each device (:data:`damper.models.base.KERNELS`).
    params
        ``(n, P)`` packed parameters (each model's ``to_array()``, padded).
    state
        ``(n, S)`` internal states, advanced in place.
    v
        ``(n,)`` commanded voltages [V], held over the step.
    dt
        Step length [s].
    ws
        :func:`devices_workspace` of these devices; its motion arrays set by the caller.
    force
        ``(n,)`` output.
    """
    n = kernel_ids.shape[0]
    any_lock = False
    for j in range(n):
        any_lock = any_lock or ws.lock[j]
    if any_lock:
        spencer_type_lockstep(params, state, ws.memo, ws.lock, ws.x0, ws.x1, ws.xd0, ws.xd1, v, dt,
                              ws.rows, ws.nodes, ws.order, ws.n_subs, force)
    for j in range(n):
        if not ws.lock[j]:
            force[j] = device_step_memo(kernel_ids[j], params[j], state[j], ws.x0[j], ws.x1[j], ws.xd0[j],
                                        ws.xd1[j], v[j], dt, ws.memo[j])
