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

from benchmark.simulator.building import Building
from benchmark.simulator.devices import DeviceLayout
from benchmark.simulator.isolation.linear import LinearBearing
from benchmark.simulator.oracle import OracleModel, group_force_and_rates
from benchmark.simulator.peaks import peaks_of
from benchmark.simulator.simulation import simulate
from records import Record, load_benchmark_record


# ----------------------------------------------------------------------------- oracle

# The oracle lives in benchmark.simulator.oracle, shared with `sbib bench` (which also drives it with a
# controller); the names below are the ones these tests use.
Oracle = OracleModel
_group_force_and_rates = group_force_and_rates


def _truncate(record: Record, seconds: float) -> Record:
    n = int(round(seconds / record.dt)) + 1
    return Record(name=record.name, dt=record.dt, acceleration=np.array(record.acceleration[:n]),
                  labels=record.labels, source=record.source, synthetic=record.synthetic,
                  metadata=dict(record.metadata))


def _compare(building, record, controller=None, voltage=None, rel=5e-3, method="RK45", **kwargs):
    result = simulate(building, record, controller=controller, **kwargs)
    oracle = Oracle(building, record, voltage=voltage)
    X = oracle.solve(len(record.acceleration), method=method)
    # one function, peaks_of, on both sides
    ref = peaks_of(oracle.result(X)).as_dict()
    mine = peaks_of(result).as_dict()
    errors = {k: mine[k] / ref[k] - 1 for k in ref if ref[k]}
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
    from damper.models.virtual import VirtualBenchmarkDamper

    layout = DeviceLayout.from_positions([(1.82, 30.69), (-17.25, -16.18)], [0, 1], VirtualBenchmarkDamper())
    building = Building.default(isolation="friction-lrb", devices=layout,
                                structure_path=shared_dir / "benchmark" / "structure.json")
    record = _truncate(load_benchmark_record("sylmar", "FN-x", records_dir=records_dir), 4.0)
    errors, result, _ = _compare(building, record, controller=ConstantVoltage(0.5), voltage=0.5)
    assert np.all(result.voltage == 0.5)
    assert np.abs(result.device_force).max() > 1e5  # the devices did work


def test_force_terms_match_solve_ivp(shared_dir, records_dir):
    """Two virtual dampers with every memoryless force term a diagnosed model can carry into the
    building (:class:`damper.models.force_terms.WithForceTerms`), at constant voltage, against the
    oracle (which calls the model's own rates/force): the same 0.5 % on peaks as the plain devices."""
    from controllers.passive import ConstantVoltage
    from damper.models.force_terms import WithForceTerms
    from damper.models.virtual import VirtualBenchmarkDamper

    def building(model):
        layout = DeviceLayout.from_positions([(1.82, 30.69), (-17.25, -16.18)], [0, 1], model)
        return Building.default(isolation="friction-lrb", devices=layout,
                                structure_path=shared_dir / "benchmark" / "structure.json")

    model = WithForceTerms(VirtualBenchmarkDamper(), asymmetry=0.1, shear_thinning=5.0e4, quadratic_damping=3.0e5)
    record = _truncate(load_benchmark_record("sylmar", "FN-x", records_dir=records_dir), 4.0)
    errors, result, _ = _compare(building(model), record, controller=ConstantVoltage(0.5), voltage=0.5)
    plain = simulate(building(VirtualBenchmarkDamper()), record, controller=ConstantVoltage(0.5))
    # the terms changed the devices' force (a kernel that dropped them would fail here)
    assert np.abs(result.device_force).max() > 1.05 * np.abs(plain.device_force).max()


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
