"""Energy balance: input = kinetic + strain + damping + hysteretic + device, computed in the kernel."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.simulator.simulation import ENERGY_NAMES, simulate
from records import load_benchmark_record


@pytest.fixture(scope="module")
def structure_path(shared_dir):
    return shared_dir / "benchmark" / "structure.json"


def _check_balance(result, tolerance=0.01):
    e = result.energy
    assert set(e) == set(ENERGY_NAMES)
    stored_and_dissipated = e["kinetic"] + e["strain"] + e["damping"] + e["hysteretic"] + e["device"]
    residual = np.abs(e["input"] - stored_and_dissipated)
    assert residual.max() <= tolerance * np.abs(e["input"]).max()
    assert result.energy_balance_error() <= tolerance
    # Dissipation never runs backwards; kinetic and strain energy are non-negative.
    assert np.all(np.diff(e["damping"]) >= -1e-9 * e["damping"].max())
    assert e["kinetic"].min() >= 0 and e["strain"].min() >= -1e-9 * e["strain"].max()
    return residual.max() / np.abs(e["input"]).max()


def _input_energy_from_histories(result, building):
    """−∫ ü_g · p dt with the momentum p of superstructure and base, from the state history."""
    sup = building.superstructure
    nv = sup.n_q + 3
    vs = result.state[:, nv:nv + sup.n_q] @ sup.basis.T
    vb = result.base_velocity
    masses = np.diag(sup.M)
    p = np.column_stack([(masses[0::3] * (vs[:, 0::3] + vb[:, [0]])).sum(axis=1) + sup.base_mass * vb[:, 0],
                         (masses[1::3] * (vs[:, 1::3] + vb[:, [1]])).sum(axis=1) + sup.base_mass * vb[:, 1]])
    power = -(result.ground_acceleration * p).sum(axis=1)
    return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * result.dt)])


def test_linear_isolation_energy_balance(structure_path, records_dir):
    building = Building.default(isolation="linear", devices=None, structure_path=structure_path)
    result = simulate(building, load_benchmark_record("kobe", "FN-x", records_dir=records_dir))
    _check_balance(result)
    assert np.all(result.energy["hysteretic"] == 0) and np.all(result.energy["device"] == 0)
    np.testing.assert_allclose(result.energy["input"], _input_energy_from_histories(result, building),
                               atol=1e-9 * np.abs(result.energy["input"]).max())


def test_nonlinear_isolation_energy_balance(structure_path, records_dir):
    building = Building.default(isolation="friction-lrb", devices=None, structure_path=structure_path)
    result = simulate(building, load_benchmark_record("newhall", "FP-x", records_dir=records_dir))
    _check_balance(result)
    e = result.energy
    # Most of the input is dissipated by the bearings' hysteresis in an isolated building.
    assert e["hysteretic"][-1] > 0.5 * e["input"][-1]
    np.testing.assert_allclose(e["input"], _input_energy_from_histories(result, building),
                               atol=1e-9 * np.abs(e["input"]).max())


def test_energy_balance_with_devices(structure_path, records_dir):
    building = Building.default(isolation="friction-lrb", structure_path=structure_path)
    record = load_benchmark_record("elcentro", "FN-x", records_dir=records_dir)
    result = simulate(building, record, controller="passive-on")
    _check_balance(result)
    assert result.energy["device"][-1] > 0.1 * result.energy["input"][-1]
