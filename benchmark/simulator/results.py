"""HDF5 result files: every time history with its units, configuration and provenance attributes.

Layout of a file written by :func:`write_result` (format ``sbib-result``, version 1)::

    /                       attrs: format, format_version, provenance (package_version,
                            git_commit, created_utc, python, numpy, scipy, numba, platform),
                            record, orientation, isolation, controller, record_step_s and
                            integration_step_s (the histories' time step), info_json
                            (the run's whole ``info`` dict as JSON), isolation_json (the
                            isolation layer's description, when given), plus ``extra``
    /run/time_histories/<field>   one dataset per time history; attrs ``units``,
                                  ``description``, ``axes``
    /run/energy/<term>            energy terms (n,) [J]; attrs ``units``, ``description``
    /run/peaks                    attrs: the peaks of :func:`benchmark.simulator.peaks.peaks_of` (SI),
                                  each with ``<name>_units``
    /reference/...                the uncontrolled reference run, same layout (optional)
    /evaluation                   attrs J1..J9 (NaN where undefined) and ``<Jk>_description``,
                                  ``<Jk>_formula``, ``<Jk>_source`` (optional)

All quantities are SI (m, m/s, m/s², rad, N, N·m, V, J, s). Histories are float64 unless the file
was written with ``precision="single"`` (root attribute ``precision``): then every float history
and energy term except the time vector is float32 (7 significant digits, relative rounding
6e-8, far below any response quantity's meaning), which halves the file; ``sbib run`` writes
single precision unless ``--full-histories``. The file is written to a
temporary file in the destination directory and renamed when complete
(:func:`benchmark.foundation.atomic.atomic_path`), so an interrupted run never leaves a partial file.
:func:`read_result` reads a run back into a :class:`StoredResult` with the same field names as
:class:`SimulationResult`, so evaluation and plots work on it unchanged.

:class:`SimulationResult` itself, the run of :func:`benchmark.simulator.simulation.simulate`, lives
here too, with the histories derived from the kernel's state (:func:`derived_histories`,
:func:`build_result`): the driver steps, this module makes the result.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.simulator.peaks import PEAK_UNITS, Peaks, peaks_of
from benchmark.simulator.evaluation import J_DESCRIPTIONS
from benchmark.foundation.provenance import provenance
from benchmark.simulator.criteria import CRITERIA
from benchmark.simulator.stepping import energy_histories, total_bearing_forces

__all__ = ["SimulationResult", "ENERGY_NAMES", "build_result", "derived_histories",
           "write_result", "read_result", "read_evaluation", "StoredResult", "FIELD_UNITS",
           "FORMAT_NAME", "FORMAT_VERSION"]

#: the energy terms of a run, in the order of :func:`benchmark.simulator.stepping.energy_histories`
ENERGY_NAMES = ("input", "kinetic", "strain", "damping", "hysteretic", "device")


@dataclass(eq=False)
class SimulationResult:
    """Time histories of one run (SI; ``n`` samples at the integration step, time along axis 0).

    Parameters
    ----------
    state : ndarray (n, n_z) or None, optional
        Full state history of the kernel (kept on request: ``record_states``); None otherwise.
    ground_acceleration : ndarray (n, 2) or None, optional
        Ground acceleration (x, y) [m/s²] the run was driven by; None when not kept.

    Attributes
    ----------
    t : (n,) [s]
    base_displacement, base_velocity, base_acceleration : (n, 3)
        Base centre of mass relative to the ground (x, y [m, m/s, m/s²], θ [rad, rad/s, rad/s²]).
    base_acceleration_absolute : (n, 3)
        :math:`\\ddot u_b + \\ddot u_g`.
    floor_displacement : (n, 8, 3)
        Floors 1..8 relative to the base (x, y [m], θ [rad]).
    floor_acceleration_absolute : (n, 8, 3)
        :math:`\\ddot u_s + R(\\ddot u_b + \\ddot u_g)` [m/s², rad/s²].
    drift_ratio : (n, 8, 2)
        Inter-storey drift / storey height at the centres of mass (storey 1 = floor 1 − base).
    isolation_force : (n, 3)
        Bearing forces resolved at the base centre of mass :math:`\\sum T_i^T f_i` [N, N·m].
    device_force_total : (n, 3)
        Device forces at the base centre of mass [N, N·m].
    base_shear : (n, 3)
        ``isolation_force + device_force_total`` (the isolation-level force).
    structure_shear : (n, 3)
        First-storey force :math:`R^T(K u_s + C\\dot u_s)` [N, N·m].
    bearing_force : (n, n_bearings, 2) or None
        Total force of each bearing (x, y) [N]; ``None`` with ``bearing_histories=False``.
    bearing_state : (n, n_bearings, n_states) or None
        Hysteretic states of each bearing (``record_states=True`` and ``bearing_histories=True``).
    device_displacement, device_velocity, device_force, voltage : (n, n_devices)
        [m], [m/s], [N] (device sign convention), [V] (held over each control step).
    energy : dict of (n,) arrays
        ``input, kinetic, strain, damping, hysteretic, device`` [J]
        (:func:`benchmark.simulator.stepping.energy_histories`).
    measurements : (n_control, n_meas)
        The measurement vectors the controller saw (noise added); empty without a controller.
    desired_force : (n_control, n_devices)
        Desired forces of a compiled controller (NaN for pure-Python controllers).
    iterations : (n,) int
        Fixed-point iterations of each step.
    info : dict
        record, orientation, isolation, controller, settings, elapsed time.

    Notes
    -----
    :func:`simulate` returns the kernel's own histories (base motion, device forces, voltages,
    measurements) at once and derives the others (accelerations, floor responses, drifts,
    shears, device strokes, energies) on first access, in one pass each
    (:func:`derived_histories`, :func:`benchmark.simulator.stepping.energy_histories`): a run whose
    caller reads only a few histories does not pay for the rest. The values are the same either
    way; pickling (worker processes) and :func:`dataclasses.replace` derive them first.
    """

    t: np.ndarray
    base_displacement: np.ndarray
    base_velocity: np.ndarray
    base_acceleration: np.ndarray
    base_acceleration_absolute: np.ndarray
    floor_displacement: np.ndarray
    floor_acceleration_absolute: np.ndarray
    drift_ratio: np.ndarray
    isolation_force: np.ndarray
    device_force_total: np.ndarray
    base_shear: np.ndarray
    structure_shear: np.ndarray
    bearing_force: np.ndarray
    bearing_state: np.ndarray | None
    device_displacement: np.ndarray
    device_velocity: np.ndarray
    device_force: np.ndarray
    voltage: np.ndarray
    energy: dict
    measurements: np.ndarray
    desired_force: np.ndarray
    iterations: np.ndarray
    info: dict = field(default_factory=dict)
    state: np.ndarray | None = field(default=None, repr=False)
    ground_acceleration: np.ndarray | None = field(default=None, repr=False)

    def __getattr__(self, name: str) -> Any:
        # Called only for an attribute not set yet: a derived history of a lazy result.
        pending = self.__dict__.get("_pending")
        if pending is None or name not in pending:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        derive = pending[name]
        values = derive()
        for key in [k for k, f in pending.items() if f is derive]:
            del pending[key]
        for key, value in values.items():  # never over a value set meanwhile
            self.__dict__.setdefault(key, value)
        return self.__dict__[name]

    def materialize(self) -> "SimulationResult":
        """Derive every history not derived yet (see Notes); returns ``self``."""
        pending = self.__dict__.get("_pending") or {}
        for name in list(pending):
            if name in pending:
                getattr(self, name)
        return self

    def __getstate__(self) -> dict:
        self.materialize()
        state = dict(self.__dict__)
        state.pop("_pending", None)
        return state

    @classmethod
    def _lazy(cls, pending: dict[str, Callable[[], dict]], **values: Any) -> "SimulationResult":
        # ``values`` the fields known now; ``pending`` maps each other field to the call that
        # returns it (with its siblings) as a dict
        self = cls.__new__(cls)
        self.__dict__.update(values)
        self.__dict__["_pending"] = dict(pending)
        return self

    @property
    def n_samples(self) -> int:
        return self.t.shape[0]

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0]) if self.t.size > 1 else float("nan")

    @property
    def peaks(self) -> Peaks:
        """Named peak responses with units (:class:`benchmark.simulator.peaks.Peaks`): e.g.
        ``result.peaks.base_displacement`` is the peak x–y resultant base displacement [m],
        where ``base_displacement.max()`` would mix the x, y [m] and θ [rad] columns."""
        return peaks_of(self)

    def energy_balance_error(self) -> float:
        """Relative closure error of the energy balance (a number, not the energies).

        Returns
        -------
        float
            :math:`\\max_t |E_{in} - (E_k + E_s + E_d + E_h + E_{dev})| / \\max_t |E_{in}|`:
            the largest residual of input = kinetic + strain + damping + hysteretic + device
            energy over the run, relative to the largest input energy (0 when no energy
            entered). The energies themselves, in J, are ``result.energy`` (a dict of (n,)
            arrays; see :mod:`benchmark.simulator.stepping`).
        """
        e = self.energy
        residual = e["input"] - (e["kinetic"] + e["strain"] + e["damping"] + e["hysteretic"] + e["device"])
        scale = np.max(np.abs(e["input"]))
        return float(np.max(np.abs(residual)) / scale) if scale > 0 else 0.0


#: the histories :func:`derived_histories` derives (one pass) and the energy terms, derived
#: on first access of a :class:`SimulationResult`
_DERIVED_HISTORIES = ("base_acceleration", "base_acceleration_absolute", "floor_displacement",
                      "floor_acceleration_absolute", "drift_ratio", "isolation_force", "base_shear",
                      "structure_shear", "device_displacement", "device_velocity")


def derived_histories(building, z, gb, gd, ag, mats, Kb, Cb, d_infl) -> dict[str, np.ndarray]:
    """The histories linear in the kernel's ``X = [z, g_bearings, g_devices, ag]`` (SI), in one
    matrix product ``X @ W`` (a single BLAS call instead of a dozen small ones on strided views).

    Parameters
    ----------
    building : Building
        The building run.
    z : (n, nz) numpy.ndarray
        The kernel's state history.
    gb, gd : (n, 3) numpy.ndarray
        Generalised hysteretic bearing force and device force at the base centre of mass [N, N·m].
    ag : (n, 2) numpy.ndarray
        Ground acceleration [m/s²].
    mats : dict
        Continuous matrices of :func:`benchmark.simulator.linear_model.state_space_matrices`.
    Kb, Cb : numpy.ndarray
        The bearings' linear stiffness and damping at the base (3, 3).
    d_infl : (n_devices, 3) numpy.ndarray
        Device influence rows.

    Returns
    -------
    dict
        The histories of :data:`_DERIVED_HISTORIES` by name.
    """
    sup = building.superstructure
    nq = sup.n_q
    nv = nq + 3
    nz = z.shape[1]
    n = z.shape[0]
    nd = d_infl.shape[0]
    X = np.empty((n, nz + 8))
    X[:, :nz] = z
    X[:, nz:nz + 3] = gb
    X[:, nz + 3:nz + 6] = gd
    X[:, nz + 6:] = ag
    A_v = mats["A"][nv:]                        # (nv, nz): accelerations from the state
    Bg_v = mats["B_g"][nv:]                     # (nv, 3): from the nonlinear forces
    Bag_v = mats["B_ag"][nv:]                   # (nv, 2): from the ground acceleration
    L_v = np.hstack([A_v, Bg_v, Bg_v, Bag_v])   # (nv, nz + 8): [q̈; ü_b] = L_v X
    basis = sup.basis
    KR = basis.T @ (sup.K.T @ sup.R)            # (nq, 3)
    CR = basis.T @ (sup.C.T @ sup.R)
    blocks = {}
    cols = []

    def add(name, w):
        blocks[name] = slice(sum(c.shape[1] for c in cols), sum(c.shape[1] for c in cols) + w.shape[1])
        cols.append(w)

    add("acc", L_v[nq:].T)                              # ü_b (q̈ is used only through basis q̈ below)
    # u_s = basis q: the state itself for the full superstructure (basis = I), a product otherwise
    identity_basis = basis.shape[0] == nq and np.array_equal(basis, np.eye(nq))
    if not identity_basis:
        Wus = np.zeros((nz + 8, basis.shape[0]))
        Wus[:nq] = basis.T
        add("us", Wus)
    add("floor_rel_acc", L_v[:nq].T @ basis.T)          # basis q̈
    Wss = np.zeros((nz + 8, 3))
    Wss[:nq] = KR
    Wss[nv:nv + nq] = CR
    add("structure_shear", Wss)                         # Rᵀ(K u_s + C u̇_s)
    Wiso = np.zeros((nz + 8, 3))
    Wiso[nq:nv] = Kb.T
    Wiso[nv + nq:nz] = Cb.T
    Wiso[nz:nz + 3] = np.eye(3)
    add("isolation", Wiso)                              # K_b u_b + C_b u̇_b + g_bearings
    Wdev = np.zeros((nz + 8, 2 * nd))
    Wdev[nq:nv, :nd] = d_infl.T
    Wdev[nv + nq:nz, nd:] = d_infl.T
    add("devices", Wdev)                                # device displacement, velocity
    Y = X @ np.hstack(cols)
    ab = Y[:, blocks["acc"]]
    base_abs = ab.copy()
    base_abs[:, :2] += ag
    us = z[:, :nq].copy() if identity_basis else Y[:, blocks["us"]]
    n_floors = sup.n_floors
    floor_abs = Y[:, blocks["floor_rel_acc"]].reshape(n, n_floors, 3) + base_abs[:, None, :]
    floor_disp = us.reshape(n, n_floors, 3)
    drift = np.empty((n, n_floors, 2))
    drift[:, 0] = floor_disp[:, 0, :2]
    drift[:, 1:] = floor_disp[:, 1:, :2] - floor_disp[:, :-1, :2]
    drift /= sup.storey_heights[None, :, None]
    iso = Y[:, blocks["isolation"]]
    dev = Y[:, blocks["devices"]]
    return {"base_acceleration": ab, "base_acceleration_absolute": base_abs, "floor_displacement": floor_disp,
            "floor_acceleration_absolute": floor_abs, "drift_ratio": drift, "isolation_force": iso,
            "base_shear": iso + gd, "structure_shear": Y[:, blocks["structure_shear"]],
            "device_displacement": dev[:, :nd], "device_velocity": dev[:, nd:]}


def build_result(building, record, ag, dt, out, mats, Kb, Cb, extra, packed, d_infl, isolation, session, info,
                 bearing_histories, **settings) -> SimulationResult:
    """The :class:`SimulationResult` of a kernel run: its own histories at once, the others
    (:data:`_DERIVED_HISTORIES`, energies) derived on first access.

    Parameters
    ----------
    building : Building
        The building run.
    record : records.Record
        The record (name, source and orientation go to ``info``).
    ag : (n, 2) numpy.ndarray
        Ground acceleration on the integration grid [m/s²].
    dt : float
        Integration step [s].
    out : benchmark.simulator.kernel_args.Outputs
        The kernel's histories.
    mats : dict
        Continuous matrices of :func:`benchmark.simulator.linear_model.state_space_matrices`.
    Kb, Cb : numpy.ndarray
        The bearings' linear stiffness and damping at the base (3, 3) [N/m, N·s/m].
    extra : dict
        Contiguous energy matrices of the plant (``Mg``, ``Kq``, ``Cq``, ``momentum``).
    packed : object
        The packed isolation layer (``IsolationLayer.pack()``).
    d_infl : (n_devices, 3) numpy.ndarray
        Device influence rows.
    isolation : IsolationLayer
        The isolation layer as run.
    session : controllers.base.ControllerSession or None
        The controller's session (``None`` without devices).
    info : dict
        The caller's ``info``, completed here.
    bearing_histories : bool
        Whether the per-bearing histories were kept.
    **settings
        Run settings recorded in ``info["settings"]``.

    Returns
    -------
    SimulationResult
    """
    z, gb, gd, fd, v, meas, desired, iters = out.z, out.gb, out.gd, out.fd, out.v, out.meas, out.desired, out.iters
    sup = building.superstructure
    nq = sup.n_q
    nv = nq + 3
    n = z.shape[0]
    t = np.arange(n) * dt
    bearing_force = bstate = None
    if bearing_histories:
        # total bearing forces, in place of the hysteretic ones (a compiled loop: no temporaries)
        bearing_force = total_bearing_forces(z, nq, np.ascontiguousarray(sup.bearing_xy, dtype=np.float64),
                                             np.ascontiguousarray(packed.params[:, 0]),
                                             np.ascontiguousarray(packed.params[:, 1]), out.fb)
        if out.bstate.shape[0] == n:
            bstate = out.bstate
    info = dict(info)
    info.setdefault("record", getattr(record, "name", ""))
    info.setdefault("record_source", getattr(record, "source", ""))
    meta = getattr(record, "metadata", None) or {}
    if "orientation" in meta:
        info.setdefault("orientation", meta["orientation"])
    info.setdefault("isolation", getattr(isolation, "name", ""))
    info["controller"] = "none" if session is None else session.name
    info["n_devices"] = d_infl.shape[0]
    info["n_modes"] = sup.n_modes if sup.is_reduced else sup.n_dof
    info["integration_step"] = dt
    info["settings"] = {k: (v if isinstance(v, (int, float, str, type(None))) else repr(v))
                        for k, v in settings.items()}
    info["mean_iterations"] = float(iters[1:].mean()) if n > 1 else 0.0
    info["max_iterations_used"] = int(iters.max()) if n > 1 else 0

    def histories() -> dict[str, np.ndarray]:
        return derived_histories(building, z, gb, gd, ag, mats, Kb, Cb, d_infl)

    def energy() -> dict[str, Any]:
        e = energy_histories(z, gb, gd, ag, dt, nq, extra["Mg"], extra["Kq"], extra["Cq"], Kb, Cb,
                             extra["momentum"])
        return {"energy": {name: e[:, i].copy() for i, name in enumerate(ENERGY_NAMES)}}

    pending: dict[str, Callable[[], dict]] = {name: histories for name in _DERIVED_HISTORIES}
    pending["energy"] = energy
    return SimulationResult._lazy(
        pending, t=t, base_displacement=z[:, nq:nv].copy(), base_velocity=z[:, nv + nq:].copy(),
        device_force_total=gd.copy(), bearing_force=bearing_force, bearing_state=bstate,
        device_force=fd, voltage=v, measurements=meas, desired_force=desired, iterations=iters, info=info,
        state=z, ground_acceleration=ag)


FORMAT_NAME = "sbib-result"
FORMAT_VERSION = 1

_XYT = "m, m, rad"
#: field -> (units, description, axes) of every time history of a SimulationResult
FIELD_UNITS: dict[str, tuple[str, str, str]] = {
    "t": ("s", "time", "time"),
    "base_displacement": (_XYT, "base displacement relative to the ground at the base centre of mass",
                          "time, (x, y, theta)"),
    "base_velocity": ("m/s, m/s, rad/s", "base velocity relative to the ground", "time, (x, y, theta)"),
    "base_acceleration": ("m/s^2, m/s^2, rad/s^2", "base acceleration relative to the ground",
                          "time, (x, y, theta)"),
    "base_acceleration_absolute": ("m/s^2, m/s^2, rad/s^2", "absolute base acceleration",
                                   "time, (x, y, theta)"),
    "floor_displacement": (_XYT, "floor displacements relative to the base, floor 1 up",
                           "time, floor, (x, y, theta)"),
    "floor_velocity": ("m/s, m/s, rad/s", "floor velocities relative to the base, floor 1 up",
                       "time, floor, (x, y, theta)"),
    "floor_acceleration_absolute": ("m/s^2, m/s^2, rad/s^2", "absolute floor accelerations, floor 1 up",
                                    "time, floor, (x, y, theta)"),
    "drift_ratio": ("1", "inter-storey drift / storey height at the centre of mass (floor 1 vs base)",
                    "time, storey, (x, y)"),
    "isolation_force": ("N, N, N*m", "bearing forces at the base centre of mass", "time, (x, y, theta)"),
    "device_force_total": ("N, N, N*m", "device forces at the base centre of mass", "time, (x, y, theta)"),
    "base_shear": ("N, N, N*m", "isolation-level force: bearings + devices", "time, (x, y, theta)"),
    "structure_shear": ("N, N, N*m", "first-storey shear R^T (K u_s + C u_s')", "time, (x, y, theta)"),
    "bearing_force": ("N", "total force of each bearing", "time, bearing, (x, y)"),
    "bearing_displacement": ("m", "displacement of each bearing", "time, bearing, (x, y)"),
    "bearing_state": ("1", "internal (hysteretic) states of each bearing", "time, bearing, state"),
    "device_displacement": ("m", "stroke of each device along its direction", "time, device"),
    "device_velocity": ("m/s", "velocity of each device along its direction", "time, device"),
    "device_force": ("N", "force of each device along its direction", "time, device"),
    "device_state": ("1", "internal states of each device", "time, device, state"),
    "voltage": ("V", "command voltage of each device", "time, device"),
    "measurements": ("SI", "measurement vector at the control steps (benchmark.simulator.sensors order)",
                     "control step, measurement"),
    "control_time": ("s", "times of the control steps", "control step"),
    "desired_force": ("N", "desired device forces of the controller at the control steps",
                      "control step, device"),
    "ground_acceleration": ("m/s^2", "ground acceleration (record, oriented)", "time, (x, y)"),
    "iterations": ("1", "fixed-point iterations of each structural step", "time"),
    "state": ("m, rad, m/s, rad/s", "state of the stepping kernel [q, u_b, q', u_b'] "
              "(benchmark.simulator.linear_model ordering)", "time, state"),
}
_ENERGY_DESCRIPTIONS = {
    "input": "input energy", "kinetic": "kinetic energy", "strain": "elastic strain energy",
    "damping": "energy dissipated by viscous damping", "hysteretic": "energy dissipated by the bearings' hysteresis",
    "device": "energy dissipated by the devices",
}


@dataclass
class StoredResult:
    """A run read back from a result file: the fields of a SimulationResult (SI).

    Attributes
    ----------
    arrays : dict
        Every time history by field name (also reachable as attributes: ``r.base_displacement``).
    energy : dict
        Energy terms [J].
    info : dict
        The run's ``info`` dict (record, orientation, isolation, controller, settings).
    units : dict
        Field -> units string as stored.
    attrs : dict
        The file's root attributes (provenance, ...).
    peak_record : dict
        The peaks stored in the file under their ``peak_*`` names (SI), if any
        (:meth:`benchmark.simulator.peaks.Peaks.as_record` of the run when written). ``r.peaks``
        computes :class:`~benchmark.simulator.peaks.Peaks` from the histories read back.
    """

    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    energy: dict[str, np.ndarray] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    attrs: dict[str, Any] = field(default_factory=dict)
    peak_record: dict[str, float] = field(default_factory=dict)

    @property
    def peaks(self) -> Peaks:
        """Named peaks of the histories read back (:func:`benchmark.simulator.peaks.peaks_of`)."""
        return peaks_of(self)

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = self.__dict__.get("arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)


def _result_items(result: Any) -> dict[str, Any]:
    if dataclasses.is_dataclass(result):
        return {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    if isinstance(result, StoredResult):
        out = dict(result.arrays)
        out.update(energy=result.energy, info=result.info)
        return out
    return dict(vars(result))


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating,)):
        return float(obj)
    if isinstance(obj, Path):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    return repr(obj)


#: storage precision -> numpy type of the float histories (:func:`write_result`)
_PRECISIONS = {"double": np.float64, "single": np.float32}


def _write_run(group: Any, result: Any, dtype: Any = np.float64, command_unit: str = "V") -> None:
    items = _result_items(result)
    th = group.create_group("time_histories")
    n = None
    for name, value in items.items():
        if name in ("energy", "info") or value is None or isinstance(value, (str, bytes, dict)):
            continue
        arr = np.asarray(value)
        if arr.dtype.kind not in "fiub" or arr.ndim == 0:
            continue
        if name == "t":
            n = arr.shape[0]
        elif arr.dtype.kind == "f":
            arr = arr.astype(dtype, copy=False)
        units, description, axes = FIELD_UNITS.get(
            name, ("SI", "field not in the results schema (see benchmark.simulator.simulation)", ""))
        kwargs = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if arr.size > 4096 else {}
        ds = th.create_dataset(name, data=arr, **kwargs)
        if name == "voltage" and command_unit != "V":
            # a damper model identified on the coil current reads the command as amperes
            units, description = command_unit, f"command input of each device, in the damper model's {command_unit}"
        ds.attrs["units"] = units
        ds.attrs["description"] = description
        ds.attrs["axes"] = axes
    if n is None:
        raise InputError("write_result: the result has no time vector 't'; expected a SimulationResult")
    energy = items.get("energy") or {}
    eg = group.create_group("energy")
    for term, values in energy.items():
        ds = eg.create_dataset(term, data=np.asarray(values, dtype=dtype))
        ds.attrs["units"] = "J"
        ds.attrs["description"] = _ENERGY_DESCRIPTIONS.get(term, term)
    info = items.get("info") or {}
    group.attrs["info_json"] = json.dumps(info, default=_json_default)
    try:
        pk = peaks_of(result).as_record()
    except InputError:
        pk = {}
    pg = group.create_group("peaks")
    for key, value in pk.items():
        pg.attrs[key] = value
        pg.attrs[f"{key}_units"] = PEAK_UNITS[key]


def write_result(result: Any, path: str | os.PathLike, *, reference: Any = None,
                 evaluation: dict[str, float | None] | None = None, isolation: Any = None,
                 precision: str = "double", command_unit: str = "V", **extra: object) -> Path:
    """Write a run (and optionally its reference run and J1–J9) to an HDF5 file, atomically.

    Parameters
    ----------
    result : SimulationResult
        The run (all fields SI).
    path : path-like
        Destination ``.h5`` file (its directory is created if needed).
    reference : SimulationResult, optional
        The uncontrolled reference run, stored under ``/reference``.
    evaluation : dict, optional
        J1–J9 (:func:`benchmark.simulator.evaluation.evaluate`), stored as attributes of ``/evaluation``.
    isolation : IsolationLayer, optional
        Stored as JSON (``isolation_json``) so the file documents the bearing parameters.
    precision : {"double", "single"}
        Storage type of the float histories and energies (the time vector stays float64);
        ``"single"`` halves the file (module docstring). Peaks and J's are computed before
        storing, in double precision, either way.
    command_unit : str
        Unit of the devices' command history (``voltage``): ``"V"``, or ``"A"`` for damper models
        identified on the coil current (:mod:`benchmark.applications.damper_choice`).
    **extra
        Further root attributes (converted to ``str``), e.g. ``record_source``.

    Returns
    -------
    Path
        The destination.
    """
    import h5py


    if precision not in _PRECISIONS:
        raise InputError(f"write_result: precision {precision!r} unknown; expected one of "
                         f"{', '.join(_PRECISIONS)}")
    dtype = _PRECISIONS[precision]
    path = Path(path)
    info = _result_items(result).get("info") or {}
    attrs = provenance(**extra)
    for key in ("record", "orientation", "isolation", "controller"):
        if key in info:
            attrs[key] = str(info[key])
    # the time grid of the histories and the record's own step, in s (the record is interpolated
    # onto the integration step when they differ)
    for key in ("record_step", "integration_step"):
        if key in info:
            attrs[f"{key}_s"] = str(info[key])
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT_NAME
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["precision"] = precision
            for key, value in attrs.items():
                f.attrs[key] = value
            if isolation is not None:
                f.attrs["isolation_json"] = (isolation.to_json() if hasattr(isolation, "to_json")
                                             else json.dumps(isolation, default=_json_default))
            _write_run(f.create_group("run"), result, dtype, command_unit)
            if reference is not None:
                _write_run(f.create_group("reference"), reference, dtype, command_unit)
            if evaluation is not None:
                eg = f.create_group("evaluation")
                for key, value in evaluation.items():
                    eg.attrs[key] = np.nan if value is None else float(value)
                    if key in J_DESCRIPTIONS:
                        eg.attrs[f"{key}_description"] = J_DESCRIPTIONS[key]
                        eg.attrs[f"{key}_formula"] = CRITERIA[key].formula
                        eg.attrs[f"{key}_source"] = CRITERIA[key].source
    return path


def _open(path: str | os.PathLike):
    import h5py

    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"result file {path} not found")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"{path}: not an HDF5 file ({exc})") from None
    fmt = _attr(f.attrs.get("format"))
    if fmt != FORMAT_NAME:
        # sbib's other result files: say which, and what reads them
        other = ("an `sbib compare --out` file (one group per run under /runs, J's and peaks as "
                 "attributes; read it with h5py)" if _attr(f.attrs.get("kind")) == "controller comparison"
                 else "an ensemble file (read it with benchmark.applications.ensemble.read_ensemble)"
                 if "n_cases" in f.attrs and "config" in f.attrs else None)
        f.close()
        if other:
            raise InputError(f"{path}: {other}; read_result reads the files of `sbib run --out`")
        raise InputError(f"{path}: attribute 'format' is {fmt!r}; expected "
                         f"{FORMAT_NAME!r} (a file written by sbib run)")
    return f


def _attr(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _as_float64(value: np.ndarray) -> np.ndarray:
    # single-precision files are read back as float64, as every computation expects
    return value.astype(np.float64) if value.dtype == np.float32 else value


def read_result(path: str | os.PathLike, which: str = "run") -> StoredResult:
    """Read a run (``which="run"``) or its reference run (``"reference"``) from a result file.

    Parameters
    ----------
    path : path-like
        A file written by :func:`write_result`.
    which : {"run", "reference"}

    Raises
    ------
    DataNotFoundError
        If the file is absent.
    InputError
        If it is not an sbib result file or lacks the requested group.
    """
    with _open(path) as f:
        if which not in f:
            raise InputError(f"{path}: no group '/{which}'; expected one of "
                             f"{', '.join(k for k in f.keys() if k in ('run', 'reference'))}")
        g = f[which]
        out = StoredResult()
        for name, ds in g["time_histories"].items():
            out.arrays[name] = _as_float64(ds[()])
            out.units[name] = _attr(ds.attrs.get("units", ""))
        for name, ds in g["energy"].items():
            out.energy[name] = _as_float64(ds[()])
        out.info = json.loads(_attr(g.attrs.get("info_json", "{}")))
        if "peaks" in g:
            out.peak_record = {k: _attr(v) for k, v in g["peaks"].attrs.items() if not k.endswith("_units")}
        out.attrs = {k: _attr(v) for k, v in f.attrs.items()}
    return out


def read_evaluation(path: str | os.PathLike) -> dict[str, float | None]:
    """J1–J9 stored in the result file ``path`` (``None`` where undefined); empty if none were stored.

    Parameters
    ----------
    path : str | os.PathLike
        Result HDF5 file.
    """
    with _open(path) as f:
        if "evaluation" not in f:
            return {}
        out: dict[str, float | None] = {}
        for key, value in f["evaluation"].attrs.items():
            if key.endswith(("_description", "_formula", "_source")):
                continue
            v = float(value)
            out[key] = None if np.isnan(v) else v
        return dict(sorted(out.items(), key=lambda kv: int(kv[0][1:]) if kv[0][1:].isdigit() else 99))
