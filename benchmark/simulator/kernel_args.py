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

Each is built once per run (:func:`benchmark.simulator.simulation.simulate`), and the plant and the
sensor rows once per building and record step (cached). Numba compiles the kernel once per
combination of field types, which are fixed here (float64 C-contiguous arrays, int64 ids).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from controllers.measurements import MeasurementLayout

__all__ = ["Plant", "Bearings", "Devices", "Sensors", "Control", "Settings", "Outputs", "make_outputs"]


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
    """

    index: np.ndarray    # (nb,) int64: position of each in the layer (the output's bearing axis)
    xy: np.ndarray       # (nb, 2) [m]
    type_id: np.ndarray  # (nb,) int64
    params: np.ndarray   # (nb, MAX_PARAMS)
    state: np.ndarray    # (nb, MAX_STATES), advanced in place


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
