"""Every in-memory cache is a named object that can be listed and cleared, and clearing them
changes no result (benchmark.foundation.cache; docs/ARCHITECTURE.md "Caches")."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.cache import Cache, caches, clear_caches
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, run_case
from records import load_benchmark_record

# importing these modules creates their caches
import benchmark.applications.comparison  # noqa: F401

EXPECTED = {"simulator.discrete_systems", "simulator.superstructure_digests", "simulator.design_models",
            "simulator.equivalent_bearings", "simulator.superstructure_files", "simulator.references",
            "compare.worker_references"}


def test_cache_is_bounded_lru_and_clears():
    c = Cache("test.lru", size=2)
    c.put("a", 1)
    c.put("b", 2)
    assert c.get("a") == 1  # "a" is now the most recent
    c.put("c", 3)
    assert "b" not in c and c.get("a") == 1 and c.get("c") == 3 and len(c) == 2
    assert c.get_or_compute("d", lambda: 4) == 4 and c.get_or_compute("d", lambda: 5) == 4
    assert caches()["test.lru"] is c
    c.clear()
    assert len(c) == 0
    with pytest.raises(ValueError):
        Cache("test.bad", size=0)


def test_every_module_cache_is_registered():
    assert EXPECTED <= set(caches())


def test_clearing_every_cache_gives_the_same_results(records_dir):
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    record = record.replace(acceleration=record.acceleration[:600])  # 3 s
    case = Case(record=record, controller="clipped-optimal",
                building=Building.default(isolation="friction-lrb"))
    first = run_case(case)
    assert sum(len(c) for c in caches().values()) > 0
    clear_caches()
    assert all(len(c) == 0 for c in caches().values())
    second = run_case(case)
    assert second.reference is not first.reference  # really recomputed
    for name in ("base_displacement", "base_shear", "floor_acceleration_absolute", "voltage"):
        np.testing.assert_array_equal(getattr(second.result, name), getattr(first.result, name))
    np.testing.assert_array_equal(second.reference.base_displacement, first.reference.base_displacement)
    assert second.peaks == first.peaks and second.J == first.J
