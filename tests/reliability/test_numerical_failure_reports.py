"""Numerical failure stops the run with the time, the failing state and a hint — and writes nothing.

Failures are provoked on purpose: a record a thousand times stronger than any earthquake
(blow-up), a fixed-point iteration allowed a single pass (no convergence), a damper whose
hysteresis is far too stiff for the step (the sub-stepping cannot keep up, the state
overflows), a controller returning NaN. The Python API must raise
:class:`benchmark.foundation.errors.NumericalError` carrying ``time``, ``state`` and ``hint``; the command
line must exit with status 3 and one ``sbib: numerical failure: ...`` line, and leave no
result file behind.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmark.foundation.errors import NumericalError


def _check(exc: NumericalError, state_key: str) -> None:
    assert exc.time is not None and math.isfinite(exc.time) and exc.time > 0
    assert state_key in exc.state, exc.state
    assert exc.hint
    message = str(exc)
    assert "\n" not in message and f"t = {exc.time:.6g} s" in message and "hint:" in message


@pytest.fixture(scope="module")
def building():
    from benchmark.simulator.building import Building

    return Building.default(isolation="linear", devices="default")


def _record(scale: float, n: int = 201, seed: int = 3):
    from records import Record

    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.005
    acc = scale * np.column_stack([np.sin(2 * np.pi * 0.5 * t), 0.3 * rng.standard_normal(n)])
    return Record("absurd", 0.005, acc)


def test_blow_up_stops_with_time_state_and_hint(building):
    from benchmark.simulator.simulation import simulate

    with pytest.raises(NumericalError) as info:
        simulate(building.without_devices(), _record(1.0e4))
    _check(info.value, "u_b_x [m]")
    assert "blow-up" in str(info.value)
    assert info.value.time < 1.0  # stopped when it happened, not at the end


def test_blow_up_limit_is_the_users_choice(building):
    from benchmark.simulator.simulation import simulate

    with pytest.raises(NumericalError, match="blow-up"):
        simulate(building.without_devices(), _record(2.0), blowup_limit=1e-4)


def test_fixed_point_that_does_not_converge_is_reported(building):
    from benchmark.simulator.simulation import simulate

    nonlinear = building.with_isolation("friction-lrb").without_devices()
    with pytest.raises(NumericalError) as info:
        simulate(nonlinear, _record(8.0), max_iterations=1, fixed_point_tolerance=1e-12)
    _check(info.value, "u_b_x [m]")
    assert "did not converge" in str(info.value)


def test_device_too_stiff_for_its_sub_steps_is_reported(building):
    """A damper whose transition displacement is 1e-11 m overflows its state: NaN is caught."""
    from benchmark.simulator.simulation import simulate
    from damper import ExtendedBoucWen

    model = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=1e5, kappa_w=1e5, rho=1e11, sigma=1.0, n=3.0)
    stiff = building.with_devices(building.devices.with_model(model))
    with pytest.raises(NumericalError) as info:
        simulate(stiff, _record(3.0), controller="passive-on")
    _check(info.value, "u_b_x [m]")


def test_damper_simulate_reports_the_internal_state():
    from damper import ExtendedBoucWen, simulate

    model = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=1e5, kappa_w=1e5, rho=1e11, sigma=1.0, n=3.0)
    t = np.linspace(0.0, 1.0, 201)
    with pytest.raises(NumericalError) as info:
        simulate(model, t, 0.1 * np.sin(2 * np.pi * t))
    _check(info.value, "x")
    assert len(info.value.state) > 3  # the motion and the model's own states


def test_failed_run_returns_no_partial_result(building):
    """The exception is the only outcome: no result object with NaN or zeros after the failure."""
    from benchmark.simulator.simulation import simulate

    outcome = None
    try:
        outcome = simulate(building.without_devices(), _record(1.0e4))
    except NumericalError:
        pass
    assert outcome is None


# ---------------------------------------------------------------------------------------------
# The command line: exit status 3, one line, no result file
# ---------------------------------------------------------------------------------------------
def test_cli_run_exits_3_and_writes_nothing(tmp_path, cli, cli_error):
    rec = _record(1.0e4)
    path = tmp_path / "absurd.csv"
    from records.readers import write_csv

    write_csv(rec, path)
    out = tmp_path / "absurd.h5"
    rc, stdout, err = cli(["run", "--record", str(path), "--isolation", "linear", "--out", str(out), "--json"])
    # the record (x 1e4) is flagged implausible before the run: the blow-up is an input error whose
    # line leads with the flag and still carries the failure's time, state and hint
    line = cli_error(rc, err, status=2, prefix="sbib: error: the record is implausible: ")
    assert "t = " in line and "hint:" in line and "u_b_x" in line
    assert stdout == ""
    assert list(tmp_path.iterdir()) == [path], "a failed run left a file behind"


def test_cli_damper_test_exits_3_and_writes_nothing(tmp_path, cli, cli_error):
    out = tmp_path / "stiff.csv"
    argv = ["damper", "test", "--model", "extended_bouc_wen", "--amplitude", "0.1", "--frequency", "1",
            "--voltage", "0", "--cycles", "1", "--out", str(out)]
    for name, value in dict(kappa_x=2e5, kappa_xdot=1e5, kappa_w=1e5, rho=1e11, sigma=1.0, n=3.0).items():
        argv += ["--param", f"{name}={value}"]
    rc, _, err = cli(argv)
    line = cli_error(rc, err, status=3, prefix="sbib: numerical failure: ")
    assert "hint:" in line
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_substepping_that_cannot_meet_its_tolerance_stops_with_a_clear_error():
    """A hysteresis needing more than MAX_SUBSTEPS sub-steps per sample is a NumericalError."""
    import numpy as np

    from benchmark.foundation.errors import NumericalError
    from damper import NormalizedBoucWen, simulate

    model = NormalizedBoucWen(kappa_xdot=1.0e3, kappa_w=1.0e4, rho=1.0e9, sigma=1.0, n=1.0,
                              substep_tolerance=1.0e-3)
    t = np.linspace(0.0, 1.0, 101)
    with pytest.raises(NumericalError, match="200 000 sub-steps"):
        simulate(model, t, 0.1 * np.sin(2 * np.pi * t))
