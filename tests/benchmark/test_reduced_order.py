"""Reduced-order superstructure: exact with all modes, error reported and shrinking with more modes."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.simulator.linear_model import linear_model
from benchmark.simulator.simulation import reduction_error, simulate
from records import load_benchmark_record

QUANTITIES = ("peak_base_displacement", "peak_base_shear", "peak_structure_shear", "peak_drift_ratio",
              "peak_floor_acceleration")


@pytest.fixture(scope="module")
def building(shared_dir):
    return Building.default(isolation="linear", devices=None,
                            structure_path=shared_dir / "benchmark" / "structure.json")


@pytest.fixture(scope="module")
def record(records_dir):
    return load_benchmark_record("kobe", "FN-x", records_dir=records_dir)


def test_all_modes_reproduce_the_full_model(building, record):
    full = simulate(building, record)
    modal = simulate(building.reduced(24), record)
    scale = np.abs(full.floor_acceleration_absolute).max()
    np.testing.assert_allclose(modal.floor_acceleration_absolute, full.floor_acceleration_absolute,
                               atol=1e-8 * scale)
    np.testing.assert_allclose(modal.base_displacement, full.base_displacement,
                               atol=1e-10 * np.abs(full.base_displacement).max())
    assert modal.info["n_modes"] == 24


def test_reduction_error_is_reported_and_shrinks(building, record):
    reports = {n: reduction_error(building, record, n) for n in (3, 9, 18)}
    worst = {}
    for n, rep in reports.items():
        assert rep["n_modes"] == n
        assert set(rep["mass_participation"]) == {"x", "y", "theta"}
        for q in QUANTITIES:
            assert set(rep[q]) == {"full", "reduced", "relative_error"}
        worst[n] = max(abs(rep[q]["relative_error"]) for q in QUANTITIES)
    # Base response is governed by the isolated modes: even three modes get it within 1 %.
    assert abs(reports[3]["peak_base_displacement"]["relative_error"]) < 0.01
    # Storey forces need the higher modes; the error falls as modes are added.
    assert worst[3] > worst[9] > worst[18]
    assert worst[18] < 5e-3
    assert reports[3]["mass_participation"]["x"] < reports[18]["mass_participation"]["x"] < 1.0


def test_reduced_linear_model_keeps_the_isolated_periods(building):
    full = linear_model(building)
    reduced = linear_model(building.reduced(6))
    assert reduced.A.shape == (18, 18)
    np.testing.assert_allclose(reduced.isolated_periods(), full.isolated_periods(), rtol=2e-3)
