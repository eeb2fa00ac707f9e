"""The residual loop on data with changing voltage: coarse pass, random-voltage protocol, Dyke reader."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import DataNotFoundError, InputError
from damper.diagnosis import DiagnosisData, diagnose
from damper.diagnosis.augmented import AugmentedModel
from damper.diagnosis.coarse import COARSE_SUBSTEP_SCALE, Progress, decimate, decimation_factor
from damper.models.base import with_coarser_substeps
from damper.models.series_dashpot import SpencerBoucWen
from damper.lab.protocols import random_motion, random_voltage, random_voltage_test, smooth_ramp
from damper.io.data import DamperTest
from damper.io.dyke import is_dyke_file, read_dyke

DYKE = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"


def test_random_voltage_protocol_switches_and_is_reproducible():
    a = random_voltage_test("virtual", duration=6.0, sample_rate=500.0, seed=3)
    b = random_voltage_test("virtual", duration=6.0, sample_rate=500.0, seed=3)
    np.testing.assert_array_equal(a.force, b.force)
    switches = np.count_nonzero(np.diff(a.voltage))
    assert 8 <= switches <= 40  # mean hold 0.3 s over 6 s
    assert 0.0 <= a.voltage.min() and a.voltage.max() <= 1.0
    assert np.sqrt(np.mean(a.displacement ** 2)) == pytest.approx(0.01, rel=1e-6)
    assert abs(a.displacement[0]) < 1e-12  # starts from rest
    with pytest.raises(InputError, match="band"):
        random_voltage_test("virtual", band=(1.0, 100.0), sample_rate=500.0)


def test_random_voltage_levels_hold_times():
    t = np.arange(0, 200.0, 0.001)
    v = random_voltage(t, (0.0, 1.0), 0.5, np.random.default_rng(0))
    n = np.count_nonzero(np.diff(v)) + 1
    assert 200.0 / n == pytest.approx(0.5, rel=0.15)


@pytest.mark.parametrize("spacing", ["stratified", "log-uniform"])
def test_random_motion_velocity_is_the_derivative_of_the_displacement(spacing):
    """The velocity is exact (analytic, ramp included): a 4th-order central difference of the
    displacement on a 0.1 ms grid agrees to its own truncation error. The smoothstep window is
    only C1 at the ramp's ends, where the difference is O(h) wrong in the second derivative:
    about 3e-6 of the peak velocity here; a velocity from a wrong ramp derivative is off by 1e-2."""
    t = np.arange(0.0, 6.0, 1e-4)
    x, xd = random_motion(t, 0.02, (0.2, 4.0), np.random.default_rng(1), components=12, spacing=spacing, ramp=1.0)
    h = t[1] - t[0]
    fd = (-x[4:] + 8 * x[3:-1] - 8 * x[1:-3] + x[:-4]) / (12 * h)
    assert np.max(np.abs(fd - xd[2:-2])) <= 1e-5 * np.max(np.abs(xd))
    assert x[0] == 0.0 and xd[0] == 0.0  # from rest
    assert np.sqrt(np.mean(x ** 2)) == pytest.approx(0.02, rel=1e-12)
    w, dw = smooth_ramp(np.array([0.0, 0.5, 1.0, 2.0]), 1.0)
    np.testing.assert_allclose(w, [0.0, 0.5, 1.0, 1.0])
    np.testing.assert_allclose(dw, [0.0, 1.5, 0.0, 0.0])


def test_random_voltage_between_given_levels_holds_within_the_range():
    t = np.arange(0.0, 60.0, 0.001)
    levels = (0.0, 0.5, 1.0)
    v = random_voltage(t, levels, (0.05, 0.3), np.random.default_rng(3))
    assert set(np.unique(v)) <= set(levels)
    jumps = np.flatnonzero(np.diff(v)) + 1
    holds = np.diff(t[jumps])
    assert holds.min() >= 0.05 - 1e-3 and holds.max() <= 0.3 + 1e-3  # each hold drawn in the range
    assert np.all(v[jumps] != v[jumps - 1])  # every switch goes to another level
    with pytest.raises(InputError, match="hold"):
        random_voltage(t, levels, (0.3, 0.05), np.random.default_rng(3))


def test_decimation_keeps_levels_nodes_and_enough_samples_per_period():
    test = random_voltage_test("virtual", duration=20.0, sample_rate=1000.0, seed=2)
    data = DiagnosisData.from_tests([test])
    q = decimation_factor(data, 3000)
    assert q > 1
    coarse = decimate(data, q)
    assert sum(k.sum() for k in coarse.train) <= 3000 * 1.01
    np.testing.assert_array_equal(coarse.nodes(), data.nodes())
    assert coarse.voltage_range() == data.voltage_range()
    assert decimation_factor(data, None) == 1
    assert decimate(data, 1) is data
    # a slow cap never decimates below 100 samples per period of a fast motion
    assert decimation_factor(data, 100) <= q * 100
    with pytest.raises(InputError, match="coarse_samples"):
        decimation_factor(data, 5)


def test_a_command_written_with_many_digits_lies_within_its_own_range():
    """A command with more than 9 decimals (a uniform random level, a MATLAB export at %.15g):
    the levels were rounded to 1e-9, so the largest one lay below the input's maximum, and the
    fitted base refused the test it was fitted on ("expected voltages in [0, 1.99685] V ... got
    1.99685 V")."""
    t = np.arange(0.0, 20.0, 1e-3)
    rng = np.random.default_rng(3)
    x, xd = random_motion(t, 0.01, (0.3, 8.0), rng, components=12, ramp=1.0)
    v = 1.9968512345 * random_voltage(t, (0.0, 1.0), 0.05, rng)
    v[v.argmax()] = 1.9968512345  # rounds down to 1.996851234: below the maximum
    v[v.argmin()] = -0.1234567894  # rounds up to -0.123456789: above the minimum
    test = DamperTest(time=t, displacement=x, velocity=xd, force=800.0 * np.tanh(xd / 0.01), voltage=v,
                      name="digits")
    data = DiagnosisData.from_tests([test])
    assert data.levels()[-1] == v.max() and data.levels()[0] == v.min()
    assert data.voltage_range() == (v.min(), v.max())
    # one level standing for values spread below its rounding: the range still holds them all
    flat = DamperTest(time=t, displacement=x, velocity=xd, force=800.0 * np.tanh(xd / 0.01),
                      voltage=np.where(np.arange(t.size) == 500, 2.0 + 5e-11, 2.0), name="flat")
    lo, hi = DiagnosisData.from_tests([flat]).voltage_range()
    assert lo <= 2.0 and hi >= 2.0 + 5e-11
    coarse = decimate(data, decimation_factor(data, 3000))
    assert coarse.voltage_range() == data.voltage_range()
    d = diagnose([test], model="normalized", holdout=0.3, candidates=["offset"])
    assert np.isfinite(d.error_after)


def test_coarser_substeps_changes_only_the_tolerance():
    m = SpencerBoucWen(2000.0, 900.0, 800.0, 600.0, 2.0e4, 1.0e4, 0.7, 1.1, field_lag=0.007,
                       voltage_range=(0.0, 2.0))
    c = with_coarser_substeps(m, 3.0)
    assert c.substep_tolerance == pytest.approx(3.0 * m.substep_tolerance) and m.substep_tolerance == 0.25
    assert type(c) is type(m) and c.rho == m.rho and c.c1 is m.c1 and c.voltage_range == m.voltage_range
    assert with_coarser_substeps(m, 10.0).substep_tolerance == 1.0  # the kernels' cap
    assert with_coarser_substeps(m, 1.0) is m
    assert with_coarser_substeps(object, 4.0) is object  # nothing to coarsen: as it is


def test_coarse_pass_simulates_at_a_coarser_tolerance_within_its_error():
    """The decimated motions carry the coarse sub-step scale; on a stiff Spencer-type model (rho
    1e4 1/m, the Dyke fit's) the force moves by the O(tol**4) RK4 error only: well below 1e-3 of
    its RMS, the residual the loop works on being ~0.1; at scale 1 it is the model's own force."""
    test = random_voltage_test("virtual", duration=6.0, sample_rate=1000.0, seed=2)
    data = DiagnosisData.from_tests([test])
    coarse = decimate(data, 4)
    assert all(m.substep_scale == COARSE_SUBSTEP_SCALE for m in coarse.motions)
    assert all(m.substep_scale == 1.0 for m in data.motions)
    lo, hi = data.voltage_range()
    model = AugmentedModel(SpencerBoucWen(2000.0, 900.0, 800.0, 600.0, 2.0e4, 1.0e4, 0.7, 1.1,
                                          field_lag=0.007, voltage_range=(lo, hi)))
    m = coarse.motions[0]
    fine = type(m)(m.t, m.x, m.xdot, m.xddot, m.v, name=m.name)
    f_coarse, f_fine = model.force(m), model.force(fine)
    diff = np.linalg.norm(f_coarse - f_fine) / np.linalg.norm(f_fine)
    assert 0.0 < diff < 1e-3
    with pytest.raises(InputError, match="substep_scale"):
        type(m)(m.t, m.x, m.xdot, m.xddot, m.v, substep_scale=0.5)


@pytest.mark.slow
def test_loop_on_random_voltage_finds_lag_and_roll_off_and_reports_progress():
    """The virtual damper has a 33 ms field lag and a low-velocity roll-off (Spencer's c1)."""
    test = random_voltage_test("virtual", duration=12.0, sample_rate=1000.0, seed=4)
    lines = []
    d = diagnose([test], progress=lines.append)
    assert {"voltage_lag", "roll_off"} <= set(d.effects)
    assert d.error_after < 0.5 * d.error_before
    assert d.final_model.effect("voltage_lag").tau == pytest.approx(1 / 30, rel=0.3)
    assert any("coarse pass" in s for s in lines) and all(s.startswith("[") for s in lines)
    assert d.settings["decimation"] > 1


def test_progress_prints_one_line_per_step(capsys):
    p = Progress()
    p("a step")
    p("another")
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and err[0].endswith("a step")
    Progress(quiet=True)("nothing")
    assert capsys.readouterr().err == ""


def test_dyke_reader_converts_to_si(tmp_path):
    path = tmp_path / "dyke.csv"
    path.write_text('"t","A","D","Y","fs","V","F",\n0,1,-0.5,2.0,3000,10,-100,\n'
                    '0.001,1,-0.4,2.0,,11,-90,\n0.002,1,-0.3,1.5,,12,-80,\n')
    assert is_dyke_file(path)
    t = read_dyke(path)
    np.testing.assert_allclose(t.displacement, [-0.005, -0.004, -0.003])
    np.testing.assert_allclose(t.velocity, [0.10, 0.11, 0.12])
    np.testing.assert_allclose(t.force, [-100, -90, -80])
    np.testing.assert_allclose(t.voltage, [2.0, 2.0, 1.5])


def test_dyke_reader_refuses_malformed_files(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text('"t","D","Y","V"\n0,1,2,3\n')
    with pytest.raises(InputError, match="missing column"):
        read_dyke(bad)
    bad.write_text('"t","D","Y","V","F"\n0,1,2,3,4\n0.1,1,x,3,4\n')
    with pytest.raises(InputError, match=r":3: column 'Y'"):
        read_dyke(bad)
    bad.write_text('"t","D","Y","V","F"\n0,1,2,3,4\n0,1,2,3,4\n')
    with pytest.raises(InputError, match="increasing"):
        read_dyke(bad)
    with pytest.raises(DataNotFoundError):
        read_dyke(tmp_path / "missing.csv")


def test_real_dyke_record(shared_dir):
    path = shared_dir / DYKE
    if not path.is_file():
        pytest.skip(f"{path} not found")
    t = read_dyke(path)
    assert t.n_samples == 60096
    assert t.sample_rate == pytest.approx(3004.8, rel=1e-3)
    assert 0.005 < np.ptp(t.displacement) < 0.05  # about +-1 cm, in metres
    assert np.ptp(t.voltage) > 2.0


def test_cli_reads_dyke_and_refuses_a_tiny_coarse_pass(tmp_path, capsys):
    path = tmp_path / "dyke.csv"
    # enough samples to pass the readers' floor (damper.io.reader.MIN_SAMPLES): the option is what fails
    path.write_text('"t","D","Y","V","F"\n' + "".join(f"{0.001 * k},{0.1 * (k % 4)},0,1,{5 * (k % 3)}\n"
                                                    for k in range(12)))
    assert main(["diagnose", "--data", str(path), "--coarse-samples", "-3"]) == 2
    assert "--coarse-samples" in capsys.readouterr().err


def test_dyke_reader_rejects_non_utf8_bytes_in_one_line(tmp_path):
    from benchmark.foundation.errors import InputError
    from damper.io.dyke import read_dyke

    bad = tmp_path / "dyke.csv"
    bad.write_bytes(b"t,D,Y,V,F\n0,0.1,1,2,3\n0.001,\xff\xfe,1,2,3\n")
    with pytest.raises(InputError, match="not UTF-8") as info:
        read_dyke(bad)
    assert "\n" not in str(info.value)


class _Chosen(Exception):
    pass


@pytest.mark.parametrize("varying, expected", [(True, "spencer"), (False, "normalized")])
def test_auto_base_model_follows_the_coil_input(monkeypatch, varying, expected):
    """``model="auto"`` (the CLI's default) takes the Spencer-type base, whose field lag is
    inside it, when the command changes within a test, and the normalized one otherwise."""
    import damper.diagnosis.loop as loop
    from damper.lab.laboratory import periodic_test

    def stop(kind):
        def fit(*args, **kwargs):
            raise _Chosen(kind)
        return fit

    monkeypatch.setattr(loop, "fit_spencer_base", stop("spencer"))
    monkeypatch.setattr(loop, "fit_base", stop("normalized"))
    test = (random_voltage_test("virtual", duration=4.0, sample_rate=500.0, seed=1) if varying
            else periodic_test("virtual", amplitude=0.02, frequency=1.0, voltage=0.5, cycles=3,
                               sample_rate=200.0))
    with pytest.raises(_Chosen, match=expected):
        diagnose([test], model="auto")
    with pytest.raises(InputError, match="model: expected one of"):
        diagnose([test], model="bouc")


def test_cli_says_which_base_a_changing_command_calls_for(tmp_path, capsys):
    """With the normalized base on a random-voltage test, stdout itself (not only the progress
    lines, which --quiet silences) names the Spencer-type base; a constant command does not."""
    from damper.io.data import write_csv
    from damper.lab.laboratory import periodic_test

    changing = random_voltage_test("virtual", duration=4.0, sample_rate=500.0, seed=1)
    constant = periodic_test("virtual", amplitude=0.02, frequency=1.0, voltage=0.5, cycles=5, sample_rate=200.0)
    for test, hinted in ((changing, True), (constant, False)):
        path = tmp_path / f"{hinted}.csv"
        write_csv(test, path)
        assert main(["diagnose", "--data", str(path), "--model", "normalized", "--effects", "offset",
                     "--quiet"]) == 0
        model_line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("model:")][0]
        assert ("--model spencer" in model_line) is hinted
