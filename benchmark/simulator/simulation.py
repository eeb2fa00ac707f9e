"""Run the building under a ground motion: :func:`simulate` -> :class:`SimulationResult`.

:func:`simulate` reads as validate → build → step → result: it checks its inputs (once; the
CLI only parses), builds the kernel's arguments (the exactly discretised plant, cached per
building and step, and :func:`benchmark.simulator.kernel_args.pack_run`: packed bearings and
devices, measurement rows, noise, compiled controller), runs the numba kernel of
:mod:`benchmark.simulator.stepping`, and hands the state history to
:func:`benchmark.simulator.results.build_result`, which derives every output of
docs/ARCHITECTURE.md (:class:`~benchmark.simulator.results.SimulationResult`). ``controller=None`` is the uncontrolled reference run: no devices at all.
A controller with a compiled form (every built-in) runs inside the kernel; any other object
with ``step(measurements) -> voltages`` is called from Python once per control step, the
kernel advancing one control step per call (slower, same results).

All quantities are SI (m, s, N, kg, rad, V); time along axis 0, one sample per integration
step. The integration step belongs to the simulator, not to the record: the benchmark's
0.005 s by default (finer for a finer record, and halved while the fixed point of the nonlinear
forces does not converge); the ground motion is interpolated onto it
(:func:`choose_integration_step`).
"""

from __future__ import annotations

import hashlib
import time as _time
from typing import Any

import numpy as np

from benchmark.foundation.cache import Cache
from benchmark.foundation.errors import InputError, NumericalError
from benchmark.simulator.linear_model import state_space_matrices
from benchmark.simulator.stepping import discretize_foh
from benchmark.simulator import stepping
from benchmark.simulator.stepping import STATUS_MESSAGES, STATUS_NOT_CONVERGED, STATUS_CONTROLLER
from controllers.registry import get_controller
from benchmark.simulator import kernel_args
from benchmark.simulator.peaks import PEAK_RECORD_KEYS, peaks_of
from benchmark.simulator.results import ENERGY_NAMES, SimulationResult, build_result
from benchmark.simulator.isolation.configurations import check_substep_tolerance
from benchmark.foundation.kernel_cache import ensure_fresh_once
from benchmark.simulator.authority import controller_authority_warnings
from records.resample import interpolate_onto

__all__ = ["SimulationResult", "simulate", "reduction_error", "ENERGY_NAMES", "choose_integration_step",
           "check_control_step", "CONTROL_STEP_RANGE", "MAX_INTEGRATION_STEPS",
           "DEFAULT_INTEGRATION_STEP", "DEFAULT_MAX_HALVINGS", "slow_controller_note",
           "SLOW_CONTROLLER_SHARE", "SLOW_CONTROLLER_SECONDS"]

#: The building's integration step [s]: the benchmark's 0.005 s (Narasimhan et al. 2006). A
#: record at another step is interpolated onto it (:func:`choose_integration_step`).
DEFAULT_INTEGRATION_STEP = 0.005
#: Times a run whose fixed point does not converge is started again with half the step.
DEFAULT_MAX_HALVINGS = 3
_DEFAULT_BLOWUP = 50.0  # m


# --------------------------------------------------------------------------- helpers

def _ground_acceleration(record: Any) -> np.ndarray:
    acc = getattr(record, "acceleration", None)
    dt = getattr(record, "dt", None)
    if acc is None or dt is None:
        raise InputError(f"record: {type(record).__name__} has no 'acceleration' and 'dt'; "
                         "expected a records.Record")
    acc = np.asarray(acc, dtype=float)
    if acc.ndim == 1:
        acc = acc[:, None]
    if acc.ndim != 2 or acc.shape[1] not in (1, 2):
        raise InputError(f"record {getattr(record, 'name', '?')!r}: acceleration has shape {acc.shape}; "
                         "expected (n, 1) (applied along x) or (n, 2) (x, y)")
    if acc.shape[0] < 2:
        raise InputError(f"record {getattr(record, 'name', '?')!r}: needs at least 2 samples")
    if not np.all(np.isfinite(acc)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(acc), axis=1))[0])
        raise InputError(f"record {getattr(record, 'name', '?')!r}: sample {bad} is NaN or infinite")
    ag = np.zeros((acc.shape[0], 2))
    ag[:, :acc.shape[1]] = acc
    return np.ascontiguousarray(ag)


#: Control steps accepted [s]: a controller updated slower than 1 s does not control an
#: earthquake response; one faster than 0.1 ms asks for more steps than any sensor chain gives.
CONTROL_STEP_RANGE = (1e-4, 1.0)
#: Most integration steps of one run: the histories cost about 6 kB per step (a 30-s record at
#: 1e-4 s: 0.3 million steps, 1.9 GB), so a million is about 6 GB.
MAX_INTEGRATION_STEPS = 1_000_000


def check_control_step(control_step: Any) -> float:
    """``control_step`` [s] as a float, checked once for every API that takes one
    (:func:`simulate`, :func:`benchmark.simulator.case.run_case`, ``compare``).

    Parameters
    ----------
    control_step : float
        The control step [s].

    Raises
    ------
    InputError
        A step that is not a positive, finite number of seconds (the message names the CLI's
        ``--control-step`` and the keyword ``control_step``).
    """
    if isinstance(control_step, bool) or not (isinstance(control_step, (int, float, np.floating))
                                              and np.isfinite(control_step) and control_step > 0):
        raise InputError(f"--control-step {control_step!r} (control_step): expected a positive time in seconds")
    lo, hi = CONTROL_STEP_RANGE
    if not lo <= control_step <= hi:
        # 1e-5 s asks for millions of steps and gigabytes of histories; 5 s updates a building's
        # dampers six times in a 30-s record
        raise InputError(f"--control-step {control_step:g} s (control_step): a semi-active controller of a "
                         f"building updates every {lo:g}-{hi:g} s (the benchmark's: 0.005 s)")
    return float(control_step)


def choose_integration_step(control_step: float, record_dt: float,
                            max_step: float | None = None) -> tuple[float, int]:
    """The integration step [s] and the number of integration steps per control step.

    The step is the longest one that divides the control step into whole steps and is no
    longer than ``max_step`` (default :data:`DEFAULT_INTEGRATION_STEP`, the benchmark's 0.005 s)
    nor than the record's own step (a finer record keeps its detail):
    ``h = control_step / k``, ``k`` the smallest whole number with
    ``h <= min(max_step, record_dt)``. A step equal to the record's (to 1e-9) is the record's
    exactly, so the benchmark's records at 0.005 s run on their own samples.

    Parameters
    ----------
    control_step : float
        Control sample time [s] (without a controller: the grid the results share with the
        controlled run).
    record_dt : float
        The record's sampling step [s].
    max_step : float, optional
        Longest integration step allowed [s].

    Returns
    -------
    (h, k) : (float, int)

    Raises
    ------
    InputError
        A control step that is not a positive time.
    """
    if max_step is None:
        max_step = DEFAULT_INTEGRATION_STEP
    control_step = check_control_step(control_step)
    limit = min(float(max_step), float(record_dt))
    k = max(1, int(np.ceil(control_step / limit * (1 - 1e-9))))
    h = control_step / k
    if abs(h - record_dt) <= 1e-9 * record_dt:
        h = float(record_dt)
    return float(h), k


#: The FOH-discretised plant of a building at an integration step (:func:`_discrete_system`),
#: keyed on the superstructure's matrices, the bearings' linear parts and the step.
DISCRETE_SYSTEMS = Cache("simulator.discrete_systems", size=16)
#: Digest of a superstructure's matrices by object (hashing costs about 4 ms a run).
SUPERSTRUCTURE_DIGESTS = Cache("simulator.superstructure_digests", size=16)


def _superstructure_digest(sup) -> str:
    """Hash of the superstructure's matrices, memoised per object (hashing costs ≈ 4 ms a run).

    Keyed on the matrices themselves, not the file name: a modified superstructure
    (``dataclasses.replace(sup, K=...)``) must not get the discretisation of the original. The
    superstructure is a frozen dataclass, so one object keeps one digest; the memo holds the
    object itself so that its ``id`` cannot be reused while the entry lives.
    """
    hit = SUPERSTRUCTURE_DIGESTS.get(id(sup))
    if hit is not None and hit[0] is sup:
        return hit[1]
    digest = hashlib.sha1()
    for arr in (sup.M, sup.K, sup.C, sup.R, sup.basis, np.array([sup.base_mass, sup.base_inertia])):
        a = np.ascontiguousarray(arr, dtype=np.float64)
        digest.update(str(a.shape).encode())
        digest.update(a.tobytes())
    SUPERSTRUCTURE_DIGESTS.put(id(sup), (sup, digest.hexdigest()))
    return SUPERSTRUCTURE_DIGESTS.get(id(sup))[1]


def _discrete_system(building, dt: float):
    """Continuous matrices with the bearings' linear parts, their FOH discretisation as the
    kernel's :class:`benchmark.simulator.kernel_args.Plant`, and the contiguous sensor and energy matrices
    (cached per building and record step)."""

    sup = building.superstructure
    Kb, Cb = building.isolation_linear_matrices()
    key = (_superstructure_digest(sup), Kb.tobytes(), Cb.tobytes(), float(dt))
    hit = DISCRETE_SYSTEMS.get(key)
    if hit is not None:
        return hit
    mats = state_space_matrices(sup, Kb, Cb)
    B = np.hstack([mats["B_ag"], mats["B_g"]])
    Phi, G0, G1 = discretize_foh(mats["A"], B, dt)
    nq = sup.n_q
    nv = nq + 3
    base_rows = np.r_[nq:nv, nv + nq:2 * nv]
    plant = kernel_args.Plant(dt=float(dt), nq=int(nq), Phi=Phi, G0=G0, G1=G1,
                              Gb=np.ascontiguousarray(G1[base_rows, 2:5]))
    extra = {name: np.ascontiguousarray(mats[name], dtype=np.float64)
             for name in ("C_acc", "D_acc_g", "D_acc_ag", "Mg", "momentum")}
    extra["Kq"] = np.ascontiguousarray(mats["Kg"][:nq, :nq])
    extra["Cq"] = np.ascontiguousarray(mats["Cg"][:nq, :nq])
    return DISCRETE_SYSTEMS.put(key, (mats, Kb, Cb, plant, extra))


def _resolve_controller(controller: Any):
    if isinstance(controller, str):
        return get_controller(controller)
    return controller


# --------------------------------------------------------------------------- simulate

def simulate(building, record, controller: Any = None, control_step: float = 0.005,
             substep_tolerance: float | None = None, noise: Any = None, seed: int | None = None,
             fixed_point_tolerance: float = 1e-6, max_iterations: int = 100,
             record_states: bool = True, blowup_limit: float = _DEFAULT_BLOWUP,
             slew_rate: Any = np.inf, info: dict | None = None,
             bearing_histories: bool = True, newton: bool | None = None, integration_step: float | None = None,
             max_halvings: int = DEFAULT_MAX_HALVINGS, integrator: str = "rk4") -> SimulationResult:
    """Simulate the building under a record.

    Parameters
    ----------
    building : benchmark.simulator.building.Building
        Superstructure (full or reduced), isolation layer, device layout.
    record : records.Record
        Ground acceleration [m/s²], ``(n, 2)`` for x and y (a single component acts along x),
        at any step ``record.dt``: it is interpolated linearly onto the integration step
        (:func:`choose_integration_step`; the record's own samples when the steps agree).
    controller : None, str or controller object
        ``None``: no devices (the uncontrolled reference). A name of
        :mod:`controllers.registry`, or an object with ``step(measurements) -> voltages``
        (``reset(context)`` and ``compiled()`` optional, see :mod:`controllers.base`).
    control_step : float
        Control sample time [s], any positive time; voltages are held between. The integration
        step divides it (:func:`choose_integration_step`). Without a controller it sets only
        the time grid (the uncontrolled reference of a controlled run shares its grid).
    substep_tolerance : float, optional
        Replace the sub-step tolerance of every nonlinear bearing and device (smaller = more
        sub-steps, more accurate); ``None`` keeps each model's own value.
    noise : None, array or noise object
        Measurement noise (see :func:`benchmark.simulator.sensors.noise_samples`).
    seed : int, optional
        Seed of the noise generator.
    fixed_point_tolerance : float
        Relative tolerance of the nonlinear-force iteration per step (see :mod:`benchmark.simulator.stepping`).
    max_iterations : int
        Iterations allowed per step before a :class:`NumericalError`.
    record_states : bool
        Keep the bearings' hysteretic states (``bearing_state``; only with ``bearing_histories``).
    blowup_limit : float
        Base displacement [m] beyond which the run stops with a :class:`NumericalError`.
    slew_rate : float or array
        Actuator voltage slew limit [V/s] passed to the controller context.
    info : dict, optional
        Extra information stored in ``result.info`` (e.g. ``orientation``).
    bearing_histories : bool
        Keep the per-bearing histories (``bearing_force`` and, with ``record_states``,
        ``bearing_state``; 92 bearings x 2 components per sample, about 9 MB per 30-s run each).
        ``False`` leaves both ``None``: the runs of ``sbib run``, ``compare``, ensembles and the
        identification study need only the resultant forces at the base.
    newton : bool
        Solve each step's coupling of the linear part and the nonlinear forces by Newton's
        method on the base's three degrees of freedom with the bearings' and devices' tangents,
        or by fixed-point iteration (default); both stop on the same tolerance
        (:mod:`benchmark.simulator.stepping`). Newton takes fewer iterations (2.03 instead of 2.39 per
        step on 30 s of Kobe with clipped-optimal control) but, with the tangents' cost, was
        9-15 % slower when measured (docs/performance.md). ``None`` (default): Newton with the
        closed-form integrator (its tangents come with the update), fixed point with RK4.
    integrator : {"rk4", "closed-form", "rk4-per-bearing"}
        How the bearings' Park–Wen states advance over a step. ``"rk4"`` (default): RK4
        sub-steps along the step's cubic Hermite path, as many as the sub-step tolerance needs
        (the path checked against ``solve_ivp`` by the oracle tests, kept as the reference),
        the bearings' sub-steps taken in lock-step (vectorised across bearings);
        ``"rk4-per-bearing"``: the same update one bearing after another (equal to rounding).
        ``"closed-form"``: the model's exact flow along the chord of each monotone piece of the
        path (:func:`benchmark.simulator.isolation.park_wen.park_wen_chord`: no sub-steps, no
        iteration, unconditionally stable, with its tangent); exact for straight-line motion,
        off by about half the path's turning angle per step on curved biaxial paths
        (docs/performance.md gives the measured differences). Devices are unaffected.
    integration_step : float, optional
        Longest integration step [s] (default :data:`DEFAULT_INTEGRATION_STEP`, 0.005 s); the
        step used also divides the control step and is no longer than the record's step.
    max_halvings : int
        When the fixed-point iteration of a step does not converge, the whole run is started
        again with half the integration step, at most this many times (default 3), before a
        :class:`NumericalError` whose hint names what helps.

    Returns
    -------
    SimulationResult
        Histories on the grid ``t = k h`` of the integration step ``h`` actually used:
        ``info["integration_step"]`` [s], with ``info["record_step"]`` (the record's own),
        ``info["integration_step_requested"]``, ``info["integration_step_halvings"]`` and
        ``info["notes"]`` (lines for the user: interpolation, halvings, a controller that
        cannot act on the devices, :func:`benchmark.simulator.authority.controller_authority_warnings`).

    Raises
    ------
    InputError
        Bad record, control step or controller output.
    NumericalError
        NaN, blow-up or a fixed point that does not converge even at the smallest step tried;
        carries time, state and a hint.
    """
    if integrator not in stepping.INTEGRATORS:
        raise InputError(f"integrator {integrator!r} unknown: expected one of {', '.join(stepping.INTEGRATORS)}")
    ensure_fresh_once()  # numba caches consistent with the kernels they call (kernel_cache)

    t_start = _time.perf_counter()
    ag_record = _ground_acceleration(record)
    record_dt = float(record.dt)
    name = getattr(record, "name", "?")
    if not (np.isfinite(record_dt) and record_dt > 0):
        raise InputError(f"record {name!r}: dt = {record_dt!r}; expected a positive step in s")
    max_step = DEFAULT_INTEGRATION_STEP if integration_step is None else integration_step
    if not (isinstance(max_step, (int, float)) and np.isfinite(max_step) and max_step > 0):
        raise InputError(f"--integration-step {integration_step!r}: expected a positive number of seconds, "
                         "e.g. 0.0025 (integration_step)")
    if int(max_halvings) != max_halvings or max_halvings < 0:
        raise InputError(f"max_halvings: expected a whole number >= 0, got {max_halvings!r}")
    dt, ratio = choose_integration_step(control_step, record_dt, float(max_step))
    steps = (ag_record.shape[0] - 1) * record_dt / dt
    if steps > MAX_INTEGRATION_STEPS:
        raise InputError(f"record {name!r}: {(ag_record.shape[0] - 1) * record_dt:g} s at an integration step of "
                         f"{dt:g} s is {steps:.3g} steps, more than the {MAX_INTEGRATION_STEPS:.0e} a run holds in "
                         "memory (about 6 kB each): a longer --integration-step or --control-step, or a shorter "
                         "record")
    if (ag_record.shape[0] - 1) * record_dt < ratio * dt * (1 - 1e-9):
        raise InputError(f"record {name!r}: {ag_record.shape[0]} samples ({(ag_record.shape[0] - 1) * record_dt:g} s) "
                         f"is shorter than one control step ({ratio * dt:g} s)")
    if substep_tolerance is not None:
        substep_tolerance = check_substep_tolerance(substep_tolerance)
    if not (np.isfinite(fixed_point_tolerance) and fixed_point_tolerance > 0):
        raise InputError(f"fixed_point_tolerance: expected > 0, got {fixed_point_tolerance!r}")
    if int(max_iterations) < 1:
        raise InputError(f"max_iterations: expected >= 1, got {max_iterations!r}")
    controller = _resolve_controller(controller)
    notes: list[str] = []
    if integration_step is not None and dt < float(integration_step) * (1 - 1e-9):
        why = (f"the record's own step ({record_dt:g} s) is finer and is kept" if dt <= record_dt * (1 + 1e-9)
               else f"the step divides the control step ({ratio * dt:g} s) into whole steps")
        notes.append(f"integration step {dt:g} s, not the {float(integration_step):g} s asked: {why}")
    if controller is not None and building.devices is not None:
        notes.extend(controller_authority_warnings(building.devices, getattr(controller, "name", "")
                                                   or type(controller).__name__))
    for halving in range(int(max_halvings) + 1):
        ag = ag_record if dt == record_dt else interpolate_onto(ag_record, record_dt, dt)
        try:
            result = _simulate_once(building, record, ag, dt, ratio, controller, substep_tolerance, noise, seed,
                                    fixed_point_tolerance, max_iterations, record_states, blowup_limit, slew_rate,
                                    info, bearing_histories, newton, integrator)
            break
        except _NotConverged as exc:
            if halving == int(max_halvings):
                raise exc.error(halving) from None
            notes.append(f"the fixed-point iteration of the nonlinear forces did not converge at t = "
                         f"{exc.error(0).time:.6g} s with the integration step {dt:g} s; ran again with "
                         f"{dt / 2:g} s")
            dt, ratio = dt / 2, ratio * 2
    if dt != record_dt:
        notes.insert(0, f"record {name}: sampled at {record_dt:g} s; its ground motion is interpolated "
                        f"linearly onto the integration step {dt:g} s (results are reported every {dt:g} s)")
    result.info["record_step"] = record_dt
    result.info["integration_step"] = dt
    result.info["integration_step_requested"] = float(max_step)
    result.info["integration_step_halvings"] = halving
    result.info["elapsed_s"] = _time.perf_counter() - t_start
    slow = slow_controller_note(getattr(controller, "name", "") or type(controller).__name__,
                                result.info["controller_s"], result.info["elapsed_s"],
                                result.info["controller_calls"])
    if slow is not None:
        notes.append(slow)
    result.info["notes"] = notes
    return result


class _NotConverged(Exception):
    """The kernel's fixed point did not converge: carries the :class:`NumericalError` to raise
    (through :meth:`error`) if no smaller step is tried."""

    def __init__(self, status, k, dt, z_out, nq, nv, session):
        super().__init__()
        self.failure = (status, k, dt, z_out, nq, nv, session)

    def error(self, halvings: int) -> NumericalError:
        return _numerical_error(*self.failure, halvings=halvings)


def _simulate_once(building, record, ag, dt, ratio, controller, substep_tolerance, noise, seed,
                   fixed_point_tolerance, max_iterations, record_states, blowup_limit, slew_rate, info,
                   bearing_histories, newton, integrator) -> SimulationResult:
    """One run at the integration step ``dt`` [s] with ``ratio`` steps per control step; ``ag``
    the ground acceleration on that grid. Raises :class:`_NotConverged` for a fixed point that
    does not converge, :class:`NumericalError` for the other failures."""
    t_start = _time.perf_counter()
    n = ag.shape[0]
    nq = building.superstructure.n_q
    nv = nq + 3
    nz = 2 * nv
    # build: the plant (cached per building and step), then bearings, devices and controller
    mats, Kb, Cb, plant, plant_extra = _discrete_system(building, dt)
    run = kernel_args.pack_run(building, record, plant_extra, n, dt, ratio, controller,
                               substep_tolerance=substep_tolerance, noise=noise, seed=seed, slew_rate=slew_rate,
                               info=info, fixed_point_tolerance=fixed_point_tolerance,
                               max_iterations=max_iterations, blowup_limit=blowup_limit,
                               bearing_histories=bearing_histories, record_states=record_states,
                               newton=bool(integrator == "closed-form" if newton is None else newton),
                               integrator=stepping.INTEGRATORS[integrator])
    bearings, dev, sensors, control, settings = run.bearings, run.devices, run.sensors, run.control, run.settings
    session, n_control, n_meas = run.session, run.n_control, run.n_meas
    nd = dev.influence.shape[0]

    # step
    out = kernel_args.make_outputs(n, nz, run.n_bearings, run.bearing_state0.shape[1], nd, n_control, n_meas,
                                   settings.record_bearings, settings.record_states)
    if settings.record_states:
        out.bstate[0] = run.bearing_state0
    stepping.initial_forces(dt, bearings, dev, control.voltage, out.fb[0], out.fd[0], out.gb[0], out.gd[0])

    controller_s = 0.0
    if control.mode == 2:
        y = np.empty(n_meas)
        g_tot = np.empty(3)
        status, k_fail = 0, 0
        for kc in range(n_control):
            k = kc * ratio
            g_tot[:] = out.gb[k] + out.gd[k]
            stepping.measure(nq, out.z[k], g_tot, ag[k], out.fd[k], dev, sensors, sensors.noise[kc], y)
            out.meas[kc] = y
            t_call = _time.perf_counter()
            control.voltage[:] = session.step(y.copy(), time=k * dt)
            controller_s += _time.perf_counter() - t_call
            k1 = min(k + ratio, n - 1)
            if k1 <= k:
                break
            status, k_fail = stepping.run_steps(k, k1, plant, ag, bearings, dev, sensors, control, settings, out)
            if status:
                break
    else:
        status, k_fail = stepping.run_steps(0, n - 1, plant, ag, bearings, dev, sensors, control, settings, out)
    if nd:
        out.v[n - 1] = control.voltage
    if status == STATUS_NOT_CONVERGED:
        raise _NotConverged(status, k_fail, dt, out.z, nq, nv, session)
    if status:
        raise _numerical_error(status, k_fail, dt, out.z, nq, nv, session)

    # result
    result = build_result(building, record, ag, dt, out, mats, Kb, Cb, plant_extra, run.packed, dev.influence,
                          run.isolation, session, dict(info or {}), bearing_histories=settings.record_bearings,
                          control_step=ratio * dt, substep_tolerance=substep_tolerance,
                          fixed_point_tolerance=fixed_point_tolerance, seed=seed, noise=noise)
    result.info["controller_s"] = controller_s  # in step() of a controller called from Python
    result.info["controller_calls"] = n_control if control.mode == 2 else 0
    result.info["elapsed_s"] = _time.perf_counter() - t_start
    return result


#: A controller called from Python that takes more of a run's wall time than this share, and at
#: least :data:`SLOW_CONTROLLER_SECONDS`, is named in the run's notes with its time per step.
SLOW_CONTROLLER_SHARE = 0.5
SLOW_CONTROLLER_SECONDS = 2.0


def slow_controller_note(name: str, controller_s: float, elapsed_s: float, n_calls: int) -> str | None:
    """The note for a controller called from Python that dominates a run's time, or None.

    A built-in controller runs inside the compiled loop; a user's class runs in Python once per
    control step, and a heavy ``step`` (a network, an optimisation) can then make a 30-s record
    take minutes with nothing said of why.

    Parameters
    ----------
    name : str
        The controller's name.
    controller_s, elapsed_s : float
        Wall time [s] inside the controller's ``step`` calls and of the whole run.
    n_calls : int
        Number of ``step`` calls (control steps).
    """
    if n_calls < 1 or controller_s < SLOW_CONTROLLER_SECONDS or controller_s < SLOW_CONTROLLER_SHARE * elapsed_s:
        return None
    return (f"controller {name!r} took {controller_s:.1f} s of the run's {elapsed_s:.1f} s "
            f"({1e3 * controller_s / n_calls:.3g} ms per control step, {n_calls} steps): its step() is "
            "what the run waits on (compiled controllers run inside the stepping loop: controllers/compiled.py)")


def _numerical_error(status, k, dt, z_out, nq, nv, session, halvings: int = 0) -> NumericalError:
    """The :class:`NumericalError` of a kernel failure at the end of step ``k`` (integration step
    ``dt`` [s], reached after ``halvings`` halvings of the requested one), with the base's state
    and a hint naming what helps."""
    z = z_out[k]
    state = {"u_b_x [m]": float(z[nq]), "u_b_y [m]": float(z[nq + 1]), "u_b_theta [rad]": float(z[nq + 2]),
             "v_b_x [m/s]": float(z[nv + nq]), "v_b_y [m/s]": float(z[nv + nq + 1])}
    if status == STATUS_NOT_CONVERGED:
        tried = f" (after {halvings} halvings of the step, down to {dt:g} s)" if halvings else f" (step {dt:g} s)"
        hint = (f"the bearings or devices are too stiff for the integration step{tried}; tighten the "
                "sub-step tolerance (--substep-tolerance 0.1, or substep_tolerance=0.1), give a smaller "
                "step (--integration-step, or integration_step=), allow more halvings (max_halvings=), or "
                "soften the bearing and device parameters")
    elif status == STATUS_CONTROLLER:
        hint = f"check the design of controller {getattr(session, 'name', '?')!r} (unstable estimator?)"
    else:
        hint = ("check the isolation and device parameters (a negative or zero stiffness?) and the "
                "controller; a bearing or damper whose hysteresis would need more than 200 000 "
                "sub-steps in one integration step also stops here: soften it or loosen substep_tolerance")
    return NumericalError(STATUS_MESSAGES.get(status, f"kernel status {status}"), time=(k + 1) * dt,
                          state=state, hint=hint)


# --------------------------------------------------------------------------- reduced order

def reduction_error(building, record, n_modes: int, **kwargs) -> dict:
    """Peak-response error of a reduced superstructure against the full one on a record.

    Parameters
    ----------
    building : Building
        The building (its superstructure is used in full and with ``n_modes`` modes).
    record : records.Record
    n_modes : int
        Modes kept.
    **kwargs
        Passed to :func:`simulate` (e.g. ``controller``).

    Returns
    -------
    dict
        ``n_modes``, ``mass_participation`` (x, y, θ kept by the first ``n_modes`` modes), and for
        each peak quantity (base displacement, base shear, structure shear, drift ratio, absolute
        floor acceleration) the full and reduced peaks and the relative error; ``elapsed_full_s``,
        ``elapsed_reduced_s``.
    """
    full = simulate(building.reduced(None), record, **kwargs)
    red = simulate(building.reduced(n_modes), record, **kwargs)
    kept = building.superstructure.mass_participation()[:n_modes].sum(axis=0)

    quantities = ("base_displacement", "base_shear", "structure_shear", "drift_ratio", "floor_acceleration")
    full_peaks, red_peaks = peaks_of(full), peaks_of(red)
    pf = {PEAK_RECORD_KEYS[q]: getattr(full_peaks, q) for q in quantities}
    pr = {PEAK_RECORD_KEYS[q]: getattr(red_peaks, q) for q in quantities}
    out = {"n_modes": int(n_modes), "mass_participation": {"x": float(kept[0]), "y": float(kept[1]),
                                                          "theta": float(kept[2])},
           "elapsed_full_s": full.info["elapsed_s"], "elapsed_reduced_s": red.info["elapsed_s"]}
    for k in pf:
        out[k] = {"full": pf[k], "reduced": pr[k], "relative_error": (pr[k] - pf[k]) / pf[k] if pf[k] else 0.0}
    return out
