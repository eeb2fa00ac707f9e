"""Force history of a damper model under a prescribed displacement and voltage history.

:func:`simulate` runs the same compiled kernels the building uses
(:func:`damper.models.registry.device_step_memo`), step by step between the given samples.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from benchmark.foundation.errors import InputError, NumericalError
from damper.io.data import check_samples
from damper.models.registry import MEMO_LENGTH, device_force, device_step_memo, kernel_id_of
from benchmark.foundation.kernel_cache import ensure_fresh_once

__all__ = ["DamperResponse", "simulate", "prepare_motion"]


@dataclass(frozen=True)
class DamperResponse:
    """Response of a damper model to a prescribed motion (SI units).

    Attributes
    ----------
    t : ndarray (n,)
        Time [s].
    displacement, velocity : ndarray (n,)
        Prescribed motion [m, m/s].
    voltage : ndarray (n,)
        Commanded voltage [V] (held from each sample to the next).
    force : ndarray (n,)
        Device force [N].
    states : ndarray (n, n_states)
        Internal states after each sample (``model.state_names`` where defined).
    model : object
        The model simulated.
    """

    t: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    voltage: np.ndarray
    force: np.ndarray
    states: np.ndarray
    model: object = field(repr=False)


def _as_1d(name: str, values, n: int | None = None) -> np.ndarray:
    return check_samples(values, name, n, allow_scalar=n is not None, reference="t")


def prepare_motion(model, t, x, xdot=None, v=0.0):
    """Validate and broadcast ``(t, x, xdot, v)``; ``xdot`` defaults to ``np.gradient(x, t)``.

    Raises :class:`InputError` for mismatched lengths, non-finite values, a time axis that is
    not strictly increasing, or a voltage outside ``model.voltage_range``.

    Parameters
    ----------
    model
        The damper model (its voltage range is checked).
    t
        Sample times [s], increasing.
    x
        Displacement history [m] at ``t``.
    xdot : ndarray, optional
        Velocity history [m/s]; None: ``np.gradient(x, t)``.
    v : float or ndarray, optional
        Voltage [V], a number or a history at ``t``.
    """
    t = _as_1d("t", t)
    if t.size < 2:
        raise InputError(f"t: expected at least 2 samples, got {t.size}")
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise InputError(f"t: expected strictly increasing times, t[{i + 1}] = {t[i + 1]} "
                         f"after t[{i}] = {t[i]}")
    x = _as_1d("x", x, t.size)
    xdot = np.gradient(x, t, edge_order=2) if xdot is None else _as_1d("xdot", xdot, t.size)
    v = _as_1d("v", v, t.size)
    lo, hi = model.voltage_range
    # a command stored in single precision (an HDF5 history) comes back up to 1e-7 of the range
    # off its edge: within a millionth of the range it is the edge, not an input outside it
    tol = max(1e-12, 1e-6 * (hi - lo))
    if np.any(v < lo - tol) or np.any(v > hi + tol):
        i = int(np.argmax((v < lo - tol) | (v > hi + tol)))
        raise InputError(f"v: expected voltages in [{lo:.10g}, {hi:.10g}] V for {model.name}, "
                         f"got {v[i]:.10g} V at sample {i}")
    if np.any(v < lo) or np.any(v > hi):
        v = np.clip(v, lo, hi)
    return t, x, xdot, v


@numba.njit(cache=True)
def _run(kernel_id, params, state, t, x, xd, v, force, states):
    force[0] = device_force(kernel_id, params, state, x[0], xd[0], v[0])
    states[0, :] = state
    # the models' per-device memo (device_step_memo): values kept while the voltage holds
    memo = np.full(MEMO_LENGTH, np.nan)
    for k in range(t.size - 1):
        f = device_step_memo(kernel_id, params, state, x[k], x[k + 1], xd[k], xd[k + 1], v[k],
                             t[k + 1] - t[k], memo)
        if not np.isfinite(f):
            return k + 1
        force[k + 1] = f
        states[k + 1, :] = state
    return -1


def simulate(model, t, x, xdot=None, v=0.0, state0=None) -> DamperResponse:
    """Force history of ``model`` under displacement ``x(t)`` [m] and voltage ``v(t)`` [V].

    Parameters
    ----------
    model : damper model
        Any registered model instance (see :mod:`damper.models.registry`).
    t : array_like (n,)
        Strictly increasing sample times [s].
    x : array_like (n,)
        Displacement [m].
    xdot : array_like (n,), optional
        Velocity [m/s]; defaults to the second-order finite difference of ``x``.
    v : float or array_like (n,)
        Voltage [V], held constant from sample ``k`` to ``k + 1``; must lie in
        ``model.voltage_range``.
    state0 : array_like, optional
        Initial internal state (default ``model.initial_state()``).

    Returns
    -------
    DamperResponse

    Raises
    ------
    InputError
        Malformed inputs or a voltage out of range.
    NumericalError
        The force became NaN or infinite.
    """
    ensure_fresh_once()  # numba caches consistent with the kernels they call (kernel_cache)
    kernel_id = kernel_id_of(model)
    t, x, xdot, v = prepare_motion(model, t, x, xdot, v)
    state = (np.array(model.initial_state(), dtype=np.float64) if state0 is None
             else _as_1d("state0", state0).copy())
    if state.size != model.n_states:
        raise InputError(f"state0: expected {model.n_states} values for {model.name}, got {state.size}")
    params = model.to_array()
    force = np.empty(t.size)
    states = np.empty((t.size, max(model.n_states, 0)))
    failed = _run(kernel_id, params, state, t, x, xdot, v, force, states)
    if failed >= 0 or not np.isfinite(force[0]):
        k = max(failed, 0)
        names = getattr(model, "state_names", tuple(f"s{i}" for i in range(model.n_states)))
        raise NumericalError(f"{model.name}: force is not finite", time=float(t[k]),
                             state={"x": float(x[k]), "xdot": float(xdot[k]), "v": float(v[k]),
                                    **{n: float(s) for n, s in zip(names, state)}},
                             hint="check the model parameters and the sampling of the motion (a hysteresis that "
                                  "would need more than 200 000 sub-steps per sample also ends here)")
    return DamperResponse(t=t, displacement=x, velocity=xdot, voltage=v, force=force,
                          states=states, model=model)
