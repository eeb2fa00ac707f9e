"""The oracle: a scipy ``solve_ivp`` integration of the building's equations (tests and ``sbib bench``).

"Reference" in this project means the uncontrolled run that J1-J9 divide by; this module is the
*oracle*, an independent integration the compiled kernels are checked against. It integrates the continuous equations of Narasimhan et al. (2006, Part I) in the benchmark's own form
(:math:`u_s` relative to the base, the base equation solved for :math:`\\ddot u_b`) with
``solve_ivp`` (RK45 by default, rtol 1e-7) and a step bounded by the record step:

.. math::

    \\ddot u_b = m^{-1}\\left(R^T(K u_s + C \\dot u_s) - f_b\\right) - \\ddot u_g, \\qquad
    \\ddot u_s = -M^{-1}(K u_s + C \\dot u_s) - R(\\ddot u_b + \\ddot u_g),

:math:`f_b = \\sum_i T_i^T f_i` (bearings) :math:`+ \\sum_j T_j^T e_j F_j` (devices), the ground
acceleration interpolated linearly between samples, the bearings' hysteretic states and the
devices' states integrated with the rest. Bearing equations are evaluated group-wise with
numpy (:func:`group_force_and_rates`, checked in the tests against the bearing modules' own
``rates``/``force``); devices use their models' ``rates``/``force``.

It shares no code with the compiled kernel (:mod:`benchmark.simulator.stepping`): no discretisation, no
sub-stepping, no fixed-point iteration. With a controller, the voltages are held over each
control step as in the kernel: at :math:`t_k` the measurement vector of :mod:`benchmark.simulator.sensors`
is formed from the reference's own state (accelerations from the right-hand side, device forces
at the voltage held so far, clipped to the sensor ranges, no noise), the controller is called
through the same :class:`controllers.base.ControllerSession`, and the integrator is restarted
for :math:`[t_k, t_{k+1}]`.

Origin: written as the oracle of ``tests/benchmark/test_oracle_nonlinear.py`` (building core);
moved here and extended to controllers so that the tests and ``sbib bench`` share one reference.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import NumericalError
from benchmark.simulator.isolation.friction_pendulum import FrictionPendulumBearing
from benchmark.simulator.isolation.lead_rubber import LeadRubberBearing
from benchmark.simulator.isolation.linear import LinearBearing
from benchmark.simulator.peaks import Peaks, peaks_of
from benchmark.simulator.sensors import noise_samples
from benchmark.simulator.simulation import _resolve_controller
from controllers.base import ControllerSession
from benchmark.simulator.control import control_context

__all__ = ["park_wen_rates", "group_force_and_rates", "OracleModel", "OracleResult",
           "simulate_oracle"]


def park_wen_rates(z: np.ndarray, v: np.ndarray, Y: float, A: float, beta: float, gamma: float) -> np.ndarray:
    """Biaxial Park–Wen rates :math:`\\dot z`, vectorised over bearings.

    Parameters
    ----------
    z, v : numpy.ndarray
        Hysteretic states and bearing velocities (n, 2) [-, m/s].
    Y : float
        Yield displacement [m].
    A, beta, gamma : float
        Park–Wen shape parameters.
    """
    zx, zy = z[:, 0], z[:, 1]
    vx, vy = v[:, 0], v[:, 1]
    gx = gamma * np.sign(vx * zx) + beta
    gy = gamma * np.sign(vy * zy) + beta
    rx = (A * vx - zx * zx * gx * vx - zx * zy * gy * vy) / Y
    ry = (A * vy - zx * zy * gx * vx - zy * zy * gy * vy) / Y
    return np.column_stack([rx, ry])


def group_force_and_rates(bearing: Any, u: np.ndarray, v: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Total force (n, 2) [N] and state rates (n, 2) of a group of identical bearings.

    Parameters
    ----------
    bearing : LinearBearing, LeadRubberBearing or FrictionPendulumBearing
    u, v : numpy.ndarray
        Bearing displacements and velocities (n, 2) [m, m/s].
    z : numpy.ndarray
        Hysteretic states (n, n_states).
    """

    b = bearing
    if isinstance(b, LinearBearing):
        return b.k * u + b.c * v, np.zeros((len(u), 0))
    if isinstance(b, LeadRubberBearing):
        f = b.post_yield_stiffness * u + b.c * v + b.characteristic_strength * z
        return f, park_wen_rates(z, v, b.yield_displacement, b.A, b.beta, b.gamma)
    if isinstance(b, FrictionPendulumBearing):
        speed = np.hypot(v[:, 0], v[:, 1])
        mu = b.mu_max - (b.mu_max - b.mu_min) * np.exp(-b.rate_parameter * speed)
        f = b.pendulum_stiffness * u + b.c * v + (mu * b.weight)[:, None] * z
        return f, park_wen_rates(z, v, b.yield_displacement, b.A, b.beta, b.gamma)
    raise NotImplementedError(f"reference: no vectorised equations for bearing type {type(b).__name__}")


class OracleModel:
    """Right-hand side of the continuous equations for ``building`` under ``record``.

    The state is ``[u_s (n_q), u_b (3), u̇_s (n_q), u̇_b (3), bearing states, device states]``
    with the full superstructure (``n_q = 24``).

    Parameters
    ----------
    building : benchmark.simulator.building.Building
        The building (a reduced superstructure is replaced by the full one).
    record : records.Record
        The ground motion (linear between samples).
    voltage : float or array, optional
        Device voltages [V] (held until changed through :attr:`voltage`); ``None``: no devices.
    """

    def __init__(self, building: Any, record: Any, voltage: float | np.ndarray | None = None) -> None:
        sup = building.superstructure
        if getattr(sup, "is_reduced", False):
            sup = sup.full()
        self.M, self.K, self.C, self.R = sup.M, sup.K, sup.C, sup.R
        self.nq = self.M.shape[0]
        self.Minv = np.linalg.inv(sup.M)
        self.minv = np.linalg.inv(sup.m_base)
        self.storey_heights = sup.storey_heights
        self.xy = sup.bearing_xy
        self.groups = [(g.bearing, np.asarray(g.indices)) for g in building.isolation.groups]
        self.zslots = []
        offset = 0
        for b, idx in self.groups:
            ns = b.n_states * len(idx)
            self.zslots.append(slice(offset, offset + ns))
            offset += ns
        self.nz = offset
        if voltage is not None and building.devices is not None:
            self.devices = building.devices
            self.G = self.devices.influence()
            self.models = self.devices.models
            self.dn = [m.n_states for m in self.models]
            self.voltage = np.broadcast_to(np.asarray(voltage, dtype=float), (len(self.models),)).copy()
        else:
            self.devices = None
            self.G = np.zeros((0, 3))
            self.models, self.dn = [], []
            self.voltage = np.zeros(0)
        self.ag = np.zeros((record.acceleration.shape[0], 2))
        self.ag[:, :record.acceleration.shape[1]] = record.acceleration
        self.dt = float(record.dt)
        self.n0 = 2 * (self.nq + 3)

    @property
    def n_states(self) -> int:
        """Length of the state vector."""
        return self.n0 + self.nz + sum(self.dn)

    def initial_state(self) -> np.ndarray:
        """At rest; bearing and device states at their models' initial values."""
        x = np.zeros(self.n_states)
        for (b, idx), sl in zip(self.groups, self.zslots):
            if b.n_states:
                x[self.n0 + sl.start:self.n0 + sl.stop] = np.tile(b.initial_state(), len(idx))
        off = self.n0 + self.nz
        for m in self.models:
            x[off:off + m.n_states] = m.initial_state()
            off += m.n_states
        return x

    def ground(self, t: float) -> np.ndarray:
        """Ground acceleration (x, y) at time ``t`` (linear between samples) [m/s²].

        Parameters
        ----------
        t : float
            Time [s].
        """
        s = t / self.dt
        k = min(int(s), len(self.ag) - 2)
        a = s - k
        return (1 - a) * self.ag[k] + a * self.ag[k + 1]

    def _split(self, x: np.ndarray):
        nq = self.nq
        return x[:nq], x[nq:nq + 3], x[nq + 3:2 * nq + 3], x[2 * nq + 3:2 * nq + 6]

    def forces(self, x: np.ndarray):
        """Bearing forces (n_b, 2), bearing-state rates, device forces and device-state rates.

        Parameters
        ----------
        x : np.ndarray
            State vector.
        """
        _, ub, _, vb = self._split(x)
        u = np.column_stack([ub[0] - self.xy[:, 1] * ub[2], ub[1] + self.xy[:, 0] * ub[2]])
        v = np.column_stack([vb[0] - self.xy[:, 1] * vb[2], vb[1] + self.xy[:, 0] * vb[2]])
        f = np.empty_like(u)
        zdot = np.empty(self.nz)
        for (b, idx), sl in zip(self.groups, self.zslots):
            z = x[self.n0 + sl.start:self.n0 + sl.stop].reshape(len(idx), -1)
            fg, rg = group_force_and_rates(b, u[idx], v[idx], z)
            f[idx] = fg
            zdot[sl] = rg.ravel()
        F = np.empty(len(self.models))
        ddot = np.empty(sum(self.dn))
        off = self.n0 + self.nz
        doff = 0
        xd = self.G @ ub
        vd = self.G @ vb
        for j, m in enumerate(self.models):
            st = x[off:off + m.n_states]
            F[j] = m.force(st, xd[j], vd[j], self.voltage[j])
            ddot[doff:doff + m.n_states] = m.rates(st, xd[j], vd[j], self.voltage[j])
            off += m.n_states
            doff += m.n_states
        return f, zdot, F, ddot

    def _base_force(self, f: np.ndarray, F: np.ndarray) -> np.ndarray:
        return np.array([f[:, 0].sum(), f[:, 1].sum(),
                         (-self.xy[:, 1] * f[:, 0] + self.xy[:, 0] * f[:, 1]).sum()]) + self.G.T @ F

    def accelerations(self, t: float, x: np.ndarray, forces=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Relative accelerations of the base (3) and superstructure (n_q), and ground (3).

        Parameters
        ----------
        t : float
            Time [s].
        x : np.ndarray
            State vector.
        forces : tuple, optional
            The result of :meth:`forces` at ``x``; None: computed.
        """
        us, _, vs, _ = self._split(x)
        f, _, F, _ = self.forces(x) if forces is None else forces
        fb = self._base_force(f, F)
        ag3 = np.zeros(3)
        ag3[:2] = self.ground(t)
        elastic = self.K @ us + self.C @ vs
        ab = self.minv @ (self.R.T @ elastic - fb) - ag3
        as_ = -self.Minv @ elastic - self.R @ (ab + ag3)
        return ab, as_, ag3

    def __call__(self, t: float, x: np.ndarray) -> np.ndarray:
        _, _, vs, vb = self._split(x)
        forces = self.forces(x)
        ab, as_, _ = self.accelerations(t, x, forces)
        return np.concatenate([vs, vb, as_, ab, forces[1], forces[3]])

    def measurement(self, t: float, x: np.ndarray, sensor_range: np.ndarray | None = None) -> np.ndarray:
        """The measurement vector of :mod:`benchmark.simulator.sensors` at ``(t, x)`` (no noise).

        Absolute accelerations of the base (3) and floors 1..8 (24), base displacement (3),
        device displacements and forces (at the voltages held so far), clipped to ``sensor_range``.

        Parameters
        ----------
        t : float
            Time [s].
        x : np.ndarray
            State vector.
        sensor_range : np.ndarray | None, optional
            Sensor ranges to clip to; None: no clipping.
        """
        forces = self.forces(x)
        ab, as_, ag3 = self.accelerations(t, x, forces)
        base_abs = ab + ag3
        floors_abs = as_ + self.R @ base_abs
        _, ub, _, _ = self._split(x)
        y = np.concatenate([base_abs, floors_abs, ub, self.G @ ub, forces[2]])
        if sensor_range is not None:
            y = np.clip(y, -sensor_range, sensor_range)
        return y

    def solve(self, n_samples: int, max_step: float | None = None, rtol: float = 1e-7,
              t0: float = 0.0, x0: np.ndarray | None = None, method: str = "RK45") -> np.ndarray:
        """Integrate from ``t0`` over ``n_samples`` record steps; return the states (n_samples, n_states).

        ``method``: a ``solve_ivp`` method; the default explicit RK45 suits this mildly stiff
        system (fastest Park–Wen relaxation about 2·10³ s⁻¹, highest mode 133 rad/s) and is about
        fifty times faster than LSODA with its finite-difference Jacobian of ~240 states, with
        the same peaks to 1e-5.

        Parameters
        ----------
        n_samples : int
            Number of record samples to integrate over.
        max_step : float | None, optional
            Largest step of the integrator [s]; None: the record step.
        rtol : float, optional
            Relative tolerance of :func:`scipy.integrate.solve_ivp`.
        t0 : float, optional
            Start time [s].
        x0 : np.ndarray | None, optional
            Initial state; None: at rest.
        method : str, optional
            Integration method of :func:`scipy.integrate.solve_ivp`.
        """
        t_eval = t0 + np.arange(n_samples) * self.dt
        atol = np.full(self.n_states, 1e-9)
        atol[self.n0:] = 1e-7
        if n_samples < 2:
            return (self.initial_state() if x0 is None else x0)[None, :].copy()
        sol = solve_ivp(self, (t0, t_eval[-1]), self.initial_state() if x0 is None else x0, method=method,
                        t_eval=t_eval, max_step=max_step or self.dt, rtol=rtol, atol=atol)
        if not sol.success:
            raise NumericalError(f"reference solve_ivp failed: {sol.message}", time=float(sol.t[-1]))
        return sol.y.T

    def outputs(self, X: np.ndarray, voltages: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Histories of the quantities compared with the kernel.

        ``voltages`` (n, n_devices): the voltage that acted over the step ending at each sample
        (default: the current :attr:`voltage` throughout).

        Parameters
        ----------
        X : np.ndarray
            States (n_samples, n_states) of :meth:`solve`.
        voltages : np.ndarray | None, optional
            Device voltages at each sample [V]; None: the current ones.
        """
        ub = X[:, self.nq:self.nq + 3]
        elastic = X[:, :self.nq] @ self.K.T + X[:, self.nq + 3:2 * self.nq + 3] @ self.C.T
        floor_acc = -(elastic @ self.Minv.T)
        fb = np.empty((len(X), 3))
        dev = np.zeros((len(X), len(self.models)))
        saved = self.voltage.copy()
        try:
            for k, x in enumerate(X):
                if voltages is not None and len(self.models):
                    self.voltage[:] = voltages[k]
                f, _, F, _ = self.forces(x)
                fb[k] = self._base_force(f, F)
                dev[k] = F
        finally:
            self.voltage[:] = saved
        floors = X[:, :self.nq].reshape(len(X), -1, 3)
        rel = np.concatenate([np.zeros((len(X), 1, 3)), floors], axis=1)
        drift = (rel[:, 1:, :2] - rel[:, :-1, :2]) / np.asarray(self.storey_heights)[None, :, None]
        return {"base_displacement": ub, "base_shear": fb, "structure_shear": elastic @ self.R,
                "floor_acceleration": floor_acc, "floor_displacement": X[:, :self.nq], "device_force": dev,
                # under the names of SimulationResult, for benchmark.simulator.peaks.peaks_of: the
                # kernel's absolute floor accelerations equal -M^{-1}(K u_s + C u_s') (see result())
                "floor_acceleration_absolute": floor_acc.reshape(len(X), -1, 3), "drift_ratio": drift,
                "device_force_total": dev @ self.G}

    def result(self, X: np.ndarray, voltages: np.ndarray | None = None) -> "OracleResult":
        """The run of states ``X`` as an :class:`OracleResult`.

        Its histories carry the names of :class:`~benchmark.simulator.simulation.SimulationResult`, so
        :func:`benchmark.simulator.peaks.peaks_of` computes the peaks of both the same way.
        ``floor_acceleration_absolute`` here is the superstructure's acceleration relative to the
        base frame :math:`-M^{-1}(K u_s + C \\dot u_s)` as the oracle computes it (the kernel's
        absolute floor accelerations equal it: :math:`\\ddot u_s + R(\\ddot u_b + \\ddot u_g)`).

        Parameters
        ----------
        X : numpy.ndarray
            States (n, n_states) of :meth:`solve`.
        voltages : numpy.ndarray, optional
            (n, n_devices) as in :meth:`outputs`.
        """
        voltage = np.zeros((len(X), 0)) if voltages is None else np.asarray(voltages)
        return OracleResult(states=X, outputs=self.outputs(X, voltages), voltage=voltage, elapsed_s=0.0)


@dataclass
class OracleResult:
    """An oracle run: states, outputs (SI), voltages, wall time.

    The histories of ``outputs`` are also attributes under the names of
    :class:`~benchmark.simulator.simulation.SimulationResult` (``r.base_displacement``,
    ``r.drift_ratio``, ``r.floor_acceleration_absolute``, ``r.device_force_total``, ...), and
    ``r.peaks`` is :func:`benchmark.simulator.peaks.peaks_of` of them, as for a kernel run.

    Parameters
    ----------
    states : numpy.ndarray
        (n, n_states) state history.
    outputs : dict
        Histories of :meth:`OracleModel.outputs` (SI).
    voltage : numpy.ndarray
        (n, n_devices) voltages [V].
    elapsed_s : float
        Wall time [s].
    info : dict
        Controller, tolerance, step and method of the integration.
    """

    states: np.ndarray
    outputs: dict
    voltage: np.ndarray
    elapsed_s: float
    info: dict = field(default_factory=dict)

    def __getattr__(self, name: str) -> np.ndarray:
        outputs = self.__dict__.get("outputs") or {}
        if name in outputs:
            return outputs[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def peaks(self) -> Peaks:
        """Named peaks (:func:`benchmark.simulator.peaks.peaks_of`), SI."""
        return peaks_of(self)


def simulate_oracle(building: Any, record: Any, controller: Any = None, control_step: float = 0.005,
                       rtol: float = 1e-7, max_step: float | None = None, method: str = "RK45") -> OracleResult:
    """Run the ``solve_ivp`` reference of :func:`benchmark.simulator.simulation.simulate`'s equations.

    Parameters
    ----------
    building : benchmark.simulator.building.Building
    record : records.Record
    controller : None, str or controller object
        ``None``: no devices (as in :func:`~benchmark.simulator.simulation.simulate`); otherwise a name of
        :mod:`controllers.registry` or an object, driven through
        :class:`controllers.base.ControllerSession` with voltages held over each control step.
    control_step : float
        [s], a whole multiple of ``record.dt``.
    rtol, max_step : float
        Relative tolerance and largest step (default ``record.dt``) of the integrator.
    method : str
        ``solve_ivp`` method (default ``"RK45"``; ``"LSODA"``/``"Radau"`` for a stiff check).

    Returns
    -------
    OracleResult

    Raises
    ------
    NumericalError
        If the integrator fails.
    """

    t_start = _time.perf_counter()
    dt = float(record.dt)
    n = record.acceleration.shape[0]
    if controller is None:
        model = OracleModel(building, record)
        X = model.solve(n, max_step=max_step, rtol=rtol, method=method)
        voltage = np.zeros((n, 0))
    else:
        controller = _resolve_controller(controller)
        ratio = int(round(control_step / dt))
        context = control_context(building, control_step=ratio * dt,
                                               info={"record": getattr(record, "name", "")})
        session = ControllerSession(controller, context)
        model = OracleModel(building, record, voltage=0.0)
        nd = len(model.models)
        n_control = (n - 1) // ratio + 1
        _, sensor_range = noise_samples(None, n_control, nd, None, n_floors=building.superstructure.n_floors)
        compiled = session.compiled
        if compiled is not None:
            _, v0 = compiled.initial_state()
            model.voltage[:] = v0
        X = np.empty((n, model.n_states))
        X[0] = model.initial_state()
        voltage = np.zeros((n, nd))
        for kc in range(n_control):
            k = kc * ratio
            y = model.measurement(k * dt, X[k], sensor_range)
            model.voltage[:] = session.step(y, time=k * dt)
            k1 = min(k + ratio, n - 1)
            voltage[k:k1 + 1] = model.voltage
            if k1 <= k:
                break
            X[k:k1 + 1] = model.solve(k1 - k + 1, max_step=max_step, rtol=rtol, t0=k * dt, x0=X[k], method=method)
    # the voltage acting over the step that ends at each sample (the kernel's convention)
    held = np.vstack([voltage[:1], voltage[:-1]]) if voltage.size else None
    out = model.outputs(X, held)
    return OracleResult(states=X, outputs=out, voltage=voltage,
                           elapsed_s=_time.perf_counter() - t_start,
                           info={"controller": None if controller is None else str(getattr(controller, "name", controller)),
                                 "rtol": rtol, "max_step": max_step or dt, "method": method})
