r"""Registry of bearing types and the one dispatch kernel the building's stepping kernel calls.

Contract with the building core
-------------------------------
* Every bearing's flat parameter array starts with its **linear part**:
  ``params[0] = k`` [N/m] and ``params[1] = c`` [N·s/m] per horizontal direction
  (linear bearing: k, c; lead-rubber: alpha k_initial, c; friction pendulum: W/R, c).
  The building puts :math:`\sum_i k_i T_i^\mathsf{T} T_i` and :math:`\sum_i c_i T_i^\mathsf{T} T_i`
  into its exact discretisation (:func:`linear_part` in Python, ``params[0:2]`` in numba).
* :func:`bearing_step` advances the bearing's internal states and writes into ``force_out``
  the **remaining (hysteretic) force** :math:`f - k u - c \dot u` [N] at the end of the step
  (zero for a linear bearing). The total bearing force is therefore
  ``k*u1 + c*v1 + force_out`` (:func:`bearing_total_force`).
* ``state`` is a float64 array of length ``n_states`` of the type (0 for linear, 2 for the
  Park–Wen types), typically a row of an ``(n_bearings, MAX_STATES)`` array (rows may be
  longer than ``n_states``; extra entries are untouched). ``params`` may likewise be a row of an
  ``(n_bearings, MAX_PARAMS)`` array padded with zeros (see
  :meth:`benchmark.simulator.isolation.configurations.IsolationLayer.pack`).
* Sub-stepping: each nonlinear type sub-steps internally from its hysteretic stiffness
  (:mod:`benchmark.simulator.isolation.park_wen`); the tolerance is the last entry of its parameter
  array (``substep_tolerance`` field of the dataclass, default 0.75).
* For a continuous-time oracle (scipy ``solve_ivp``) use the dataclasses' plain-numpy
  ``rates(state, ux, uy, vx, vy)`` (d state/dt) and ``force(...)`` (total force) methods.

* :func:`bearing_tangent` writes the hysteretic force's derivatives with respect to the end
  displacement and velocity (2 x 4) at the state after :func:`bearing_step`; the kernel's Newton
  iteration on the base uses them. A type without one (zeros) still converges, by the kernel's
  fixed-point fallback, only more slowly.

Adding a bearing type is one class decorated with
:func:`benchmark.simulator.isolation.base.register_bearing` (registry :data:`BEARINGS`); the
integer the kernels below dispatch on is the class's kernel *family*
(:data:`benchmark.simulator.isolation.base.BEARING_KERNELS`), never an id chosen per type. A new
family adds its numba step beside its class and one branch each to :func:`bearing_step`,
:func:`bearing_step_closed_form` and :func:`bearing_tangent`; a Park–Wen family also gives its
``lockstep_form`` (``_LOCKSTEP_FORMS``) so that :func:`bearings_step_lockstep` takes its RK4
sub-steps together with the other bearings' (without one it takes the per-bearing update).
"""

from __future__ import annotations

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.simulator.isolation import friction_pendulum, lead_rubber, linear
from benchmark.simulator.isolation.base import (BEARING_KERNELS, BEARINGS, KERNEL_FRICTION_PENDULUM,
                                                 KERNEL_LEAD_RUBBER, KERNEL_LINEAR, BearingParameters)
from benchmark.simulator.isolation.friction_pendulum import (FrictionPendulumBearing, friction_pendulum_step,
                                                   friction_pendulum_step_closed_form, friction_pendulum_tangent)
from benchmark.simulator.isolation.lead_rubber import (LeadRubberBearing, lead_rubber_step, lead_rubber_step_closed_form,
                                             lead_rubber_tangent)
from benchmark.simulator.isolation.linear import LinearBearing, linear_step
from benchmark.simulator.isolation.park_wen import LOCKSTEP_FORM, park_wen_lockstep, park_wen_path

__all__ = [
    "BEARINGS", "BEARING_NAMES", "bearing_names", "KERNEL_N_PARAMS", "MAX_STATES", "MAX_PARAMS", "bearing_type", "bearing_step",
    "bearing_step_closed_form", "bearing_tangent", "bearings_step_lockstep", "lockstep_forms",
    "bearing_total_force", "linear_part", "LinearBearing", "LeadRubberBearing",
    "FrictionPendulumBearing", "BearingParameters",
]

#: kernel family -> length of its packed parameter array (the layout every type of the family packs into)
KERNEL_N_PARAMS: dict[int, int] = {KERNEL_LINEAR: linear.N_PARAMS, KERNEL_LEAD_RUBBER: lead_rubber.N_PARAMS,
                                   KERNEL_FRICTION_PENDULUM: friction_pendulum.N_PARAMS}
#: the built-in bearing type names ("linear", "lead-rubber", "friction-pendulum"); :func:`bearing_names`
#: also lists the types registered since
BEARING_NAMES: tuple[str, ...] = tuple(BEARINGS)
#: largest number of internal states of any kernel family (the Park–Wen families: z_x, z_y)
MAX_STATES: int = 2
#: largest parameter-array length of any kernel family
MAX_PARAMS: int = max(KERNEL_N_PARAMS.values())

assert set(KERNEL_N_PARAMS) == set(BEARING_KERNELS)
assert all(cls.n_states <= MAX_STATES for cls in BEARINGS.values())


def bearing_names() -> tuple[str, ...]:
    """Names of every registered bearing type (built-in and registered since).

    Returns
    -------
    tuple of str
        Registered names, in registration order.
    """
    return tuple(BEARINGS)


def bearing_type(key: str) -> type[BearingParameters]:
    """Return the parameter class of a registered bearing type.

    Parameters
    ----------
    key : str
        Registered name (:func:`bearing_names`).

    Raises
    ------
    ParameterError
        If the type is unknown (the message lists the known ones).
    """
    cls = BEARINGS.get(key) if isinstance(key, str) else None
    if cls is None:
        raise ParameterError(f"bearing type {key!r} unknown: expected one of {', '.join(bearing_names())}")
    return cls


def linear_part(type_id: int, params: np.ndarray) -> tuple[float, float]:
    """``(k, c)`` of a packed bearing: linear stiffness [N/m] and damping [N·s/m] per direction.

    Parameters
    ----------
    type_id : int
        Kernel family id (checked only: the layout starts with ``k, c`` in every family).
    params : ndarray
        The bearing's packed parameters; returns ``params[0], params[1]``.

    Raises
    ------
    ParameterError
        If ``type_id`` is not a kernel family.
    """
    if isinstance(type_id, bool) or type_id not in BEARING_KERNELS:
        raise ParameterError(f"bearing kernel family {type_id!r} unknown: expected one of {sorted(BEARING_KERNELS)}")
    return float(params[0]), float(params[1])


@numba.njit(cache=True, inline="always")
def bearing_step(type_id, params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out):
    """Advance one bearing's internal states (in place) along one structural step.

    The path goes from displacement (ux0, uy0), velocity (vx0, vy0) to (ux1, uy1), (vx1, vy1)
    over ``dt`` [m, m/s, s] (cubic Hermite in time), sub-stepping as the bearing's stiffness
    needs. Writes the bearing's **hysteretic force** (total force minus ``params[0]*u1 +
    params[1]*v1``) at the end of the step, ``(fx, fy)`` [N], into ``force_out[0:2]``.
    An unknown ``type_id`` writes NaN (the stepping kernel's NaN check reports it).

    Parameters
    ----------
    type_id
        Kernel family id of the bearing (:data:`benchmark.simulator.isolation.base.BEARING_KERNELS`).
    params
        Packed bearing parameters (``pack()`` of the bearing's parameters, float64).
    state
        Internal (hysteretic) states of the bearing.
    ux0
        Displacement in x at the start of the step [m].
    uy0
        Displacement in y at the start of the step [m].
    ux1
        Displacement in x at the end of the step [m].
    uy1
        Displacement in y at the end of the step [m].
    vx0
        Velocity in x at the start of the step [m/s].
    vy0
        Velocity in y at the start of the step [m/s].
    vx1
        Velocity in x at the end of the step [m/s].
    vy1
        Velocity in y at the end of the step [m/s].
    dt
        Step length [s].
    force_out
        Array of 2 the force (x, y) [N] is written into.
    """
    if type_id == KERNEL_LINEAR:
        linear_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out)
    elif type_id == KERNEL_LEAD_RUBBER:
        lead_rubber_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out)
    elif type_id == KERNEL_FRICTION_PENDULUM:
        friction_pendulum_step(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out)
    else:
        force_out[0] = np.nan
        force_out[1] = np.nan


@numba.njit(cache=True, inline="always")
def bearing_step_closed_form(type_id, params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out, tangent):
    """Closed-form update of one bearing over one structural step, with its tangent.

    Same contract as :func:`bearing_step` (hysteretic force at the end of the step into
    ``force_out``), but the Park–Wen types advance each monotone piece of the path by the
    model's exact flow along its chord
    (:func:`benchmark.simulator.isolation.park_wen.park_wen_closed_form`; no sub-steps, no
    iteration, unconditionally stable) instead of RK4 sub-steps, and write into ``tangent`` (2 x 4, the layout of :func:`bearing_tangent`) the
    derivatives of that update's force with respect to the end displacement and velocity.
    Linear and unknown types as in :func:`bearing_step` (tangent zero).

    Parameters
    ----------
    type_id : int
        The bearing type (0 linear, 1 lead-rubber, 2 friction pendulum).

    params : ndarray
        The bearing's packed parameters (its ``pack()``, float64, SI).
    state : ndarray
        Its hysteretic state ``[z_x, z_y]``, advanced in place.
    ux0, uy0, ux1, uy1 : float
        Bearing displacement (x, y) at the start and the end of the step [m].
    vx0, vy0, vx1, vy1 : float
        Bearing velocity (x, y) at the start and the end of the step [m/s].
    dt : float
        Step length [s].
    force_out : ndarray, shape (2,)
        Receives the hysteretic force (x, y) at the end of the step [N].
    tangent : ndarray, shape (2, 4)
        Receives d force / d (ux1, uy1) [N/m] and d force / d (vx1, vy1) [N s/m].
    """
    if type_id == KERNEL_LEAD_RUBBER:
        lead_rubber_step_closed_form(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out, tangent)
    elif type_id == KERNEL_FRICTION_PENDULUM:
        friction_pendulum_step_closed_form(params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out,
                                        tangent)
    else:
        bearing_step(type_id, params, state, ux0, uy0, ux1, uy1, vx0, vy0, vx1, vy1, dt, force_out)
        for a in range(2):
            for b in range(4):
                tangent[a, b] = 0.0


#: kernel family -> the lock-step form of its packed parameters (:func:`lockstep_forms`)
_LOCKSTEP_FORMS = {KERNEL_LEAD_RUBBER: LeadRubberBearing.lockstep_form,
                   KERNEL_FRICTION_PENDULUM: FrictionPendulumBearing.lockstep_form}


def lockstep_forms(type_ids: np.ndarray, params: np.ndarray) -> np.ndarray:
    """The bearings' lock-step forms, one column each (:data:`park_wen.LOCKSTEP_FORM` rows).

    A family without one (the linear bearing, whose force is all in the linear part) gets a
    column of NaN: :func:`bearings_step_lockstep` advances it by :func:`bearing_step` instead.

    Parameters
    ----------
    type_ids : ndarray of int (n,)
        Kernel family of each bearing.
    params : ndarray (n, MAX_PARAMS)
        Packed parameters.
    """
    form = np.full((LOCKSTEP_FORM, len(type_ids)), np.nan)
    for i, family in enumerate(type_ids):
        to_form = _LOCKSTEP_FORMS.get(int(family))
        if to_form is not None:
            form[:, i] = to_form(params[i])
    return form


@numba.njit(cache=True, fastmath={"reassoc", "contract"})  # the flags of the stepping kernel it serves
def bearings_step_lockstep(type_id, params, state, form, xy, ux0b, uy0b, th0, ub1, vx0b, vy0b, om0, vb1, dt,
                           ws, ns, force_out):
    """Advance all bearings of a rigid base over one step, the RK4 sub-steps in lock-step.

    The result of :func:`bearing_step` for every bearing (the same path, sub-steps and
    arithmetic, to rounding), but the Park–Wen bearings whose step is one monotone segment
    advance together (:func:`park_wen.park_wen_lockstep`, vectorised across bearings); a
    bearing whose path turns inside the step (a velocity reversal: about 5 % of the
    bearing-steps of a Kobe run) or that has no lock-step form takes :func:`bearing_step`.

    Parameters
    ----------
    type_id, params, state : ndarray
        The bearings' families (n,), packed parameters (n, MAX_PARAMS) and states (n,
        MAX_STATES), the states advanced in place.
    form : ndarray (LOCKSTEP_FORM, n)
        :func:`lockstep_forms`.
    xy : ndarray (n, 2)
        Plan positions [m].
    ux0b, uy0b, th0, vx0b, vy0b, om0 : float
        The base's displacement [m, m, rad] and velocity [m/s, m/s, rad/s] at the start.
    ub1, vb1 : ndarray (3,)
        The same at the end of the step.
    dt : float
        Step length [s].
    ws, ns : ndarray
        Workspace (LOCKSTEP_ROWS, n) and sub-step counts (n,) int64.
    force_out : ndarray (n, 2)
        Receives each bearing's hysteretic force at the end of the step [N].
    """
    nb = xy.shape[0]
    force = np.empty(2)
    for i in range(nb):
        bx = xy[i, 0]
        by = xy[i, 1]
        ns[i] = 0
        if form[0, i] == form[0, i]:
            ns[i] = park_wen_path(ws, i, ux0b - by * th0, uy0b + bx * th0, ub1[0] - by * ub1[2],
                                  ub1[1] + bx * ub1[2], vx0b - by * om0, vy0b + bx * om0, vb1[0] - by * vb1[2],
                                  vb1[1] + bx * vb1[2], dt, form[3, i])
        ws[9, i] = state[i, 0] if ns[i] > 0 else 0.0
        ws[10, i] = state[i, 1] if ns[i] > 0 else 0.0
    park_wen_lockstep(ws, ns, form[0], form[1], form[2])
    for i in range(nb):
        bx = xy[i, 0]
        by = xy[i, 1]
        vx1 = vb1[0] - by * vb1[2]
        vy1 = vb1[1] + bx * vb1[2]
        if ns[i] > 0:
            state[i, 0] = ws[9, i]
            state[i, 1] = ws[10, i]
            speed = np.sqrt(vx1 * vx1 + vy1 * vy1)
            mu = form[5, i] - form[6, i] * np.exp(-form[7, i] * speed)
            w = mu * form[4, i]
            force_out[i, 0] = w * ws[9, i]
            force_out[i, 1] = w * ws[10, i]
        else:
            bearing_step(type_id[i], params[i], state[i], ux0b - by * th0, uy0b + bx * th0, ub1[0] - by * ub1[2],
                         ub1[1] + bx * ub1[2], vx0b - by * om0, vy0b + bx * om0, vx1, vy1, dt, force)
            force_out[i, 0] = force[0]
            force_out[i, 1] = force[1]


@numba.njit(cache=True)
def bearing_total_force(params, ux, uy, vx, vy, hysteretic_force, force_out):
    """Total bearing force = linear part + hysteretic force (as written by :func:`bearing_step`).

    Parameters
    ----------
    params
        Packed bearing parameters (``pack()`` of the bearing's parameters, float64).
    ux
        Bearing displacement in x [m].
    uy
        Bearing displacement in y [m].
    vx
        Bearing velocity in x [m/s].
    vy
        Bearing velocity in y [m/s].
    hysteretic_force
        The hysteretic force (x, y) [N] written by :func:`bearing_step`.
    force_out
        Array of 2 the force (x, y) [N] is written into.
    """
    force_out[0] = params[0] * ux + params[1] * vx + hysteretic_force[0]
    force_out[1] = params[0] * uy + params[1] * vy + hysteretic_force[1]


@numba.njit(cache=True, inline="always")
def bearing_tangent(type_id, params, state, dx, dy, vx1, vy1, tangent):
    """Derivatives of the hysteretic force at the end of a step, after :func:`bearing_step`.

    Writes ``tangent[:, 0:2]`` = d(fx, fy)/d(ux1, uy1) [N/m] and ``tangent[:, 2:4]`` =
    d(fx, fy)/d(vx1, vy1) [N·s/m] of the bearing of type ``type_id`` with packed ``params``,
    at its current (end-of-step) ``state``;
    ``(dx, dy)`` is the step's displacement (its direction of motion), ``(vx1, vy1)`` the end
    velocity [m/s]. Zero for a linear bearing (its force is all in the linear part) and for an
    unknown type.

    Parameters
    ----------
    type_id
        Kernel family id of the bearing (:data:`benchmark.simulator.isolation.base.BEARING_KERNELS`).
    params
        Packed bearing parameters (``pack()`` of the bearing's parameters, float64).
    state
        Internal (hysteretic) states of the bearing.
    dx
        Displacement increment in x over the step [m].
    dy
        Displacement increment in y over the step [m].
    vx1
        Velocity in x at the end of the step [m/s].
    vy1
        Velocity in y at the end of the step [m/s].
    tangent
        Array (2, 2) the derivatives d f_h / d u [N/m] are written into.
    """
    if type_id == KERNEL_LEAD_RUBBER:
        lead_rubber_tangent(params, state, dx, dy, vx1, vy1, tangent)
    elif type_id == KERNEL_FRICTION_PENDULUM:
        friction_pendulum_tangent(params, state, dx, dy, vx1, vy1, tangent)
    else:
        for a in range(2):
            for b in range(4):
                tangent[a, b] = 0.0
