"""Nonlinear isolation (and devices): the kernel against a scipy ``solve_ivp`` oracle.

The oracle integrates the continuous equations of DOMAIN.md §1 in the benchmark's own form
(u_s relative to the base, base equation solved for ü_b) with ``solve_ivp`` and a step bounded
by the record step:

    ü_b = m⁻¹(Rᵀ(K u_s + C u̇_s) − f_b) − ü_g,   ü_s = −M⁻¹(K u_s + C u̇_s) − R(ü_b + ü_g),

f_b = Σ T_iᵀ f_i (bearings) + Σ T_jᵀ e_j F_j (devices), the ground acceleration interpolated
linearly between samples, the bearings' hysteretic states and the devices' states integrated
with the rest. The bearing equations are evaluated group-wise with numpy (92 bearings per
right-hand side); :func:`test_vectorised_bearings_match_the_modules` checks them against the
bearing modules' own plain-numpy ``rates``/``force`` at random states, so the oracle integrates
the modules' equations. Devices use the damper models' ``rates``/``force`` directly.

Integrator: the system is only mildly stiff (the friction pendulum's Park–Wen state relaxes at
about 2/Y·|u̇| ≈ 2·10³ s⁻¹, the superstructure's highest mode is 133 rad/s), so the default tests
use the explicit adaptive RK45 (rtol 1e-7, step ≤ the record step), which is some fifty times
faster here than LSODA with its finite-difference Jacobian of ~240 states and gives the same
peaks to 1e-5 (checked by the slow LSODA test).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.building import Building
from benchmark.devices import DeviceLayout
from benchmark.isolation.friction_pendulum import FrictionPendulumBearing
from benchmark.isolation.lead_rubber import LeadRubberBearing
from benchmark.isolation.linear import LinearBearing
from benchmark.simulation import simulate
from records import Record, load_benchmark_record


# ----------------------------------------------------------------------------- oracle

def _park_wen_rates(z, v, Y, A, beta, gamma):
    """Biaxial Park–Wen rates, vectorised over bearings: z, v (n, 2)."""
    zx, zy = z[:, 0], z[:, 1]
    vx, vy = v[:, 0], v[:, 1]
    gx = gamma * np.sign(vx * zx) + beta
    gy = gamma * np.sign(vy * zy) + beta
    rx = (A * vx - zx * zx * gx * vx - zx * zy * gy * vy) / Y
    ry = (A * vy - zx * zy * gx * vx - zy * zy * gy * vy) / Y
    return np.column_stack([rx, ry])


def _group_force_and_rates(b, u, v, z):
    """Total force (n, 2) and state rates (n, 2) of a group of identical bearings."""
    if isinstance(b, LinearBearing):
        return b.k * u + b.c * v, np.zeros((len(u), 0))
    if isinstance(b, LeadRubberBearing):
        f = b.post_yield_stiffness * u + b.c * v + b.characteristic_strength * z
        return f, _park_wen_rates(z, v, b.yield_displacement, b.A, b.beta, b.gamma)
    if isinstance(b, FrictionPendulumBearing):
        speed = np.hypot(v[:, 0], v[:, 1])
        mu = b.mu_max - (b.mu_max - b.mu_min) * np.exp(-b.rate_parameter * speed)
        f = b.pendulum_stiffness * u + b.c * v + (mu * b.weight)[:, None] * z
        return f, _park_wen_rates(z, v, b.yield_displacement, b.A, b.beta, b.gamma)
    raise NotImplementedError(type(b).__name__)


class Oracle:
    """Right-hand side of the continuous equations for ``building`` under ``record``."""

    def __init__(self, building: Building, record: Record, voltage: float | None = None):
        sup = building.superstructure
        self.M, self.K, self.C, self.R = sup.M, sup.K, sup.C, sup.R
        self.Minv = np.linalg.inv(sup.M)
        self.minv = np.linalg.inv(sup.m_base)
        self.xy = sup.bearing_xy
        self.groups = [(g.bearing, np.asarray(g.indices)) for g in building.isolation.groups]
        self.nz = sum(2 * len(idx) for b, idx in self.groups if b.n_states)
        self.zslots = []
        offset = 0
        for b, idx in self.groups:
            ns = b.n_states * len(idx)
            self.zslots.append(slice(offset, offset + ns))
            offset += ns
        self.devices = None if voltage is None else building.devices
        self.voltage = voltage
        if self.devices is not None:
            self.G = self.devices.influence()
            self.models = self.devices.models
            self.dn = [m.n_states for m in self.models]
        else:
            self.G = np.zeros((0, 3))
            self.models, self.dn = [], []
        self.ag = record.acceleration
        self.dt = record.dt

    @property
    def n_states(self) -> int:
        return 54 + self.nz + sum(self.dn)

    def initial_state(self) -> np.ndarray:
        x = np.zeros(self.n_states)
        for (b, idx), sl in zip(self.groups, self.zslots):
            if b.n_states:
                x[54 + sl.start:54 + sl.stop] = np.tile(b.initial_state(), len(idx))
        off = 54 + self.nz
        for m in self.models:
            x[off:off + m.n_states] = m.initial_state()
            off += m.n_states
        return x

    def ground(self, t: float) -> np.ndarray:
        s = t / self.dt
        k = min(int(s), len(self.ag) - 2)
        a = s - k
        return (1 - a) * self.ag[k] + a * self.ag[k + 1]

    def forces(self, x):
        """Bearing forces (92, 2), z rates, device forces and device-state rates."""
        ub, vb = x[24:27], x[51:54]
        u = np.column_stack([ub[0] - self.xy[:, 1] * ub[2], ub[1] + self.xy[:, 0] * ub[2]])
        v = np.column_stack([vb[0] - self.xy[:, 1] * vb[2], vb[1] + self.xy[:, 0] * vb[2]])
        f = np.empty_like(u)
        zdot = np.empty(self.nz)
        for (b, idx), sl in zip(self.groups, self.zslots):
            z = x[54 + sl.start:54 + sl.stop].reshape(len(idx), -1)
            fg, rg = _group_force_and_rates(b, u[idx], v[idx], z)
            f[idx] = fg
            zdot[sl] = rg.ravel()
        F = np.empty(len(self.models))
        ddot = np.empty(sum(self.dn))
        off = 54 + self.nz
        doff = 0
        xd = self.G @ ub
        vd = self.G @ vb
        for j, m in enumerate(self.models):
            st = x[off:off + m.n_states]
            F[j] = m.force(st, xd[j], vd[j], self.voltage)
            ddot[doff:doff + m.n_states] = m.rates(st, xd[j], vd[j], self.voltage)
            off += m.n_states
            doff += m.n_states
        return f, zdot, F, ddot

    def __call__(self, t, x):
        us, ub, vs, vb = x[:24], x[24:27], x[27:51], x[51:54]
        f, zdot, F, ddot = self.forces(x)
        fb = np.array([f[:, 0].sum(), f[:, 1].sum(),
                       (-self.xy[:, 1] * f[:, 0] + self.xy[:, 0] * f[:, 1]).sum()]) + self.G.T @ F
        ag3 = np.zeros(3)
        ag3[:2] = self.ground(t)
        elastic = self.K @ us + self.C @ vs
        ab = self.minv @ (self.R.T @ elastic - fb) - ag3
        as_ = -self.Minv @ elastic - self.R @ (ab + ag3)
        return np.concatenate([vs, vb, as_, ab, zdot, ddot])

    def solve(self, n_samples: int, max_step: float | None = None, rtol: float = 1e-7, method: str = "RK45"):
        t_eval = np.arange(n_samples) * self.dt
        atol = np.full(self.n_states, 1e-9)
        atol[54:] = 1e-7
        sol = solve_ivp(self, (0.0, t_eval[-1]), self.initial_state(), method=method, t_eval=t_eval,
                        max_step=max_step or self.dt, rtol=rtol, atol=atol)
        assert sol.success, sol.message
        return sol.y.T

    def outputs(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """Peaks of the same quantities the kernel reports."""
        ub = X[:, 24:27]
        elastic = X[:, :24] @ self.K.T + X[:, 27:51] @ self.C.T
        floor_acc = -(elastic @ self.Minv.T)
        fb = np.empty((len(X), 3))
        dev = np.zeros((len(X), len(self.models)))
        for k, x in enumerate(X):
            f, _, F, _ = self.forces(x)
            fb[k] = [f[:, 0].sum(), f[:, 1].sum(), (-self.xy[:, 1] * f[:, 0] + self.xy[:, 0] * f[:, 1]).sum()]
            fb[k] += self.G.T @ F
            dev[k] = F
        return {"base_displacement": ub, "base_shear": fb, "structure_shear": elastic @ self.R,
                "floor_acceleration": floor_acc, "floor_displacement": X[:, :24], "device_force": dev}


def _peaks_oracle(out: dict, heights: np.ndarray) -> dict[str, float]:
    rel = np.concatenate([np.zeros((len(out["floor_displacement"]), 1, 3)),
                          out["floor_displacement"].reshape(-1, 8, 3)], axis=1)
    drift = (rel[:, 1:, :2] - rel[:, :-1, :2]) / heights[None, :, None]
    peaks = {
        "base_displacement": np.hypot(out["base_displacement"][:, 0], out["base_displacement"][:, 1]).max(),
        "base_rotation": np.abs(out["base_displacement"][:, 2]).max(),
        "base_shear": np.hypot(out["base_shear"][:, 0], out["base_shear"][:, 1]).max(),
        "base_torque": np.abs(out["base_shear"][:, 2]).max(),
        "structure_shear": np.hypot(out["structure_shear"][:, 0], out["structure_shear"][:, 1]).max(),
        "floor_acceleration": np.abs(out["floor_acceleration"].reshape(-1, 8, 3)[..., :2]).max(),
        "drift_ratio": np.abs(drift).max(),
    }
    if out["device_force"].size:
        peaks["device_force"] = np.abs(out["device_force"]).max()
    return peaks


def _peaks_kernel(r) -> dict[str, float]:
    peaks = {
        "base_displacement": np.hypot(r.base_displacement[:, 0], r.base_displacement[:, 1]).max(),
        "base_rotation": np.abs(r.base_displacement[:, 2]).max(),
        "base_shear": np.hypot(r.base_shear[:, 0], r.base_shear[:, 1]).max(),
        "base_torque": np.abs(r.base_shear[:, 2]).max(),
        "structure_shear": np.hypot(r.structure_shear[:, 0], r.structure_shear[:, 1]).max(),
        "floor_acceleration": np.abs(r.floor_acceleration_absolute[..., :2]).max(),
        "drift_ratio": np.abs(r.drift_ratio).max(),
    }
    if r.device_force.size:
        peaks["device_force"] = np.abs(r.device_force).max()
    return peaks


def _truncate(record: Record, seconds: float) -> Record:
    n = int(round(seconds / record.dt)) + 1
    return Record(name=record.name, dt=record.dt, acceleration=np.array(record.acceleration[:n]),
                  labels=record.labels, source=record.source, synthetic=record.synthetic,
                  metadata=dict(record.metadata))


def _compare(building, record, controller=None, voltage=None, rel=5e-3, method="RK45", **kwargs):
    result = simulate(building, record, controller=controller, **kwargs)
    oracle = Oracle(building, record, voltage=voltage)
    X = oracle.solve(len(record.acceleration), method=method)
    ref = _peaks_oracle(oracle.outputs(X), building.superstructure.storey_heights)
    mine = _peaks_kernel(result)
    errors = {k: mine[k] / ref[k] - 1 for k in ref}
    for key in ref:
        assert mine[key] == pytest.approx(ref[key], rel=rel), (key, errors)
    return errors, result, X


# ----------------------------------------------------------------------------- tests

@pytest.fixture(scope="module")
def nonlinear_building(shared_dir):
    return Building.default(isolation="friction-lrb", devices=None,
                            structure_path=shared_dir / "benchmark" / "structure.json")


def test_vectorised_bearings_match_the_modules(nonlinear_building):
    rng = np.random.default_rng(1)
    bearings = [g.bearing for g in nonlinear_building.isolation.groups]
    bearings.append(LinearBearing(919.422e3, 27.717e3))
    for b in bearings:
        u = rng.normal(scale=0.2, size=(20, 2))
        v = rng.normal(scale=0.5, size=(20, 2))
        z = rng.uniform(-1, 1, size=(20, b.n_states)) if b.n_states else np.zeros((20, 0))
        f, rates = _group_force_and_rates(b, u, v, z)
        for i in range(20):
            np.testing.assert_allclose(f[i], b.force(z[i], u[i, 0], u[i, 1], v[i, 0], v[i, 1]), rtol=1e-12)
            np.testing.assert_allclose(rates[i], b.rates(z[i], u[i, 0], u[i, 1], v[i, 0], v[i, 1]),
                                       rtol=1e-12, atol=1e-9)


# The first seconds of two records, covering their strongest shaking (El Centro's peak at 2.2 s,
# Erzincan's at 3.4 s); the full records are in the slow test below.
@pytest.mark.parametrize("name,orientation,seconds", [("elcentro", "FN-x", 6.0), ("erzikan", "FP-x", 5.0)])
def test_nonlinear_isolation_matches_solve_ivp(nonlinear_building, records_dir, name, orientation, seconds):
    record = _truncate(load_benchmark_record(name, orientation, records_dir=records_dir), seconds)
    errors, result, _ = _compare(nonlinear_building, record)
    assert max(abs(e) for e in errors.values()) < 5e-3
    assert result.info["mean_iterations"] > 1  # the nonlinear forces were really iterated
    assert np.abs(result.bearing_state).max() > 0.99  # the bearings yielded / slid


def test_devices_at_constant_voltage_match_solve_ivp(shared_dir, records_dir):
    # Two virtual benchmark dampers (one per direction; the 16-device run is in the slow test):
    # the oracle calls the damper model's own rates/force for each device.
    from controllers.passive import ConstantVoltage
    from damper.virtual import VirtualBenchmarkDamper

    layout = DeviceLayout.from_positions([(1.82, 30.69), (-17.25, -16.18)], [0, 1], VirtualBenchmarkDamper())
    building = Building.default(isolation="friction-lrb", devices=layout,
                                structure_path=shared_dir / "benchmark" / "structure.json")
    record = _truncate(load_benchmark_record("sylmar", "FN-x", records_dir=records_dir), 4.0)
    errors, result, _ = _compare(building, record, controller=ConstantVoltage(0.5), voltage=0.5)
    assert np.all(result.voltage == 0.5)
    assert np.abs(result.device_force).max() > 1e5  # the devices did work


def test_substep_tolerance_convergence(nonlinear_building, records_dir):
    """Time histories converge as the sub-step tolerance tightens (against a tight-tolerance run)."""
    record = _truncate(load_benchmark_record("elcentro", "FN-x", records_dir=records_dir), 4.0)
    ref = simulate(nonlinear_building, record, substep_tolerance=0.01, fixed_point_tolerance=1e-11)
    scale = np.abs(ref.base_shear[:, :2]).max()
    errors = []
    for tol in (2.0, 0.25, 0.03):
        r = simulate(nonlinear_building, record, substep_tolerance=tol, fixed_point_tolerance=1e-11)
        errors.append(np.abs(r.base_shear[:, :2] - ref.base_shear[:, :2]).max() / scale)
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 5e-5
    assert errors[0] > 20 * errors[2]


@pytest.mark.slow
@pytest.mark.parametrize("name,orientation", [("newhall", "FP-x"), ("sylmar", "FN-x"), ("rinaldi", "FN-x"),
                                              ("kobe", "FP-x")])
def test_full_records_match_solve_ivp(nonlinear_building, records_dir, name, orientation):
    record = load_benchmark_record(name, orientation, records_dir=records_dir)
    errors, _, _ = _compare(nonlinear_building, record)
    assert max(abs(e) for e in errors.values()) < 5e-3


@pytest.mark.slow
def test_lsoda_oracle_agrees(nonlinear_building, records_dir):
    record = _truncate(load_benchmark_record("elcentro", "FN-x", records_dir=records_dir), 6.0)
    errors, _, _ = _compare(nonlinear_building, record, method="LSODA")
    assert max(abs(e) for e in errors.values()) < 5e-3


@pytest.mark.slow
def test_sixteen_devices_match_solve_ivp(shared_dir, records_dir):
    from controllers.passive import ConstantVoltage

    building = Building.default(isolation="friction-lrb", structure_path=shared_dir / "benchmark" / "structure.json")
    record = _truncate(load_benchmark_record("newhall", "FN-x", records_dir=records_dir), 8.0)
    errors, _, _ = _compare(building, record, controller=ConstantVoltage(1.0), voltage=1.0)
    assert max(abs(e) for e in errors.values()) < 5e-3
