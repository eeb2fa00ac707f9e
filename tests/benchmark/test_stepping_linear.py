"""Linear isolation, no devices: the kernel against an independent exact discretisation.

The reference is assembled here from STRUC.mat (t, kN) in the benchmark's own first-order
form (u_s relative to the base, base equation solved for ü_b), discretised with
``scipy.signal.cont2discrete(method="foh")`` and run with ``dlsim``; it shares no code with
``benchmark.simulator.linear_model`` or ``benchmark.simulator.stepping``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.io
import scipy.signal

from benchmark.simulator.building import Building
from benchmark.foundation.errors import InputError, NumericalError
from benchmark.simulator.simulation import simulate
from records import BENCHMARK_RECORDS, ORIENTATIONS, Record, load_benchmark_record

K_BEARING = 919.422  # kN/m
C_BEARING = 27.717   # kN·s/m


@pytest.fixture(scope="module")
def building(shared_dir):
    return Building.default(isolation="linear", devices=None,
                            structure_path=shared_dir / "benchmark" / "structure.json")


@pytest.fixture(scope="module")
def reference_system(shared_dir):
    """Continuous state space from STRUC.mat; outputs in kN, m, m/s² (t·m/s² = kN)."""
    S = scipy.io.loadmat(shared_dir / "benchmark" / "STRUC.mat", squeeze_me=True)["STRUC"]
    M = np.asarray(S["M"].item(), float)
    K = np.asarray(S["K"].item(), float)
    C = np.asarray(S["C"].item(), float)
    m = np.asarray(S["m"].item(), float)
    R = np.asarray(S["R"].item(), float)
    H = np.asarray(S["H"].item(), float)
    dh = np.asarray(S["dh"].item(), float)
    Kb, Cb = K_BEARING * H, C_BEARING * H
    Mi, mi = np.linalg.inv(M), np.linalg.inv(m)
    # ü_b = m⁻¹(Rᵀ(K u_s + C u̇_s) − Kb u_b − Cb u̇_b) − ü_g ;  M ü_s = −C u̇_s − K u_s − M R (ü_b + ü_g)
    n = 27
    # acceleration of the base (without −ü_g) as a row block acting on x = [u_s, u_b, u̇_s, u̇_b]
    ab = mi @ np.hstack([R.T @ K, -Kb, R.T @ C, -Cb])
    as_ = -Mi @ np.hstack([K, np.zeros((24, 3)), C, np.zeros((24, 3))]) - R @ ab
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:n + 24] = as_
    A[n + 24:] = ab
    B = np.zeros((2 * n, 2))
    B[n + 24:n + 26, :] = -np.eye(2)[:, :2]  # −ü_g on the base's x, y
    # outputs: base displacement (3), base shear Kb u_b + Cb u̇_b (3), structure shear (3),
    # absolute floor accelerations −M⁻¹(K u_s + C u̇_s) (24), floor displacements (24)
    Cout = np.vstack([
        np.hstack([np.zeros((3, 24)), np.eye(3), np.zeros((3, 27))]),
        np.hstack([np.zeros((3, 24)), Kb, np.zeros((3, 24)), Cb]),
        np.hstack([R.T @ K, np.zeros((3, 3)), R.T @ C, np.zeros((3, 3))]),
        -Mi @ np.hstack([K, np.zeros((24, 3)), C, np.zeros((24, 3))]),
        np.hstack([np.eye(24), np.zeros((24, 30))]),
    ])
    return A, B, Cout, dh


def _reference_peaks(reference_system, record: Record) -> dict[str, float]:
    A, B, Cout, dh = reference_system
    Ad, Bd, Cd, Dd, _ = scipy.signal.cont2discrete((A, B, Cout, np.zeros((Cout.shape[0], 2))),
                                                   record.dt, method="foh")
    # scipy's FOH state is ξ = x − Γ u (its feedthrough with C = I is Γ): start from rest, x(0) = 0.
    n = A.shape[0]
    gamma = scipy.signal.cont2discrete((A, B, np.eye(n), np.zeros((n, 2))), record.dt, method="foh")[3]
    xi0 = -gamma @ record.acceleration[0]
    _, y, _ = scipy.signal.dlsim((Ad, Bd, Cd, Dd, record.dt), record.acceleration, x0=xi0)
    floors = y[:, 9:33].reshape(-1, 8, 3)
    rel = np.concatenate([np.zeros((len(y), 1, 3)), y[:, 33:57].reshape(-1, 8, 3)], axis=1)
    drift = (rel[:, 1:, :2] - rel[:, :-1, :2]) / dh[None, :, None]
    return {
        "base_displacement": np.abs(y[:, 0:2]).max(),
        "base_rotation": np.abs(y[:, 2]).max(),
        "base_shear": np.abs(y[:, 3:5]).max() * 1e3,
        "base_torque": np.abs(y[:, 5]).max() * 1e3,
        "structure_shear": np.abs(y[:, 6:8]).max() * 1e3,
        "floor_acceleration": np.abs(floors[..., :2]).max(),
        "drift_ratio": np.abs(drift).max(),
    }


def _peaks(r) -> dict[str, float]:
    return {
        "base_displacement": np.abs(r.base_displacement[:, :2]).max(),
        "base_rotation": np.abs(r.base_displacement[:, 2]).max(),
        "base_shear": np.abs(r.base_shear[:, :2]).max(),
        "base_torque": np.abs(r.base_shear[:, 2]).max(),
        "structure_shear": np.abs(r.structure_shear[:, :2]).max(),
        "floor_acceleration": np.abs(r.floor_acceleration_absolute[..., :2]).max(),
        "drift_ratio": np.abs(r.drift_ratio).max(),
    }


@pytest.mark.parametrize("orientation", ORIENTATIONS)
@pytest.mark.parametrize("name", BENCHMARK_RECORDS)
def test_linear_peaks_match_exact_discretisation(building, reference_system, records_dir, name, orientation):
    record = load_benchmark_record(name, orientation, records_dir=records_dir)
    result = simulate(building, record)
    ref = _reference_peaks(reference_system, record)
    mine = _peaks(result)
    for key, value in ref.items():
        assert mine[key] == pytest.approx(value, rel=5e-3), key
        # Same equations, same discretisation: agreement is far better than the 0.5 % required.
        assert abs(mine[key] / value - 1) < 1e-6, (key, mine[key], value)
    assert result.info["max_iterations_used"] == 1  # linear bearings leave no nonlinear force


def _record(acc: np.ndarray, dt: float = 0.005, name: str = "test") -> Record:
    acc = np.asarray(acc, float)
    return Record(name=name, dt=dt, acceleration=acc, labels=("x", "y")[:acc.shape[1]],
                  source="synthetic: test", synthetic=True, metadata={})


def test_zero_record_gives_zero_response(building):
    nonlinear = building.with_isolation("friction-lrb")
    for b in (building, nonlinear):
        r = simulate(b, _record(np.zeros((400, 2))))
        for name in ("base_displacement", "floor_acceleration_absolute", "bearing_force", "base_shear",
                     "structure_shear", "drift_ratio"):
            assert np.all(getattr(r, name) == 0.0), name
        assert all(np.all(e == 0.0) for e in r.energy.values())


def test_floor_accelerations_follow_the_equations_of_motion(building, records_dir):
    # Absolute floor acceleration = −M⁻¹(K u_s + C u̇_s) for the full model (DOMAIN.md §1, J5).
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    r = simulate(building, record)
    sup = building.superstructure
    nv = sup.n_q + 3
    us, usd = r.state[:, :24], r.state[:, nv:nv + 24]
    expected = -(us @ sup.K.T + usd @ sup.C.T) @ np.linalg.inv(sup.M).T
    np.testing.assert_allclose(r.floor_acceleration_absolute.reshape(-1, 24), expected,
                               atol=1e-9 * np.abs(expected).max())
    # Base: m(ü_b + ü_g) = Rᵀ(K u_s + C u̇_s) − f_b.
    base = (r.structure_shear - r.base_shear) / np.diag(sup.m_base)
    np.testing.assert_allclose(r.base_acceleration_absolute, base, atol=1e-9 * np.abs(base).max())


def test_single_component_record_acts_along_x(building):
    t = np.arange(800) * 0.005
    acc = np.sin(2 * np.pi * 0.5 * t)
    r1 = simulate(building, _record(acc[:, None]))
    r2 = simulate(building, _record(np.column_stack([acc, np.zeros_like(acc)])))
    np.testing.assert_array_equal(r1.base_displacement, r2.base_displacement)


def test_bad_inputs_raise_clear_errors(building):
    acc = np.zeros((100, 2))
    acc[10, 1] = np.nan
    with pytest.raises(InputError, match="sample 10"):  # any object with dt and acceleration
        simulate(building, SimpleNamespace(name="nan", dt=0.005, acceleration=acc))
    with pytest.raises(InputError, match="acceleration"):
        simulate(building, object())
    with pytest.raises(InputError, match="positive time"):  # any positive control step fits (issue 22)
        simulate(building, _record(np.zeros((100, 2))), control_step=-0.005)
    with pytest.raises(InputError, match="shape"):
        simulate(building, SimpleNamespace(name="3c", dt=0.005, acceleration=np.zeros((100, 3))))
    with pytest.raises(InputError, match="no devices"):
        simulate(building, _record(np.zeros((100, 2))), controller="passive-off")


def test_blowup_stops_with_time_state_and_hint(building, records_dir):
    record = load_benchmark_record("elcentro", "FN-x", records_dir=records_dir)
    with pytest.raises(NumericalError) as info:
        simulate(building, record, blowup_limit=0.01)
    err = info.value
    assert err.time is not None and 0 < err.time < record.duration
    assert "u_b_x [m]" in err.state and err.hint
