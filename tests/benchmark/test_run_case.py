"""The one way to run a case (benchmark.simulator.case): record resolution, control step,
reference cache, evaluation."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, ReferenceCache, run_case
from benchmark.simulator.simulation import simulate
from records import load_benchmark_record


@pytest.fixture(scope="module")
def short_kobe(records_dir):
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    return rec.replace(acceleration=rec.acceleration[:1200])  # 6 s


@pytest.fixture(scope="module")
def building():
    return Building.default(isolation="linear")


def test_run_case_equals_simulate_and_caches_the_reference(short_kobe, building):
    cache = ReferenceCache()
    a = run_case(Case(record=short_kobe, controller="passive-on", building=building), cache=cache)
    b = run_case(Case(record=short_kobe, controller="passive-off", building=building), cache=cache)
    assert a.reference is b.reference  # one uncontrolled run for both controllers
    direct = simulate(building, short_kobe, controller="passive-on")
    np.testing.assert_array_equal(a.result.base_displacement, direct.base_displacement)
    np.testing.assert_array_equal(a.reference.base_displacement,
                                  simulate(building.without_devices(), short_kobe).base_displacement)
    assert set(a.J) >= {f"J{i}" for i in range(1, 10)} and a.J["J3"] < 1.0
    assert a.peaks.base_displacement == pytest.approx(
        np.max(np.hypot(*a.result.base_displacement[:, :2].T)))


def test_uncontrolled_case_is_its_own_reference(short_kobe, building):
    out = run_case(Case(record=short_kobe, controller="none", building=building), cache=None)
    assert out.result is out.reference and out.building.devices is None


def test_record_by_name_and_the_seeds_orientation_name(records_dir):
    a = run_case(Case(record="kobe", orientation="FP-y", controller="none", isolation="linear",
                      record_options={"records_dir": str(records_dir)}), cache=None)
    assert a.record.metadata.get("orientation") == "FN-x"


def test_control_step_does_not_depend_on_the_record_step(short_kobe):
    # the simulator integrates on a step that divides the control step (issue 22): any record
    # step fits the benchmark's 0.005 s and any requested step
    assert Case(record="kobe").control_step is None  # run_case then uses the benchmark's 0.005 s
    assert Case(record="kobe", control_step=0.015).control_step == 0.015
    # checked once, when the case is made, before anything is read or run
    with pytest.raises(InputError, match="--control-step"):
        Case(record="kobe", control_step=-0.015)
    with pytest.raises(InputError, match="--control-step"):
        Case(record="kobe", control_step="fast")


def test_bad_record_is_an_input_error():
    with pytest.raises(InputError):
        run_case(Case(record=42, controller="none"))  # type: ignore[arg-type]
