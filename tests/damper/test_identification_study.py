"""Voltage grid and laws, field lag, validation helpers, isolation from the virtual damper, CLI."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.models.bouc_wen import ExtendedBoucWen
from benchmark.applications.identification_validation import replay, run_errors
from damper.identification.voltage_grid import TestProtocol, fit_voltage_laws, identify_voltage_grid
from damper.identification.voltage_lag import filtered_force, fit_voltage_lag
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial

IDENT_DIR = Path(__file__).resolve().parents[2] / "damper" / "identification"


def test_no_identification_module_imports_the_virtual_damper():
    """Identification reaches the virtual damper only through damper.lab.laboratory (injected device)."""
    offenders = []
    apps = IDENT_DIR.parents[1] / "benchmark" / "applications"
    for path in sorted(IDENT_DIR.glob("*.py")) + [apps / "cli_identify.py", apps / "identification_study.py",
                                                 apps / "identification_validation.py"]:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                mod = node.module or ""
                names = [mod] + [f"{mod}.{a.name}" for a in node.names]
            if any(n == "damper.models.virtual" or n.startswith("damper.models.virtual.") for n in names):
                offenders.append(f"{path.name}:{node.lineno}")
        text = path.read_text(encoding="utf-8")
        assert "VirtualBenchmarkDamper" not in text, path.name
        assert "importlib" not in text, path.name  # no back door around the scan
    assert not offenders, offenders


def test_seed_laws_recover_their_own_coefficients_and_generic_law_interpolates():
    # Region boundaries 0.3 and 0.7 V left out: there the seed's law fits both neighbouring
    # regions to the same point, which a law discontinuous by construction cannot match.
    v = np.array([x for x in np.round(np.linspace(0, 1, 21), 10) if x not in (0.3, 0.7)])
    kw = np.where(v <= 0.3, 5e4 + 4e5 * v ** 1.15,
                  np.where(v <= 0.7, 2e5 + 3e5 * np.sin(np.pi * (v - 0.3) / 0.8)
                           + 2e4 * np.sin(3 * np.pi * (v - 0.3) / 0.8),
                           1e5 + 5e5 * v + 1e5 * v ** 3 + 2e5 * v ** 5))
    table = np.column_stack([np.full(v.size, 2.07e5), 1e5 + 1.5e5 * v, kw, 100 + 20 * np.exp(-14 * v),
                             1.4 - 0.3 * np.exp(-14 * v), 1.5 + 0.2 * np.exp(-13 * v)])
    laws = fit_voltage_laws(v, table)
    for name, fit in laws["seed"].items():
        assert fit.rms_error < 1e-8, name
    assert laws["seed"]["kappa_xdot"].coefficients == pytest.approx([1e5, 1.5e5])
    assert laws["seed"]["rho"].coefficients[:2] == pytest.approx([100, 20])
    for name, fit in laws["generic"].items():
        assert fit.law(v) == pytest.approx(table[:, list(laws["generic"]).index(name)], rel=1e-9)
    with pytest.raises(InputError):
        fit_voltage_laws(v[:2], table[:2])


def test_voltage_grid_recovers_a_known_voltage_dependent_device():
    device = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 1e5)),
                             kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.4)
    grid = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("extended",),
                                 protocol=TestProtocol(cycles=3, sample_rate=500.0))
    table = grid.table("extended")
    for k, v in enumerate((0.0, 0.5, 1.0)):
        truth = device.coefficients(v)
        for j, name in enumerate(("kappa_x", "kappa_xdot", "kappa_w", "rho", "sigma", "n")):
            assert table[k, j] == pytest.approx(truth[name], rel=0.01), (v, name)
    assert grid.laws["extended"]["seed"]["kappa_xdot"].rms_error < 0.01
    model = grid.models["extended"]["generic"]
    assert model.coefficients(0.5)["kappa_w"] == pytest.approx(5e4 + 4.5e5, rel=0.01)
    assert {r["model"] for r in grid.rows()} == {"extended"}
    # a device inside the search's bounds: nothing at a bound (the column names them, as the
    # --data path does: the virtual path had said nothing of n at its lower bound 1)
    assert all(r["at_bounds"] == "" for r in grid.rows())


def test_kappa_x_is_read_once_from_the_large_loop_and_held_over_the_grid():
    """Seed step (a) and eq. 5: one kappa_x for every voltage; the variants are options."""
    from damper.identification.voltage_grid import estimate_kappa_x
    device = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 1e5)),
                             kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.4)
    estimate, test = estimate_kappa_x(device)
    assert estimate.mode == "large-loop" and estimate.protocol["amplitude"] == 0.4
    assert estimate.value == pytest.approx(2e5, rel=0.02)  # the loop's average inclination
    protocol = TestProtocol(cycles=3, sample_rate=500.0)
    grid = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("extended",), protocol=protocol)
    table = grid.table("extended")
    assert np.all(table[:, 0] == estimate.value)
    assert {r["kappa_x_mode"] for r in grid.rows()} == {"large-loop"}
    assert all("kappa_x" not in i.fit.free for i in grid.identifications["extended"])
    assert grid.laws["extended"]["seed"]["kappa_x"].rms_error < 1e-12
    assert grid.laws_json()["kappa_x"]["value"] == estimate.value
    given = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("extended",), protocol=protocol,
                                  kappa_x=1.9e5)
    assert np.all(given.table("extended")[:, 0] == 1.9e5) and given.kappa_x.mode == "given"
    free = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("extended",), protocol=protocol,
                                 kappa_x="per-voltage")
    assert free.kappa_x.mode == "per-voltage"
    assert all("kappa_x" in i.fit.free for i in free.identifications["extended"])
    with pytest.raises(InputError, match="kappa_x"):
        identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), kappa_x="sometimes")


def test_joint_kappa_x_and_a_pool_give_the_same_grid_as_one_process():
    device = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 1e5)),
                             kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.4)
    protocol = TestProtocol(cycles=3, sample_rate=400.0)
    one = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("normalized", "extended"),
                                protocol=protocol, kappa_x="joint", jobs=1)
    two = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("normalized", "extended"),
                                protocol=protocol, kappa_x="joint", jobs=2)
    assert one.kappa_x.mode == "joint"
    assert one.kappa_x.value == pytest.approx(2e5, rel=0.01)
    np.testing.assert_array_equal(one.table("extended"), two.table("extended"))
    np.testing.assert_array_equal(one.table("normalized"), two.table("normalized"))
    assert one.kappa_x.value == two.kappa_x.value


def test_worker_count_rejects_bad_jobs():
    from benchmark.foundation.pools import run_tasks, worker_count
    assert worker_count(1) == 1 and worker_count(8, n_tasks=3) == 3 and worker_count(None) >= 1
    for bad in (-1, 1.5, "2", True):
        with pytest.raises(InputError, match="jobs"):
            worker_count(bad)
    assert run_tasks(pow, [(2, 3), (3, 2)]) == [8, 9]


def test_cli_identify_rejects_a_bad_kappa_x(capsys):
    from benchmark.applications.cli import main
    assert main(["identify", "--kappa-x", "often", "--no-validation", "--no-plots"]) == 2
    assert "--kappa-x" in capsys.readouterr().err


def test_field_lag_is_recovered_from_a_switching_test():
    model = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 1e5)),
                            kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.4)
    t = np.arange(0, 3.0, 1e-3)
    x = 0.1 * np.sin(np.pi * t)
    xd = 0.1 * np.pi * np.cos(np.pi * t)
    v = np.where(np.mod(t, 0.4) < 0.2, 0.0, 1.0)
    from damper.io.data import DamperTest
    force = filtered_force(model, t, x, xd, v, tau=0.03)
    fit = fit_voltage_lag(model, DamperTest(time=t, displacement=x, velocity=xd, force=force, voltage=v,
                                            name="switching"))
    assert fit.tau == pytest.approx(0.03, rel=0.01)
    assert fit.rel_rms_error < 1e-3 < fit.rel_rms_error_without_lag


def test_replay_and_run_errors():
    model = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=1e5, kappa_w=1e5, rho=120.0, sigma=0.9, n=1.4)
    t = np.arange(0, 2.0, 5e-3)
    x = np.column_stack([0.05 * np.sin(2 * np.pi * t), 0.03 * np.sin(3 * t)])
    xd = np.gradient(x, t, axis=0)
    v = np.zeros_like(x)
    f = replay(model, t, x, xd, v)
    assert f[:, 1] == pytest.approx(simulate(model, t, x[:, 1], xd[:, 1], 0.0).force)
    e = run_errors(f, 0.9 * f, x)
    assert e["rel_rms_error"] == pytest.approx(0.1)
    assert e["peak_error"] == pytest.approx(0.1)
    assert e["energy_error"] == pytest.approx(0.1, rel=1e-6)


def test_cli_identify_data_on_utfsm_files(shared_dir, tmp_path, capsys):
    from benchmark.applications.cli import main
    folder = shared_dir / "hysteresis_data" / "quiroz_utfsm_mr_damper_sinusoidal" / "Preprocesados"
    files = [str(folder / "25mm0x25Hz1A.txt"), str(folder / "25mm0x1Hz1A.txt")]
    status = main(["identify", "--data", *files, "--model", "extended", "--bootstrap", "0",
                   "--out", str(tmp_path), "--json"])
    assert status == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["tests"]) == 2
    for s in out["tests"]:
        assert set(s["parameters"]) == {"kappa_x", "kappa_xdot", "kappa_w", "rho", "sigma", "n"}
        assert s["level"] == 1.0 and s["level_unit"] == "A"
        assert s["errors"]["rel_rms_error"] < 0.15
        assert len(s["held_out"]) == 1  # the other amplitude/frequency at 1 A
    assert (tmp_path / "fit_25mm0x25Hz1A_extended.png").is_file()


def test_cli_identify_rejects_a_missing_file(tmp_path, capsys):
    from benchmark.applications.cli import main
    assert main(["identify", "--data", str(tmp_path / "absent.csv")]) == 2
    assert "absent.csv" in capsys.readouterr().err


@pytest.mark.slow
def test_identify_study_one_run(records_dir, tmp_path):
    from benchmark.applications.identification_study import run_identify_study
    summary = run_identify_study(tmp_path, records=["kobe"], orientations=["FP-x"], progress=False)
    for name in ("parameters.csv", "voltage_laws.json", "validation.json", "identification.h5"):
        assert (tmp_path / name).is_file()
    val = json.loads((tmp_path / "validation.json").read_text())
    errors = val["errors"]["kobe"]["FP-x"]
    assert set(errors) >= {"normalized", "extended", "normalized+lag", "extended+lag"}
    assert set(errors["extended"]) == {"rel_rms_error", "peak_error", "energy_error"}
    assert summary["field_lag"]["extended"]["tau"] > 0
    assert any(p.endswith("fig11_force_errors_kobe_FP-x.png") for p in summary["files"]["figures"])
    for p in summary["files"]["figures"]:
        assert Path(p).is_file(), p
    # kappa_x read once (seed step a) and held over the grid; the per-voltage variant reported too.
    kx = summary["kappa_x"]
    assert kx["mode"] == "large-loop" and kx["value"] > 0
    assert {p["kappa_x"] for p in summary["parameters"]["extended"].values()} == {kx["value"]}
    assert len({p["kappa_x"] for p in summary["parameters"]["extended-free-kx"].values()}) > 1
    assert {"extended-free-kx", "extended-free-kx+lag", "extended-free-kx-pchip"} <= set(errors)
    assert "extended_below_normalized_every_run" in val["summary"]
    assert val["J"]["kobe"]["FP-x"]["extended"]["J1"] > 0
    # errors split by field regime, and the structural ceiling on the run's damper motion
    regimes = val["regimes"]["kobe"]["FP-x"]["extended+lag"]
    assert set(regimes) == {"low", "high", "transition"}
    assert sum(r["sample_share"] for r in regimes.values()) == pytest.approx(1.0)
    ceiling = json.loads((tmp_path / "ceiling.json").read_text())
    assert {(e["voltage"], e["model"]) for e in ceiling["entries"]} == {
        (0.0, "normalized"), (0.0, "extended"), (1.0, "normalized"), (1.0, "extended")}
    best = {(e["voltage"], e["model"]): e["best_error"] for e in ceiling["entries"]}
    assert best[(0.0, "extended")] < 0.5 * best[(0.0, "normalized")]  # the elastic term at 0 V
    assert summary["ceiling"]["1 V"]["extended"]["n_motions"] == 1
    assert any(p.endswith("fig11_error_anatomy.png") for p in summary["files"]["figures"])


def test_a_parameter_at_its_bound_is_named_in_the_rows():
    # a device with n = 1 exactly, the normalized model's lower bound: the fit lands on it
    from damper.identification.voltage_grid import TestProtocol, identify_voltage_grid
    device = ExtendedBoucWen(kappa_x=0.0, kappa_xdot=Polynomial((1e5, 1e5)),
                             kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.0)
    grid = identify_voltage_grid(device, voltages=(0.0, 0.5, 1.0), models=("normalized",),
                                 protocol=TestProtocol(cycles=3, sample_rate=500.0))
    assert any("n lower 1" in r["at_bounds"] for r in grid.rows()), [r["at_bounds"] for r in grid.rows()]
