"""The compiled time-stepping kernel: superstructure, base, bearings, devices, controller.

Method
------
State :math:`z = [q, u_b, \\dot q, \\dot u_b]` of :mod:`benchmark.simulator.linear_model`, whose linear
part (superstructure, base, and the *linear parts* :math:`k_i, c_i` of every bearing) is
discretised exactly at the integration step :math:`h` with a first-order hold on its inputs
:math:`w = [\\ddot u_{g,x}, \\ddot u_{g,y}, g_x, g_y, g_\\theta]` (ground acceleration
interpolated linearly between the samples, which :mod:`benchmark.simulator.simulation` puts on
this step's grid; :math:`g` the generalised base force of
the bearings' hysteretic forces and of the devices):

.. math::

    z_{k+1} = \\Phi z_k + G_0 w_k + G_1 w_{k+1}, \\qquad \\Phi = e^{Ah},

with :math:`G_0 = \\Gamma_1 - \\Gamma_2`, :math:`G_1 = \\Gamma_2` read off
:math:`\\exp\\left(\\begin{bmatrix} A & B & 0 \\\\ 0 & 0 & I/h \\\\ 0 & 0 & 0\\end{bmatrix} h\\right)
= \\begin{bmatrix} \\Phi & \\Gamma_1 & \\Gamma_2 \\\\ \\cdot & \\cdot & \\cdot \\end{bmatrix}`
(:func:`discretize_foh`). The nonlinear forces at the end of the step, :math:`g_{k+1}`, are
found by fixed-point (predictor–corrector) iteration: predict :math:`g_{k+1}` by extrapolation
(quadratic from steps k, k−1, k−2 for the bearings' part, linear for the devices', whose force
jumps with the voltage), compute the base's end displacement and velocity, advance every bearing
(:func:`benchmark.simulator.isolation.registry.bearing_step`) and device
(:func:`damper.models.registry.device_step`) from its state at the step's start along the cubic
Hermite path between the step's end points (the kernels sub-step internally as their
stiffness needs), sum their forces into :math:`g_{k+1}`, and repeat until the change of the
base's end displacement and velocity that the update causes is below ``fixed_point_tolerance``
(relative, with floors of 1 µm and 10 µm/s; rotations scaled by a 30 m radius), or until the
error left after the update, estimated from the contraction rate c of the last two updates as
err·c/(1 − c), is below it (this saves the confirming evaluation). The states
are restarted from the step's start at every iteration, so the converged step is the
solution of the implicit (trapezoid-like) coupling of the exact linear step and the
sub-stepped nonlinear elements.

With ``Settings.integrator`` = :data:`INTEGRATOR_CLOSED_FORM` the bearings advance by the
closed-form chord update (:func:`benchmark.simulator.isolation.registry.bearing_step_closed_form`),
which also writes each bearing's tangent; the Newton iteration on the base then uses those
tangents instead of recomputing them.

Voltages change only at control steps (zero-order hold). At a control step the kernel forms
the measurement vector (:mod:`benchmark.simulator.sensors`), adds the precomputed noise, clips it to the
sensor ranges and, for a compiled controller, calls
:func:`controllers.compiled.controller_update`; a pure-Python controller is called by
:mod:`benchmark.simulator.simulation` between kernel calls of one control step each.

Energy (relative formulation), computed from the histories the kernel writes
(:func:`energy_histories`, dense products over the whole run rather than inside the loop):

* input :math:`E_{in} = -\\int \\ddot u_g^T p\\, dt`, :math:`p` the x, y momentum of
  superstructure and base relative to the ground;
* kinetic :math:`\\tfrac12 \\dot x^T M_g \\dot x`; strain :math:`\\tfrac12 q^T K_q q +
  \\tfrac12 u_b^T K_b u_b` (superstructure and the bearings' linear parts);
* damping :math:`\\int (\\dot q^T C_q \\dot q + \\dot u_b^T C_b \\dot u_b) dt`;
* hysteretic :math:`\\int g_{bearings}^T \\dot u_b\\, dt` (the bearings' remaining force: this
  includes the energy momentarily stored in the hysteretic states);
* device :math:`\\int g_{devices}^T \\dot u_b\\, dt`.

The integrals use the trapezoid rule on the step's end points. The balance
:math:`E_{in} = E_k + E_s + E_d + E_h + E_{dev}` holds in continuous time; its discrete
residual measures the kernel's accuracy.

Status codes returned by :func:`run_steps`: 0 ok, 1 non-finite state, 2 fixed point not
converged, 3 response beyond ``blowup_limit``, 4 compiled controller returned non-finite values.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import scipy.linalg



from benchmark.simulator.isolation.registry import (bearing_step, bearing_step_closed_form, bearing_tangent,  # noqa: E402
                                                    bearings_step_lockstep)
from benchmark.simulator.isolation.park_wen import LOCKSTEP_ROWS  # noqa: E402
from controllers.compiled import controller_update  # noqa: E402
from damper.models.registry import device_step, device_tangent_memo, devices_step_memo, devices_workspace  # noqa: E402

__all__ = ["discretize_foh", "run_steps", "measure", "initial_forces", "total_bearing_forces",
           "energy_histories",
           "STATUS_MESSAGES",
           "STATUS_OK", "STATUS_NONFINITE", "STATUS_NOT_CONVERGED", "STATUS_BLOWUP",
           "STATUS_CONTROLLER", "ROTATION_RADIUS", "INTEGRATORS", "INTEGRATOR_RK4", "INTEGRATOR_CLOSED_FORM",
           "INTEGRATOR_RK4_PER_BEARING"]

STATUS_OK = 0
STATUS_NONFINITE = 1
STATUS_NOT_CONVERGED = 2
STATUS_BLOWUP = 3
STATUS_CONTROLLER = 4
STATUS_MESSAGES = {
    STATUS_NONFINITE: "the state became NaN or infinite",
    STATUS_NOT_CONVERGED: "the fixed-point iteration of the nonlinear forces did not converge",
    STATUS_BLOWUP: "the base displacement grew beyond the blow-up limit",
    STATUS_CONTROLLER: "the compiled controller's state or desired force became NaN or infinite",
}
#: ``Settings.integrator`` values: explicit RK4 sub-steps of every hysteretic element (the
#: oracle-checked reference path; the bearings' sub-steps taken in lock-step across bearings,
#: :func:`benchmark.simulator.isolation.registry.bearings_step_lockstep`), the same one bearing
#: after another (the path before the lock-step, kept to check it against), or the implicit
#: element updates with consistent tangents.
INTEGRATOR_RK4 = 0
INTEGRATOR_CLOSED_FORM = 1
INTEGRATOR_RK4_PER_BEARING = 2
#: names accepted by ``simulate(integrator=...)``
INTEGRATORS = {"rk4": INTEGRATOR_RK4, "closed-form": INTEGRATOR_CLOSED_FORM,
               "rk4-per-bearing": INTEGRATOR_RK4_PER_BEARING}
#: Radius [m] that turns a base rotation into a displacement for tolerances and limits.
ROTATION_RADIUS = 30.0
#: LLVM fast-math flags of the kernels: reassociation lets the dense products and the energy
#: sums vectorise, contraction fuses multiply-adds. No flag that assumes finite values (the NaN
#: and blow-up checks must stay), so results are deterministic and exactly odd in the record.
_FASTMATH = {"reassoc", "contract"}
_U_FLOOR = 1.0e-6   # m
_V_FLOOR = 1.0e-5   # m/s


def discretize_foh(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact discretisation of :math:`\\dot z = Az + Bw` with ``w`` linear over each step.

    Parameters
    ----------
    A : np.ndarray
        State matrix (n, n).
    B : np.ndarray
        Input matrix (n, m).
    h : float
        Step [s].

    Returns
    -------
    Phi, G0, G1 : arrays
        :math:`z_{k+1} = \\Phi z_k + G_0 w_k + G_1 w_{k+1}`.
    """
    n, m = B.shape
    big = np.zeros((n + 2 * m, n + 2 * m))
    big[:n, :n] = A * h
    big[:n, n:n + m] = B * h
    big[n:n + m, n + m:] = np.eye(m)
    E = scipy.linalg.expm(big)
    Phi = E[:n, :n]
    gamma1 = E[:n, n:n + m]
    gamma2 = E[:n, n + m:]
    return np.ascontiguousarray(Phi), np.ascontiguousarray(gamma1 - gamma2), np.ascontiguousarray(gamma2)


@numba.njit(cache=True, fastmath=_FASTMATH)
def measure(nq, z, g, ag, fd, devices, sensors, noise_row, y):
    """Write the measurement vector (noise added, clipped to the ranges) into ``y``.

    ``z`` (n_z,) state, ``g`` (3,) total generalised nonlinear force, ``ag`` (2,) ground
    acceleration and ``fd`` (n_dev,) device forces, all at one sample; ``devices`` and
    ``sensors`` the :class:`benchmark.simulator.kernel_args.Devices` and
    :class:`benchmark.simulator.kernel_args.Sensors` of the run (the sensors' ``layout`` places the
    blocks); ``noise_row`` the noise of this control step.

    Parameters
    ----------
    nq
        Number of superstructure coordinates.
    z
        State at the sample (n_z,).
    g
        Total generalised nonlinear force (3,) [N, N, N·m].
    ag
        Ground acceleration (2,) [m/s²].
    fd
        Device forces (n_dev,) [N].
    devices
        The run's devices (:class:`benchmark.simulator.kernel_args.Devices`).
    sensors
        The run's sensors (:class:`benchmark.simulator.kernel_args.Sensors`).
    noise_row
        Noise of this control step (n_meas,).
    y
        Array the measurement vector is written into.
    """
    nz = z.shape[0]
    lay = sensors.layout
    C_acc = sensors.C_acc
    D_acc_g = sensors.D_acc_g
    D_acc_ag = sensors.D_acc_ag
    d_infl = devices.influence
    for r in range(lay.n_accelerations):
        s = 0.0
        for c in range(nz):
            s += C_acc[r, c] * z[c]
        for c in range(3):
            s += D_acc_g[r, c] * g[c]
        s += D_acc_ag[r, 0] * ag[0] + D_acc_ag[r, 1] * ag[1]
        y[r] = s
    for c in range(3):
        y[lay.base_displacement + c] = z[nq + c]
    for j in range(lay.n_devices):
        y[lay.device_displacement + j] = d_infl[j, 0] * z[nq] + d_infl[j, 1] * z[nq + 1] + d_infl[j, 2] * z[nq + 2]
        y[lay.device_force + j] = fd[j]
    ranges = sensors.ranges
    for r in range(y.shape[0]):
        v = y[r] + noise_row[r]
        lim = ranges[r]
        if v > lim:
            v = lim
        elif v < -lim:
            v = -lim
        y[r] = v


@numba.njit(cache=True)
def initial_forces(dt, bearings, devices, voltage, fb, fd, gb, gd):
    """Hysteretic bearing forces and device forces of the initial states at rest.

    Evaluated by one zero-motion step on copies of the states (the states are not changed).
    ``bearings``, ``devices``: :class:`benchmark.simulator.kernel_args.Bearings`, ``Devices``.

    Parameters
    ----------
    dt
        Record step [s].
    bearings
        The run's bearings (:class:`benchmark.simulator.kernel_args.Bearings`).
    devices
        The run's devices (:class:`benchmark.simulator.kernel_args.Devices`).
    voltage
        Initial device voltages [V].
    fb
        Array (n_b, 2) the bearings' hysteretic forces [N] are written into.
    fd
        Array (n_dev,) the device forces [N] are written into.
    gb
        Array (3,) the generalised bearing force is written into.
    gd
        Array (3,) the generalised device force is written into.
    """
    out = np.zeros(2)
    gb[:] = 0.0
    gd[:] = 0.0
    b_xy = bearings.xy
    for i in range(b_xy.shape[0]):
        st = bearings.state[i].copy()
        bearing_step(bearings.type_id[i], bearings.params[i], st, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                     dt, out)
        fb[bearings.index[i], 0] = out[0]
        fb[bearings.index[i], 1] = out[1]
        gb[0] += out[0]
        gb[1] += out[1]
        gb[2] += -b_xy[i, 1] * out[0] + b_xy[i, 0] * out[1]
    d_infl = devices.influence
    for j in range(d_infl.shape[0]):
        st = devices.state[j].copy()
        f = device_step(devices.model_id[j], devices.params[j], st, 0.0, 0.0, 0.0, 0.0, voltage[j], dt)
        fd[j] = f
        for c in range(3):
            gd[c] += d_infl[j, c] * f


@numba.njit(cache=True)
def total_bearing_forces(z, nq, b_xy, k_lin, c_lin, fb):
    r"""Turn the hysteretic bearing forces ``fb`` (n, n_b, 2) into total forces, in place, and return it.

    Bearing i at plan position (x_i, y_i) moves with the base as
    :math:`u_i = (u_x - y_i\theta,\ u_y + x_i\theta)`; its total force is
    :math:`k_i u_i + c_i \dot u_i + f_{h,i}` [N] (``z`` the state history, base at ``nq:nq+3``
    and velocities at ``2nq+3+...``).

    Parameters
    ----------
    z
        State history (n, n_z) (or the state at one sample).
    nq
        Number of superstructure coordinates.
    b_xy
        Bearing plan positions (n_b, 2) [m].
    k_lin
        Linear stiffness of each bearing [N/m].
    c_lin
        Linear damping of each bearing [N·s/m].
    fb
        Hysteretic bearing forces (n, n_b, 2) [N], made total in place.
    """
    nv = nq + 3
    for k in range(z.shape[0]):
        ux = z[k, nq]
        uy = z[k, nq + 1]
        th = z[k, nq + 2]
        vx = z[k, nv + nq]
        vy = z[k, nv + nq + 1]
        om = z[k, nv + nq + 2]
        for i in range(b_xy.shape[0]):
            bx = b_xy[i, 0]
            by = b_xy[i, 1]
            fb[k, i, 0] += k_lin[i] * (ux - by * th) + c_lin[i] * (vx - by * om)
            fb[k, i, 1] += k_lin[i] * (uy + bx * th) + c_lin[i] * (vy + bx * om)
    return fb


def energy_histories(z: np.ndarray, gb: np.ndarray, gd: np.ndarray, ag: np.ndarray, dt: float, nq: int,
                     Mg: np.ndarray, Kq: np.ndarray, Cq: np.ndarray, Kb: np.ndarray, Cb: np.ndarray,
                     momentum: np.ndarray) -> np.ndarray:
    """Energy terms of a run from its histories (module docstring), shape ``(n, 6)`` [J].

    Columns ``input, kinetic, strain, damping, hysteretic, device``; the powers at every sample
    are dense products over the whole history (one BLAS call each) and the integrals the
    trapezoid rule on consecutive samples, starting from zero at rest.

    Parameters
    ----------
    z : np.ndarray
        State history (n, n_z) (or the state at one sample).
    gb : np.ndarray
        Generalised hysteretic bearing force history (n, 3).
    gd : np.ndarray
        Generalised device force history (n, 3).
    ag : np.ndarray
        Ground acceleration history (n, 2) [m/s²].
    dt : float
        Record step [s].
    nq : int
        Number of superstructure coordinates.
    Mg : np.ndarray
        Mass matrix of the generalised velocities (kinetic energy).
    Kq : np.ndarray
        Superstructure stiffness (n_q, n_q).
    Cq : np.ndarray
        Superstructure damping (n_q, n_q).
    Kb : np.ndarray
        Linear base stiffness (3, 3).
    Cb : np.ndarray
        Linear base damping (3, 3).
    momentum : np.ndarray
        Rows (2, n_v) giving the x, y momentum from the velocities.
    """
    nv = nq + 3
    q = z[:, :nq]
    ub = z[:, nq:nv]
    v = z[:, nv:]
    qd = v[:, :nq]
    ubd = v[:, nq:]
    out = np.empty((z.shape[0], 6))
    out[:, 1] = 0.5 * np.einsum("ij,ij->i", v @ Mg.T, v)
    out[:, 2] = 0.5 * (np.einsum("ij,ij->i", q @ Kq.T, q) + np.einsum("ij,ij->i", ub @ Kb.T, ub))
    powers = np.empty((z.shape[0], 4))
    powers[:, 0] = -np.einsum("ij,ij->i", ag, v @ momentum.T)
    powers[:, 1] = np.einsum("ij,ij->i", qd @ Cq.T, qd) + np.einsum("ij,ij->i", ubd @ Cb.T, ubd)
    powers[:, 2] = np.einsum("ij,ij->i", gb, ubd)
    powers[:, 3] = np.einsum("ij,ij->i", gd, ubd)
    steps = 0.5 * dt * (powers[1:] + powers[:-1])
    for col, p in zip((0, 3, 4, 5), range(4)):
        out[0, col] = 0.0
        np.cumsum(steps[:, p], out=out[1:, col])
    return out


@numba.njit(cache=True, fastmath=_FASTMATH, inline="always")
def _base_change(Gb, dg, u_scale, v_scale):
    """Largest change of the base's end displacement / velocity a force change ``dg`` causes,
    relative to ``u_scale`` / ``v_scale`` (rotations times :data:`ROTATION_RADIUS`)."""
    du_max = 0.0
    dv_max = 0.0
    for r in range(3):
        du = 0.0
        dv = 0.0
        for c in range(3):
            du += Gb[r, c] * dg[c]
            dv += Gb[3 + r, c] * dg[c]
        if r == 2:
            du *= ROTATION_RADIUS
            dv *= ROTATION_RADIUS
        du_max = max(du_max, abs(du))
        dv_max = max(dv_max, abs(dv))
    return max(du_max / u_scale, dv_max / v_scale)


@numba.njit(cache=True, inline="always")
def _solve3(M, b, x):
    """Solve the 3 x 3 system ``M x = b`` by Cramer's rule; False when ``M`` is (near) singular."""
    c00 = M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1]
    c01 = M[1, 2] * M[2, 0] - M[1, 0] * M[2, 2]
    c02 = M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]
    det = M[0, 0] * c00 + M[0, 1] * c01 + M[0, 2] * c02
    scale = abs(M[0, 0]) + abs(M[1, 1]) + abs(M[2, 2])
    if not (abs(det) > 1e-12 * scale * scale * scale):
        return False
    inv = 1.0 / det
    x[0] = (b[0] * c00 + b[1] * (M[0, 2] * M[2, 1] - M[0, 1] * M[2, 2])
            + b[2] * (M[0, 1] * M[1, 2] - M[0, 2] * M[1, 1])) * inv
    x[1] = (b[0] * c01 + b[1] * (M[0, 0] * M[2, 2] - M[0, 2] * M[2, 0])
            + b[2] * (M[0, 2] * M[1, 0] - M[0, 0] * M[1, 2])) * inv
    x[2] = (b[0] * c02 + b[1] * (M[0, 1] * M[2, 0] - M[0, 0] * M[2, 1])
            + b[2] * (M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0])) * inv
    return math.isfinite(x[0]) and math.isfinite(x[1]) and math.isfinite(x[2])


@numba.njit(cache=True, fastmath=_FASTMATH)
def _compiled_control(k, plant, ag, devices, sensors, control, out, y, g_tot, fc):
    """Measure at step k, store the measurement, and update the compiled controller's voltages."""
    kc = k // control.ratio
    lay = sensors.layout
    for c in range(3):
        g_tot[c] = out.gb[k, c] + out.gd[k, c]
    measure(plant.nq, out.z[k], g_tot, ag[k], out.fd[k], devices, sensors, sensors.noise[kc], y)
    for r in range(y.shape[0]):
        out.meas[kc, r] = y[r]
    for j in range(lay.n_devices):
        fc[j] = y[lay.device_force + j]
    return controller_update(control.Ac, control.Bc, control.Cc, control.Dc, control.law_id,
                             control.law_params, control.v_max, control.slew_rate, control.dt,
                             y, fc, control.xc, control.voltage, out.desired[kc])


@numba.njit(cache=True, fastmath=_FASTMATH, inline="always")
def _exact_linear_step(plant, ag, gb_out, gd_out, k, z0, w0, zlin):
    """``zlin = Phi z0 + G0 w_k + G1[:, :2] a_g,k+1``: step ``k``'s exact linear update with its
    known inputs (``w0``, filled here: the ground acceleration and the base's forces at the
    step's start); the forces at its end enter through ``G1[:, 2:5]`` once they are known."""
    Phi = plant.Phi
    G0 = plant.G0
    G1 = plant.G1
    nz = Phi.shape[0]
    w0[0] = ag[k, 0]
    w0[1] = ag[k, 1]
    for c in range(3):
        w0[2 + c] = gb_out[k, c] + gd_out[k, c]
    a1x = ag[k + 1, 0]
    a1y = ag[k + 1, 1]
    for r in range(nz):
        s = 0.0
        for c in range(nz):
            s += Phi[r, c] * z0[c]
        for c in range(5):
            s += G0[r, c] * w0[c]
        s += G1[r, 0] * a1x + G1[r, 1] * a1y
        zlin[r] = s


@numba.njit(cache=True, fastmath=_FASTMATH)
def _linear_steps(k_start, k_stop, plant, ag, settings, out):
    """:func:`run_steps` for a building with no nonlinear force and nothing commanded (linear
    isolation, no devices): the exact linear step alone, with the same sums as the general loop
    (the base's force inputs, zero here, included) and the same checks, but in the linear floor's
    loop (:mod:`benchmark.applications.linear_floor`; the general loop took ~1.6x it)."""
    nq = plant.nq
    nz = plant.Phi.shape[0]
    z_out = out.z
    limit = settings.blowup_limit
    w0 = np.empty(5)
    for k in range(k_start, k_stop):
        z1 = z_out[k + 1]
        _exact_linear_step(plant, ag, out.gb, out.gd, k, z_out[k], w0, z1)
        finite = True
        for r in range(nz):
            finite = finite and math.isfinite(z1[r])
        out.iters[k + 1] = 1
        if not finite:
            return STATUS_NONFINITE, k
        if (abs(z1[nq]) > limit or abs(z1[nq + 1]) > limit or ROTATION_RADIUS * abs(z1[nq + 2]) > limit):
            return STATUS_BLOWUP, k
    return STATUS_OK, k_stop


@numba.njit(cache=True, fastmath=_FASTMATH)
def run_steps(k_start, k_stop, plant, ag, bearings, devices, sensors, control, settings, out):
    """Advance the building from step ``k_start`` to ``k_stop`` (integration steps, k_stop ≤ n − 1).

    Arguments are the objects of :mod:`benchmark.simulator.kernel_args`: ``plant`` (:class:`Plant`),
    ``ag`` the ground acceleration ``(n, 2)`` [m/s²], ``bearings``, ``devices`` (states
    advanced in place), ``sensors``, ``control`` (controller state and voltages updated in
    place; ``control.mode`` 0 no controller or voltages held as given, 1 compiled controller,
    ``controller_update`` at every ``control.ratio``-th step, 2 voltages given by the caller
    for this chunk), ``settings`` and ``out`` (:class:`Outputs`). On entry ``out.z[k_start]``,
    ``out.gb[k_start]``, ``out.gd[k_start]``, ``out.fd[k_start]`` hold the state at
    ``k_start``.

    Parameters
    ----------
    k_start
        First record sample (its state is given in ``out``).
    k_stop
        Last record sample to reach.
    plant
        The exact linear step (:class:`benchmark.simulator.kernel_args.Plant`).
    ag
        Ground acceleration (n, 2) [m/s²].
    bearings
        The run's bearings (:class:`benchmark.simulator.kernel_args.Bearings`).
    devices
        The run's devices (:class:`benchmark.simulator.kernel_args.Devices`).
    sensors
        The run's sensors (:class:`benchmark.simulator.kernel_args.Sensors`).
    control
        The controller (:class:`benchmark.simulator.kernel_args.Control`), updated in place.
    settings
        Iteration and output settings (:class:`benchmark.simulator.kernel_args.Settings`).
    out
        The histories written (:class:`benchmark.simulator.kernel_args.Outputs`).

    Returns
    -------
    (status, k)
        ``status`` 0 when all steps were taken, else a code of :data:`STATUS_MESSAGES` with ``k``
        the step whose end failed.
    """
    Phi = plant.Phi
    G1 = plant.G1
    Gb = plant.Gb
    dt = plant.dt
    nq = plant.nq
    nz = Phi.shape[0]
    nv = nq + 3
    b_xy = bearings.xy
    b_type = bearings.type_id
    b_params = bearings.params
    b_state = bearings.state
    d_infl = devices.influence
    d_model = devices.model_id
    d_params = devices.params
    d_state = devices.state
    voltage = control.voltage
    ratio = control.ratio
    ctrl_mode = control.mode
    fp_tol = settings.fp_tol
    blowup_limit = settings.blowup_limit
    z_out = out.z
    gb_out = out.gb
    gd_out = out.gd
    nb = b_xy.shape[0]
    nd = d_infl.shape[0]
    n_meas = sensors.layout.n_measurements
    sb = b_state.shape[1]
    sd = d_state.shape[1]

    zlin = np.empty(nz)
    w0 = np.empty(5)
    g_guess = np.empty(3)
    g_new = np.empty(3)
    gb_new = np.empty(3)
    gd_new = np.empty(3)
    zb_lin = np.empty(6)
    ub1 = np.empty(3)
    vb1 = np.empty(3)
    b_start = np.empty((nb, sb))
    d_start = np.empty((nd, sd))
    fb_tmp = np.empty((nb, 2))
    fd_tmp = np.empty(nd)
    force = np.empty(2)
    y = np.empty(n_meas)
    g_tot = np.empty(3)
    fc = np.empty(nd)
    resid = np.empty(3)
    delta = np.empty(3)
    left = np.empty(3)
    jac = np.empty((3, 6))
    mat = np.empty((3, 3))
    tangent = np.empty((2, 4))
    implicit = settings.integrator == INTEGRATOR_CLOSED_FORM
    lockstep = settings.integrator == INTEGRATOR_RK4
    lock_ws = np.empty((LOCKSTEP_ROWS, nb if lockstep else 0))
    lock_ns = np.empty(nb if lockstep else 0, dtype=np.int64)
    # consistent tangents of the implicit bearing updates, written by the evaluation itself
    b_tan = np.zeros((nb if implicit else 0, 2, 4))
    # per-device scratch of values that depend only on a step's start state and voltage (the
    # iterations below advance each device several times from the same state), and the
    # Spencer-type devices' lock-step workspace (the per-bearing reference path keeps the
    # per-device update of the devices too)
    d_ws = devices_workspace(d_model, settings.integrator != INTEGRATOR_RK4_PER_BEARING)
    d_memo = d_ws.memo

    if nb == 0 and nd == 0 and ctrl_mode == 0:
        return _linear_steps(k_start, k_stop, plant, ag, settings, out)
    for k in range(k_start, k_stop):
        z0 = z_out[k]
        # ---- control step: measurement, compiled controller
        if ctrl_mode == 1 and k % ratio == 0:
            st = _compiled_control(k, plant, ag, devices, sensors, control, out, y, g_tot, fc)
            if st != 0:
                return STATUS_CONTROLLER, k
        for j in range(nd):
            out.v[k, j] = voltage[j]

        # ---- linear part with the known inputs
        _exact_linear_step(plant, ag, gb_out, gd_out, k, z0, w0, zlin)
        for r in range(3):
            zb_lin[r] = zlin[nq + r]
            zb_lin[3 + r] = zlin[nv + nq + r]

        # ---- predictor: quadratic extrapolation of the bearings' force, linear of the devices'
        # (which jump with the voltage); mean iterations on Kobe 30 s with all-linear
        # extrapolation 2.25 -> 2.06 without devices, 2.50 -> 2.39 with clipped-optimal
        for c in range(3):
            if k > 1:
                g_guess[c] = (3.0 * gb_out[k, c] - 3.0 * gb_out[k - 1, c] + gb_out[k - 2, c]
                              + 2.0 * gd_out[k, c] - gd_out[k - 1, c])
            elif k > 0:
                g_guess[c] = 2.0 * w0[2 + c] - (gb_out[k - 1, c] + gd_out[k - 1, c])
            else:
                g_guess[c] = w0[2 + c]
        if nb + nd > 0:
            for i in range(nb):
                for c in range(sb):
                    b_start[i, c] = b_state[i, c]
            for j in range(nd):
                for c in range(sd):
                    d_start[j, c] = d_state[j, c]

        ux0b = z0[nq]
        uy0b = z0[nq + 1]
        th0 = z0[nq + 2]
        vx0b = z0[nv + nq]
        vy0b = z0[nv + nq + 1]
        om0 = z0[nv + nq + 2]
        converged = False
        newton = settings.newton
        iters = 0
        err_prev = -1.0
        for it in range(settings.max_iter):
            iters = it + 1
            for r in range(3):
                su = zb_lin[r]
                sv = zb_lin[3 + r]
                for c in range(3):
                    su += Gb[r, c] * g_guess[c]
                    sv += Gb[3 + r, c] * g_guess[c]
                ub1[r] = su
                vb1[r] = sv
            if it > 0:
                for i in range(nb):
                    for c in range(sb):
                        b_state[i, c] = b_start[i, c]
                for j in range(nd):
                    for c in range(sd):
                        d_state[j, c] = d_start[j, c]
            for c in range(3):
                gb_new[c] = 0.0
                gd_new[c] = 0.0
            if lockstep:
                bearings_step_lockstep(b_type, b_params, b_state, bearings.form, b_xy, ux0b, uy0b, th0, ub1,
                                       vx0b, vy0b, om0, vb1, dt, lock_ws, lock_ns, fb_tmp)
            for i in range(nb if lockstep else 0):
                bx = b_xy[i, 0]
                by = b_xy[i, 1]
                gb_new[0] += fb_tmp[i, 0]
                gb_new[1] += fb_tmp[i, 1]
                gb_new[2] += -by * fb_tmp[i, 0] + bx * fb_tmp[i, 1]
            for i in range(0 if lockstep else nb):
                bx = b_xy[i, 0]
                by = b_xy[i, 1]
                ux0 = ux0b - by * th0
                uy0 = uy0b + bx * th0
                ux1 = ub1[0] - by * ub1[2]
                uy1 = ub1[1] + bx * ub1[2]
                vx0 = vx0b - by * om0
                vy0 = vy0b + bx * om0
                vx1 = vb1[0] - by * vb1[2]
                vy1 = vb1[1] + bx * vb1[2]
                if implicit:
                    bearing_step_closed_form(b_type[i], b_params[i], b_state[i], ux0, uy0, ux1, uy1,
                                          vx0, vy0, vx1, vy1, dt, force, b_tan[i])
                else:
                    bearing_step(b_type[i], b_params[i], b_state[i], ux0, uy0, ux1, uy1,
                                 vx0, vy0, vx1, vy1, dt, force)
                fb_tmp[i, 0] = force[0]
                fb_tmp[i, 1] = force[1]
                gb_new[0] += force[0]
                gb_new[1] += force[1]
                gb_new[2] += -by * force[0] + bx * force[1]
            for j in range(nd):
                d_ws.x0[j] = d_infl[j, 0] * ux0b + d_infl[j, 1] * uy0b + d_infl[j, 2] * th0
                d_ws.x1[j] = d_infl[j, 0] * ub1[0] + d_infl[j, 1] * ub1[1] + d_infl[j, 2] * ub1[2]
                d_ws.xd0[j] = d_infl[j, 0] * vx0b + d_infl[j, 1] * vy0b + d_infl[j, 2] * om0
                d_ws.xd1[j] = d_infl[j, 0] * vb1[0] + d_infl[j, 1] * vb1[1] + d_infl[j, 2] * vb1[2]
            if nd > 0:
                devices_step_memo(d_model, d_params, d_state, voltage, dt, d_ws, fd_tmp)
            for j in range(nd):
                f = fd_tmp[j]
                for c in range(3):
                    gd_new[c] += d_infl[j, c] * f
            # Change of the end displacement/velocity the update causes.
            for r in range(3):
                g_new[r] = gb_new[r] + gd_new[r]
                resid[r] = g_new[r] - g_guess[r]
            u_scale = max(abs(ub1[0]), abs(ub1[1]), ROTATION_RADIUS * abs(ub1[2])) + _U_FLOOR
            v_scale = max(abs(vb1[0]), abs(vb1[1]), ROTATION_RADIUS * abs(vb1[2])) + _V_FLOOR
            err = _base_change(Gb, resid, u_scale, v_scale)
            if not (err == err):  # NaN
                return STATUS_NONFINITE, k
            if err <= fp_tol:
                converged = True
                break
            if newton:
                # Newton on the base's 3 DOF: the residual R(g) = F(u(g)) - g of the nonlinear
                # force, u = zb_lin + Gb g, with the Jacobian I - J Gb, J the sum of the
                # bearings' and devices' tangents at the end of the step (3 x 6, generalised).
                for r in range(3):
                    for c in range(6):
                        jac[r, c] = 0.0
                for i in range(nb):
                    bx = b_xy[i, 0]
                    by = b_xy[i, 1]
                    dx = (ub1[0] - by * ub1[2]) - (ux0b - by * th0)
                    dy = (ub1[1] + bx * ub1[2]) - (uy0b + bx * th0)
                    if implicit:
                        tan_i = b_tan[i]
                    else:
                        bearing_tangent(b_type[i], b_params[i], b_state[i], dx, dy,
                                        vb1[0] - by * vb1[2], vb1[1] + bx * vb1[2], tangent)
                        tan_i = tangent
                    for half in range(2):  # displacement, then velocity columns
                        o = 2 * half
                        col = 3 * half
                        # T_i^T K T_i with T_i = [[1, 0, -y_i], [0, 1, x_i]] (bearing i's motion)
                        k00 = tan_i[0, o]
                        k01 = tan_i[0, o + 1]
                        k10 = tan_i[1, o]
                        k11 = tan_i[1, o + 1]
                        a02 = -by * k00 + bx * k01
                        a12 = -by * k10 + bx * k11
                        jac[0, col] += k00
                        jac[0, col + 1] += k01
                        jac[0, col + 2] += a02
                        jac[1, col] += k10
                        jac[1, col + 1] += k11
                        jac[1, col + 2] += a12
                        jac[2, col] += -by * k00 + bx * k10
                        jac[2, col + 1] += -by * k01 + bx * k11
                        jac[2, col + 2] += -by * a02 + bx * a12
                for j in range(nd):
                    x1 = d_infl[j, 0] * ub1[0] + d_infl[j, 1] * ub1[1] + d_infl[j, 2] * ub1[2]
                    xd1 = d_infl[j, 0] * vb1[0] + d_infl[j, 1] * vb1[1] + d_infl[j, 2] * vb1[2]
                    kx, kv = device_tangent_memo(d_model[j], d_params[j], d_state[j], x1, xd1, voltage[j],
                                                 d_memo[j])
                    for r in range(3):
                        for c in range(3):
                            jac[r, c] += kx * d_infl[j, r] * d_infl[j, c]
                            jac[r, 3 + c] += kv * d_infl[j, r] * d_infl[j, c]
                # M = I - J Gb
                for r in range(3):
                    for c in range(3):
                        s = 0.0
                        for m in range(6):
                            s += jac[r, m] * Gb[m, c]
                        mat[r, c] = (1.0 if r == c else 0.0) - s
                ok = _solve3(mat, resid, delta)
                if ok:
                    # error left if the evaluated forces g_new are accepted, by the Newton model:
                    # g_new - g* = R - delta (the analogue of err c / (1 - c) below)
                    for r in range(3):
                        left[r] = resid[r] - delta[r]
                    err_left = _base_change(Gb, left, u_scale, v_scale)
                    # the first evaluation is accepted on the model's word only with the
                    # closed-form updates, whose tangents are the update's own derivatives
                    if (it > 0 and err < 0.5 * err_prev or it == 0 and implicit) and err_left <= fp_tol:
                        converged = True
                        break
                    if err_prev > 0.0 and err > err_prev:
                        newton = False  # diverging (a tangent far off): plain fixed point from here
                    else:
                        for c in range(3):
                            g_guess[c] += delta[c]
                        err_prev = err
                        continue
                else:
                    newton = False
            # Fixed-point update. Error left after it, estimated from the contraction of the
            # last two updates (c < 1): err * c / (1 - c). Saves the confirming evaluation.
            for c in range(3):
                g_guess[c] = g_new[c]
            if err_prev > 0.0:
                rate = err / err_prev
                if rate < 0.5 and err * rate / (1.0 - rate) <= fp_tol:
                    converged = True
                    break
            err_prev = err
        out.iters[k + 1] = iters
        if not converged:
            return STATUS_NOT_CONVERGED, k

        # ---- final state with the converged forces
        z1 = z_out[k + 1]
        for r in range(nz):
            z1[r] = zlin[r] + G1[r, 2] * g_new[0] + G1[r, 3] * g_new[1] + G1[r, 4] * g_new[2]
        for r in range(nz):
            if not math.isfinite(z1[r]):
                return STATUS_NONFINITE, k
        if (abs(z1[nq]) > blowup_limit or abs(z1[nq + 1]) > blowup_limit
                or ROTATION_RADIUS * abs(z1[nq + 2]) > blowup_limit):
            return STATUS_BLOWUP, k
        for c in range(3):
            gb_out[k + 1, c] = gb_new[c]
            gd_out[k + 1, c] = gd_new[c]
        if settings.record_bearings:
            for i in range(nb):
                out.fb[k + 1, bearings.index[i], 0] = fb_tmp[i, 0]
                out.fb[k + 1, bearings.index[i], 1] = fb_tmp[i, 1]
        for j in range(nd):
            out.fd[k + 1, j] = fd_tmp[j]
        if settings.record_states:
            for i in range(nb):
                for c in range(sb):
                    out.bstate[k + 1, bearings.index[i], c] = b_state[i, c]
    # The last sample of the record is a control step too: measure it (the voltage it yields
    # is recorded for that sample only), as the pure-Python path does.
    n = z_out.shape[0]
    if ctrl_mode == 1 and k_stop == n - 1 and k_stop % ratio == 0:
        st = _compiled_control(k_stop, plant, ag, devices, sensors, control, out, y, g_tot, fc)
        if st != 0:
            return STATUS_CONTROLLER, k_stop
    return STATUS_OK, k_stop
