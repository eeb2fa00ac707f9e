"""The stepping kernel's arguments as objects: named tuples numba passes by reference.

:func:`benchmark.simulator.stepping.run_steps` takes seven structured arguments instead of 55 arrays:

==============  ===========================================================================
argument        fields
==============  ===========================================================================
:class:`Plant`  the exact linear step of the superstructure, base and the bearings' linear
                parts (``Phi``, ``G0``, ``G1`` of :func:`benchmark.simulator.stepping.discretize_foh`),
                the base rows ``Gb`` of ``G1``, the record step ``dt`` [s], ``nq``
:class:`Bearings`  index in the layer, plan positions [m], type ids, packed parameters and
                states (advanced in place) of the bearings with a hysteretic force
                (:mod:`benchmark.simulator.isolation.registry`); linear bearings are wholly in ``Plant``
:class:`Devices`  influence rows (device stroke per base x, y [m], θ [rad]), model ids,
                packed parameters and states (advanced in place) (:mod:`damper.models.registry`)
:class:`Sensors`  the acceleration rows of the measurement (``C_acc``, ``D_acc_g``,
                ``D_acc_ag`` of :func:`benchmark.simulator.linear_model.state_space_matrices`), the noise
                of every control step, the sensor ranges and the
                :class:`controllers.measurements.MeasurementLayout`
:class:`Control`  mode (0 none or voltages held, 1 compiled controller, 2 voltages set by a
                Python controller between calls), control ratio, the compiled controller's
                arrays (:mod:`controllers.compiled`) and its state and voltages (in place)
:class:`Settings`  fixed-point tolerance, iteration cap, blow-up limit [m], whether the
                per-bearing histories are kept
:class:`Outputs`  the histories the kernel writes
==============  ===========================================================================

Each is built once per run (:func:`pack_run`, called by :func:`benchmark.simulator.simulation.simulate`), and the plant and the
sensor rows once per building and record step (cached). Numba compiles the kernel once per
combination of field types, which are fixed here (float64 C-contiguous arrays, int64 ids).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.simulator.control import control_context
from benchmark.simulator.isolation.registry import LinearBearing, lockstep_forms
from benchmark.simulator.sensors import n_measurements, noise_samples
from controllers.base import ControllerSession
from controllers.measurements import MeasurementLayout, measurement_layout

__all__ = ["Plant", "Bearings", "Devices", "Sensors", "Control", "Settings", "Outputs", "make_outputs",
           "KernelRun", "pack_run"]


class Plant(NamedTuple):
    """Exact first-order-hold step of the linear part: ``z1 = Phi z0 + G0 w0 + G1 w1`` (SI).

    Parameters
    ----------
    dt : float
        Record (structural) step [s].
    nq : int
        Number of superstructure coordinates.
    Phi : np.ndarray
        State transition matrix (nz, nz).
    G0 : np.ndarray
        Input matrix of the inputs at the step's start (nz, 5).
    G1 : np.ndarray
        Input matrix of the inputs at the step's end (nz, 5).
    Gb : np.ndarray
        Rows of ``G1`` for the base displacement and velocity, nonlinear-force columns (6, 3).
    """

    dt: float
    nq: int
    Phi: np.ndarray   # (nz, nz)
    G0: np.ndarray    # (nz, 5)
    G1: np.ndarray    # (nz, 5)
    Gb: np.ndarray    # (6, 3): rows of G1 for the base displacement and velocity, nonlinear-force columns


class Bearings(NamedTuple):
    """The isolation layer's bearings with a hysteretic force, packed
    (:meth:`benchmark.simulator.isolation.configurations.IsolationLayer.pack`). Linear bearings are left
    out: their force is all in the plant's exact linear step.

    Parameters
    ----------
    index : np.ndarray
        Position of each bearing in the layer (the output's bearing axis), int64 (nb,).
    xy : np.ndarray
        Plan positions (nb, 2) [m].
    type_id : np.ndarray
        Bearing type ids, int64 (nb,).
    params : np.ndarray
        Packed parameters (nb, MAX_PARAMS).
    state : np.ndarray
        States (nb, MAX_STATES), advanced in place.
    form : np.ndarray
        The lock-step form of each bearing (LOCKSTEP_FORM, nb)
        (:func:`benchmark.simulator.isolation.registry.lockstep_forms`).
    """

    index: np.ndarray    # (nb,) int64: position of each in the layer (the output's bearing axis)
    xy: np.ndarray       # (nb, 2) [m]
    type_id: np.ndarray  # (nb,) int64
    params: np.ndarray   # (nb, MAX_PARAMS)
    state: np.ndarray    # (nb, MAX_STATES), advanced in place
    form: np.ndarray     # (LOCKSTEP_FORM, nb): the RK4 update's lock-step coefficients


class Devices(NamedTuple):
    """The devices, packed (:meth:`benchmark.simulator.devices.DeviceLayout.pack`).

    Parameters
    ----------
    influence : np.ndarray
        Stroke per base motion (x [m], y [m], θ [rad]) of each device (nd, 3).
    model_id : np.ndarray
        Model ids, int64 (nd,).
    params : np.ndarray
        Packed parameters (nd, n_params).
    state : np.ndarray
        States (nd, n_states), advanced in place.
    """

    influence: np.ndarray  # (nd, 3): stroke per base (x [m], y [m], θ [rad])
    model_id: np.ndarray   # (nd,) int64
    params: np.ndarray     # (nd, n_params)
    state: np.ndarray      # (nd, n_states), advanced in place


class Sensors(NamedTuple):
    """What forms the measurement vector (:mod:`benchmark.simulator.sensors`).

    Parameters
    ----------
    C_acc : np.ndarray
        Acceleration rows of the measurement on the state (n_acc, nz).
    D_acc_g : np.ndarray
        Acceleration rows on the generalised nonlinear forces (n_acc, 3).
    D_acc_ag : np.ndarray
        Acceleration rows on the ground acceleration (n_acc, 2).
    noise : np.ndarray
        Noise of every control step (n_control, n_meas), added before clipping (SI).
    ranges : np.ndarray
        Sensor ranges (n_meas,): measurements clipped to ±range.
    layout : MeasurementLayout
        The measurement vector's layout.
    """

    C_acc: np.ndarray       # (n_acc, nz)
    D_acc_g: np.ndarray     # (n_acc, 3)
    D_acc_ag: np.ndarray    # (n_acc, 2)
    noise: np.ndarray       # (n_control, n_meas), added before clipping
    ranges: np.ndarray      # (n_meas,) clip to +-range
    layout: MeasurementLayout


class Control(NamedTuple):
    """The controller seen by the kernel (:func:`controllers.compiled.controller_update`).

    Parameters
    ----------
    mode : int
        0 no controller or voltages held, 1 compiled controller, 2 voltages set by the caller between calls.
    ratio : int
        Record steps per control step.
    dt : float
        Control step [s].
    Ac : np.ndarray
        Compiled controller's state matrix.
    Bc : np.ndarray
        Compiled controller's input matrix (measurements).
    Cc : np.ndarray
        Compiled controller's output matrix (desired forces).
    Dc : np.ndarray
        Compiled controller's feedthrough.
    law_id : int
        Voltage law id (:mod:`controllers.compiled`).
    law_params : np.ndarray
        Parameters of the voltage law (e.g. dead band [N]).
    v_max : np.ndarray
        Largest voltage per device [V].
    slew_rate : np.ndarray
        Largest voltage rate per device [V/s].
    xc : np.ndarray
        Controller state, updated in place.
    voltage : np.ndarray
        Commanded voltages [V], updated in place.
    """

    mode: int               # 0 none/held, 1 compiled, 2 set by the caller between calls
    ratio: int              # record steps per control step
    dt: float               # control step [s]
    Ac: np.ndarray
    Bc: np.ndarray
    Cc: np.ndarray
    Dc: np.ndarray
    law_id: int
    law_params: np.ndarray
    v_max: np.ndarray
    slew_rate: np.ndarray
    xc: np.ndarray          # controller state, in place
    voltage: np.ndarray     # commanded voltages, in place


class Settings(NamedTuple):
    """Iteration and output settings of one run.

    Parameters
    ----------
    fp_tol : float
        Tolerance of the fixed-point (or Newton) iteration of each step.
    max_iter : int
        Iteration cap per step.
    blowup_limit : float
        Base displacement [m] beyond which the run is stopped as diverged.
    record_bearings : bool
        Keep the per-bearing hysteretic forces.
    record_states : bool
        Keep the per-bearing hysteretic states.
    newton : bool
        Newton iteration on the base's 3 DOF (else plain fixed-point iteration).
    integrator : int
        The bearings' update: 0 RK4 sub-steps, 1 the closed-form chord update
        (:data:`benchmark.simulator.stepping.INTEGRATORS`).
    """

    fp_tol: float
    max_iter: int
    blowup_limit: float     # [m]
    record_bearings: bool   # keep the per-bearing hysteretic forces
    record_states: bool     # keep the per-bearing hysteretic states
    newton: bool            # Newton on the base's 3 DOF (else plain fixed-point iteration)
    integrator: int = 0     # 0 explicit RK4 sub-steps, 1 implicit element updates (stepping.INTEGRATORS)


class Outputs(NamedTuple):
    """Histories the kernel writes (time along axis 0, ``n`` record samples).

    Parameters
    ----------
    z : np.ndarray
        State history (n, nz).
    gb : np.ndarray
        Generalised hysteretic bearing force at the base centre of mass (n, 3) [N, N, N·m].
    gd : np.ndarray
        Generalised device force (n, 3) [N, N, N·m].
    fb : np.ndarray
        Hysteretic force of each bearing (n or 1, nb, 2) [N].
    bstate : np.ndarray
        Bearing states (n or 1, nb, n_states).
    fd : np.ndarray
        Device forces (n, nd) [N].
    v : np.ndarray
        Voltages (n, nd) [V].
    meas : np.ndarray
        Measurement vector at each control step (n_control, n_meas), SI.
    desired : np.ndarray
        Desired device forces at each control step (n_control, nd) [N].
    iters : np.ndarray
        Iterations per step, int64 (n,).
    """

    z: np.ndarray         # (n, nz) state
    gb: np.ndarray        # (n, 3) generalised hysteretic bearing force at the base centre of mass
    gd: np.ndarray        # (n, 3) generalised device force
    fb: np.ndarray        # (n or 1, nb, 2) hysteretic force of each bearing
    bstate: np.ndarray    # (n or 1, nb, n_states)
    fd: np.ndarray        # (n, nd) device forces
    v: np.ndarray         # (n, nd) voltages
    meas: np.ndarray      # (n_control, n_meas)
    desired: np.ndarray   # (n_control, nd)
    iters: np.ndarray     # (n,) int64 iterations per step


def make_outputs(n: int, nz: int, nb: int, n_bstates: int, nd: int, n_control: int, n_meas: int,
                 record_bearings: bool, record_states: bool) -> Outputs:
    """Zeroed output arrays (per-bearing histories of one sample only when not kept).

    Parameters
    ----------
    n : int
        Number of record samples.
    nz : int
        State size.
    nb : int
        Number of bearings with a hysteretic force.
    n_bstates : int
        States per bearing.
    nd : int
        Number of devices.
    n_control : int
        Number of control steps.
    n_meas : int
        Length of the measurement vector.
    record_bearings : bool
        Keep the per-bearing forces at every sample.
    record_states : bool
        Keep the per-bearing states at every sample.
    """
    return Outputs(z=np.zeros((n, nz)), gb=np.zeros((n, 3)), gd=np.zeros((n, 3)),
                   fb=np.zeros((n if record_bearings else 1, nb, 2)),
                   bstate=np.zeros((n if record_states else 1, nb, n_bstates)),
                   fd=np.zeros((n, nd)), v=np.zeros((n, nd)), meas=np.zeros((n_control, n_meas)),
                   desired=np.full((n_control, nd), np.nan), iters=np.zeros(n, dtype=np.int64))


class KernelRun(NamedTuple):
    """Everything one kernel run needs, packed from a building and a controller by :func:`pack_run`.

    Parameters
    ----------
    bearings, devices, sensors, control, settings : Bearings, Devices, Sensors, Control, Settings
        The kernel's arguments.
    isolation : IsolationLayer
        The isolation layer as run (sub-step tolerance applied).
    packed : object
        Its packed form (``IsolationLayer.pack()``), for the result.
    bearing_state0 : numpy.ndarray
        (n_bearings, n_states) initial hysteretic states of every bearing.
    n_bearings : int
        Bearings of the layer.
    session : controllers.base.ControllerSession or None
        The controller's session; None without devices.
    n_control, n_meas : int
        Control steps of the run and length of the measurement vector.
    """

    bearings: Bearings
    devices: Devices
    sensors: Sensors
    control: Control
    settings: Settings
    isolation: Any          # the isolation layer as run (sub-step tolerance applied)
    packed: Any             # its packed form (``IsolationLayer.pack()``), for the result
    bearing_state0: np.ndarray  # (n_bearings, n_states) initial hysteretic states of every bearing
    n_bearings: int
    session: Any            # the ControllerSession, or None without devices
    n_control: int
    n_meas: int


def _f64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def pack_run(building: Any, record: Any, plant_extra: dict, n: int, dt: float, ratio: int, controller: Any, *,
             substep_tolerance: float | None, noise: Any, seed: int | None, slew_rate: float | None,
             info: dict | None, fixed_point_tolerance: float, max_iterations: int, blowup_limit: float,
             bearing_histories: bool, record_states: bool, newton: bool, integrator: int = 0) -> KernelRun:
    """Pack ``building`` and a resolved ``controller`` into the kernel's arguments (SI).

    Parameters
    ----------
    building : Building
    record : records.Record
        Only its name goes to the controller's context.
    plant_extra : dict
        The sensor rows ``C_acc``, ``D_acc_g``, ``D_acc_ag`` of the discretised plant.
    n : int
        Samples of the run.
    dt : float
        Integration step [s].
    ratio : int
        Integration steps per control step.
    controller : controller object or None
        Already resolved (:func:`benchmark.simulator.simulation.simulate`); ``None``: no devices.
    substep_tolerance, noise, seed, slew_rate, info, fixed_point_tolerance, max_iterations,
    blowup_limit, bearing_histories, record_states, newton
        As in :func:`benchmark.simulator.simulation.simulate` (already checked there).
    integrator : int
        The bearings' update (:data:`benchmark.simulator.stepping.INTEGRATORS`: 0 RK4 sub-steps,
        1 the closed-form update).

    Returns
    -------
    KernelRun

    Raises
    ------
    InputError
        A controller without devices, or a compiled controller designed for another control step
        or device count.
    """
    isolation = building.isolation
    floors = building.superstructure.n_floors
    if substep_tolerance is not None:
        isolation = isolation.with_substep_tolerance(substep_tolerance)
    packed = isolation.pack()
    b_type = np.ascontiguousarray(packed.type_ids, dtype=np.int64)
    b_params = np.ascontiguousarray(packed.params, dtype=np.float64)
    b_state = np.ascontiguousarray(packed.states, dtype=np.float64).copy()
    b_xy = np.ascontiguousarray(building.superstructure.bearing_xy, dtype=np.float64)

    devices = building.devices if controller is not None else None
    if controller is not None and devices is None:
        raise InputError("simulate: a controller was given but the building has no devices "
                         "(Building.default(devices='default') or building.with_devices(...))")
    session = None
    compiled = None
    if devices is not None:
        if substep_tolerance is not None:
            devices = devices.with_substep_tolerance(substep_tolerance)
        d_model, d_params, d_state, _ = devices.pack()
        d_infl = np.ascontiguousarray(devices.influence())

        context = control_context(building, control_step=ratio * dt, slew_rate=slew_rate,
                                  info=dict(info or {}, record=getattr(record, "name", "")))
        session = ControllerSession(controller, context)
        compiled = session.compiled
        if compiled is not None:
            if abs(compiled.control_step - ratio * dt) > 1e-9 * ratio * dt:
                raise InputError(f"controller {session.name!r} was designed for a control step of "
                                 f"{compiled.control_step:g} s, the run uses {ratio * dt:g} s")
            if compiled.n_devices != d_infl.shape[0] or compiled.n_meas != n_measurements(d_infl.shape[0], floors):
                raise InputError(f"controller {session.name!r} expects {compiled.n_devices} devices and "
                                 f"{compiled.n_meas} measurements; the building has {d_infl.shape[0]} "
                                 f"devices ({n_measurements(d_infl.shape[0], floors)} measurements)")
    else:
        d_model = np.zeros(0, dtype=np.int64)
        d_params = np.zeros((0, 1))
        d_state = np.zeros((0, 1))
        d_infl = np.zeros((0, 3))
    nd = d_infl.shape[0]
    n_meas = n_measurements(nd, floors)
    n_control = (n - 1) // ratio + 1 if nd else 0
    noise_arr, meas_range = noise_samples(noise if nd else None, n_control, nd, seed, n_floors=floors)

    if compiled is not None:
        ctrl_mode = 1
        Ac, Bc, Cc, Dc = compiled.Ac, compiled.Bc, compiled.Cc, compiled.Dc
        law_id, law_params = compiled.law_id, compiled.law_params
        v_max, slew = compiled.v_max, compiled.slew_rate
        xc, voltage = compiled.initial_state()
    else:
        ctrl_mode = 2 if session is not None else 0
        Ac = np.zeros((0, 0))
        Bc = np.zeros((0, n_meas))
        Cc = np.zeros((nd, 0))
        Dc = np.zeros((nd, n_meas))
        law_id = 0
        law_params = np.zeros(nd)
        v_max = np.zeros(nd) if devices is None else devices.voltage_max
        slew = np.full(nd, np.inf)
        xc = np.zeros(0)
        voltage = np.zeros(nd)

    control = Control(mode=int(ctrl_mode), ratio=int(ratio), dt=float(ratio * dt), Ac=_f64(Ac),
                      Bc=_f64(Bc), Cc=_f64(Cc), Dc=_f64(Dc), law_id=int(law_id),
                      law_params=_f64(law_params), v_max=_f64(v_max), slew_rate=_f64(slew),
                      xc=_f64(xc).copy(), voltage=_f64(voltage).copy())
    # Linear bearings have no hysteretic force: all of theirs is in the plant's exact step, so
    # the kernel gets only the others (a linear run's kernel is then the bare linear loop).
    hysteretic = np.flatnonzero(b_type != LinearBearing.kernel)
    bearings = Bearings(index=hysteretic.astype(np.int64),
                        xy=np.ascontiguousarray(b_xy[hysteretic]),
                        type_id=np.ascontiguousarray(b_type[hysteretic]),
                        params=np.ascontiguousarray(b_params[hysteretic]),
                        state=np.ascontiguousarray(b_state[hysteretic]),
                        form=lockstep_forms(b_type[hysteretic], b_params[hysteretic]))
    dev = Devices(influence=_f64(d_infl), model_id=np.ascontiguousarray(d_model, dtype=np.int64),
                  params=_f64(d_params), state=_f64(d_state))
    sensors = Sensors(C_acc=plant_extra["C_acc"], D_acc_g=plant_extra["D_acc_g"],
                      D_acc_ag=plant_extra["D_acc_ag"], noise=_f64(noise_arr), ranges=_f64(meas_range),
                      layout=measurement_layout(nd, floors))
    settings = Settings(fp_tol=float(fixed_point_tolerance), max_iter=int(max_iterations),
                        blowup_limit=float(blowup_limit), record_bearings=bool(bearing_histories),
                        record_states=bool(bearing_histories and record_states),
                        newton=bool(newton), integrator=int(integrator))
    return KernelRun(bearings=bearings, devices=dev, sensors=sensors, control=control, settings=settings,
                     isolation=isolation, packed=packed, bearing_state0=b_state, n_bearings=int(b_xy.shape[0]),
                     session=session, n_control=int(n_control), n_meas=int(n_meas))
