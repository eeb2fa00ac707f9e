"""`sbib damper test` and the loop plots."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main
from damper.io.data import read_csv
from damper.lab.laboratory import periodic_test
from damper.lab.loops import last_cycles
from damper.lab.plots import plot_loops


def test_damper_test_writes_csv_and_plot(tmp_path, capsys):
    out, png = tmp_path / "virtual.csv", tmp_path / "virtual.png"
    status = main(["damper", "test", "--model", "virtual", "--amplitude", "0.05", "--frequency", "1",
                   "--voltage", "0.5", "--cycles", "2", "--out", str(out), "--plot", str(png)])
    assert status == 0
    test = read_csv(out)
    assert np.all(test.voltage == 0.5)
    assert np.max(np.abs(test.displacement)) == pytest.approx(0.05, rel=1e-6)
    assert test.time[-1] == pytest.approx(2.0)
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    assert "kN" in capsys.readouterr().out


def test_damper_test_with_parameters(tmp_path):
    out = tmp_path / "bw.csv"
    args = ["damper", "test", "--model", "extended_bouc_wen", "--amplitude", "0.01", "--frequency", "2",
            "--voltage", "0", "--cycles", "1", "--out", str(out)]
    for p in ("kappa_x=2e5", "kappa_xdot=1e5", "kappa_w=5e4", "rho=100", "sigma=1", "n=1.5"):
        args += ["--param", p]
    assert main(args) == 0
    assert np.max(np.abs(read_csv(out).force)) > 3e4


@pytest.mark.parametrize("extra, message", [
    (["--model", "virtual", "--voltage", "3"], "voltage"),
    (["--model", "virtual", "--voltage", "0", "--param", "nope=1"], "no parameter nope"),
    (["--model", "normalized_bouc_wen", "--voltage", "0"], "missing kappa_xdot"),
    (["--model", "unknown", "--voltage", "0"], "unknown name"),
    (["--model", "virtual", "--voltage", "0", "--param", "sigma=0.2"], "sigma"),
])
def test_damper_test_errors_exit_2(tmp_path, capsys, extra, message):
    args = ["damper", "test", "--amplitude", "0.01", "--frequency", "1", "--out", str(tmp_path / "x.csv")]
    assert main(args + extra) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()


def test_plot_loops_with_elastic_part(tmp_path):
    test = last_cycles(periodic_test("virtual", 0.1, 1.0, 0.0, cycles=2))
    path = plot_loops([test, test], tmp_path / "loops.png", labels=["a", "b"], kappa_x=2.07e5,
                      styles=["-", "--"])
    assert path.stat().st_size > 10_000


@pytest.mark.parametrize("model", ["dahl", "hyperbolic_tangent", "bingham"])
def test_voltage_is_rejected_for_a_model_that_does_not_depend_on_it(tmp_path, model, capsys):
    """Issue #16 item 10: the force of these defaults is the same at every voltage, so a
    --voltage must not be silently ignored; without --voltage the test runs."""
    out = tmp_path / "m.csv"
    base = ["damper", "test", "--model", model, "--amplitude", "0.01", "--frequency", "1",
            "--cycles", "1", "--out", str(out)]
    assert main(base + ["--voltage", "1"]) == 2
    err = capsys.readouterr().err
    assert "does not depend on the voltage" in err and "--voltage" in err and model in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
    assert main(base) == 0 and out.exists()
    assert main(base + ["--voltage", "0"]) == 0   # the voltage it runs at anyway


def test_voltage_is_required_for_a_model_that_depends_on_it(tmp_path, capsys):
    out = tmp_path / "v.csv"
    assert main(["damper", "test", "--model", "virtual", "--amplitude", "0.01", "--frequency", "1",
                 "--cycles", "1", "--out", str(out)]) == 2
    assert "--voltage" in capsys.readouterr().err and not out.exists()


def test_voltage_is_accepted_for_a_voltage_law(tmp_path):
    """A model whose parameters are voltage laws responds to --voltage (API-built model)."""
    from damper.models.bingham import Bingham
    from benchmark.applications.cli_damper import check_voltage_effect
    from damper.models.voltage_laws import Polynomial

    model = Bingham(f_c=Polynomial((500.0, 300.0)), c0=5.0e3, f0=0.0)
    check_voltage_effect(model, "bingham", 1.0)          # no error
    with pytest.raises(Exception, match="does not depend on the voltage"):
        check_voltage_effect(Bingham(f_c=500.0, c0=5.0e3, f0=0.0), "bingham", 1.0)


def test_param_takes_a_pair_for_the_voltage_range(tmp_path, capsys):
    """`--param` lists voltage_range among a model's parameters: a pair is given as 0,3."""
    from benchmark.applications.cli import main
    out = tmp_path / "vr.csv"
    assert main(["damper", "test", "--model", "virtual", "--amplitude", "0.05", "--frequency", "1",
                 "--voltage", "2.5", "--param", "voltage_range=0,3", "--out", str(out)]) == 0
    assert out.exists()
    assert main(["damper", "test", "--model", "virtual", "--amplitude", "0.05", "--frequency", "1",
                 "--voltage", "2.5", "--out", str(out)]) == 2       # outside the default range
    assert "voltage" in capsys.readouterr().err
