"""The integration step belongs to the simulator (issue 22): a record at any step runs, the
ground motion interpolated onto the building's step; a fixed point that does not converge makes
the run start again at half the step, and says so; the last failure names what helps."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError, NumericalError
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, run_case
from benchmark.simulator.simulation import DEFAULT_INTEGRATION_STEP, choose_integration_step, simulate
from records.resample import resample
from records.resolve import resolve_record

KJM = "records/raw/SLAMMER/Kobe_Japan_1995/KJM-000"


@pytest.fixture(scope="module")
def kjm_14s(shared_dir):
    """SLAMMER KJM-000 (Kobe JMA, g, dt = 0.02 s), cut to 14 s: it holds t = 10.96 s, where the
    fixed point failed at the record's own step under every controller."""
    rec = resolve_record(str(shared_dir / KJM), "FN-x", dt=0.02, units="g")
    return rec.replace(acceleration=rec.acceleration[:701])


@pytest.fixture(scope="module")
def nonlinear():
    return Building.default(isolation="friction-lrb")


def test_choose_integration_step_divides_the_control_step():
    assert choose_integration_step(0.005, 0.005) == (0.005, 1)
    assert choose_integration_step(0.005, 0.02) == (0.005, 1)        # coarse record: the building's step
    assert choose_integration_step(0.01, 0.005) == (0.005, 2)
    h, k = choose_integration_step(0.005, 0.002)                     # fine record keeps its detail
    assert k == 3 and h == pytest.approx(0.005 / 3)
    h, k = choose_integration_step(0.0075, 0.01)                     # any control step fits
    assert k == 2 and h == pytest.approx(0.00375)
    assert choose_integration_step(0.02, 0.02, max_step=0.02) == (0.02, 1)
    with pytest.raises(InputError, match="control_step"):
        choose_integration_step(0.0, 0.005)


def test_a_record_at_0_02_s_runs_under_clipped_optimal(kjm_14s, nonlinear):
    out = run_case(Case(record=kjm_14s, controller="clipped-optimal",
                        building=Building.default(isolation="friction-lrb", devices="default")), cache=None)
    for run in (out.result, out.reference):
        assert run.info["record_step"] == 0.02
        assert run.info["integration_step"] == DEFAULT_INTEGRATION_STEP
        assert np.allclose(np.diff(run.t), DEFAULT_INTEGRATION_STEP)
        assert run.t[-1] == pytest.approx(14.0)
        assert np.all(np.isfinite(run.base_displacement))
    assert all(np.isfinite(v) for v in out.J.values() if v is not None)
    assert any("interpolated linearly onto the integration step 0.005 s" in n for n in out.notes)


def test_the_result_file_states_the_time_grid(kjm_14s, nonlinear, tmp_path):
    from benchmark.simulator.results import read_result, write_result

    r = simulate(nonlinear, kjm_14s, bearing_histories=False)
    stored = read_result(write_result(r, tmp_path / "kjm.h5"))
    assert float(stored.attrs["integration_step_s"]) == 0.005 and float(stored.attrs["record_step_s"]) == 0.02
    assert stored.info["integration_step"] == 0.005 and stored.info["notes"]


def test_interpolating_inside_equals_resampling_first(kjm_14s, nonlinear):
    a = simulate(nonlinear, kjm_14s)
    b = simulate(nonlinear, resample(kjm_14s, 0.005))
    np.testing.assert_array_equal(a.base_displacement, b.base_displacement)
    assert b.info["notes"] == [] and a.info["notes"]


def test_a_step_that_does_not_converge_is_halved_and_said(kjm_14s, nonlinear):
    r = simulate(nonlinear, kjm_14s, control_step=0.02, integration_step=0.02)
    assert r.info["integration_step"] == 0.01 and r.info["integration_step_halvings"] == 1
    assert np.allclose(np.diff(r.t), 0.01)
    assert any("did not converge at t = 10.96 s with the integration step 0.02 s; ran again with 0.01 s" in n
               for n in r.info["notes"])


def test_controlled_run_and_reference_share_the_grid_after_a_halving(kjm_14s):
    building = Building.default(isolation="friction-lrb", devices="default")
    out = run_case(Case(record=kjm_14s, controller="passive-on", building=building, control_step=0.02,
                        options={"integration_step": 0.02}), cache=None)
    np.testing.assert_array_equal(out.result.t, out.reference.t)
    assert out.result.info["integration_step"] <= 0.01


def test_giving_up_names_the_options_that_help(kjm_14s, nonlinear):
    with pytest.raises(NumericalError) as info:
        simulate(nonlinear, kjm_14s, control_step=0.02, integration_step=0.02, max_halvings=0)
    err = info.value
    assert err.time == pytest.approx(10.96)
    assert "--substep-tolerance" in err.hint and "--integration-step" in err.hint


def test_bad_integration_options_are_input_errors(kjm_14s, nonlinear):
    with pytest.raises(InputError, match="integration_step"):
        simulate(nonlinear, kjm_14s, integration_step=-0.005)
    with pytest.raises(InputError, match="max_halvings"):
        simulate(nonlinear, kjm_14s, max_halvings=-1)


def test_an_integration_step_that_is_not_used_is_said():
    # --integration-step 0.01 on a 0.005-s record ran at 0.005 s without a word
    from records import Record
    record = Record("noise", 0.005, 0.3 * np.random.default_rng(3).standard_normal((201, 2)))
    building = Building.default(isolation="linear").without_devices()
    result = simulate(building, record, integration_step=0.01)
    assert result.info["integration_step"] == 0.005
    assert any("not the 0.01 s asked: the record's own step (0.005 s) is finer" in n for n in result.info["notes"])
    assert not simulate(building, record).info["notes"]
