"""Own record files from the command line (issue #16, items 1-3, 5 and 6).

A PEER ``.AT2`` file at dt = 0.01 s, a single-column file in g, a CSV in cm/s² read as m/s²,
the seed paper's orientation names and synthetic records: each through the Python API and the
``sbib`` commands that take a record.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmark.applications.cli import build_parser, main
from benchmark.foundation.errors import InputError
from records import STANDARD_GRAVITY, Record

G = STANDARD_GRAVITY
FAST = ["--isolation", "linear", "--n-modes", "3"]


@pytest.fixture(scope="module")
def kobe_files(tmp_path_factory, records_dir):
    """8 s of kobe's strong motion (4-12 s) at dt = 0.01 s as a PEER .AT2 file (g), a single-column file (g),
    and a CSV whose values are cm/s² but which says nothing about units (read as m/s²)."""
    from records import load_benchmark_record

    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    acc = rec.acceleration[800:2400:2]  # dt 0.01 s, 8 s, PGA 0.84 g
    d = tmp_path_factory.mktemp("own")
    at2 = d / "KJM000.AT2"
    values = acc[:, 0] / G
    body = "\n".join("  ".join(f"{v: .7E}" for v in values[i:i + 5]) for i in range(0, values.size, 5))
    at2.write_text("PEER NGA STRONG MOTION DATABASE RECORD\nKOBE 01/16/95 2046, KJMA, 000\n"
                   "ACCELERATION TIME HISTORY IN UNITS OF G\n"
                   f"NPTS=  {values.size}, DT=   .0100 SEC\n{body}\n", encoding="utf-8")
    single = d / "kobe_g.txt"
    single.write_text("\n".join(f"{v:.7e}" for v in values) + "\n", encoding="utf-8")
    cm = d / "kobe_cm.csv"
    t = np.arange(acc.shape[0]) * 0.01
    cm.write_text("time,ax,ay\n" + "\n".join(f"{ti:.2f},{100 * a:.4f},{100 * b:.4f}"
                                             for ti, (a, b) in zip(t, acc)) + "\n", encoding="utf-8")
    return {"at2": at2, "single": single, "cm": cm, "acc": acc}


def _run(capsys, argv):
    status = main(argv)
    out, err = capsys.readouterr()
    return status, out, err


def _run_json(capsys, *args):
    status, out, err = _run(capsys, ["run", *args, "--json"])
    assert status == 0, err
    return json.loads(out), err


# --------------------------------------------------------------------------- item 1: control step
def test_at2_at_dt_001_runs_without_controller(capsys, kobe_files):
    s, _ = _run_json(capsys, "--record", str(kobe_files["at2"]), "--controller", "none", *FAST)
    assert s["peaks"]["peak_base_displacement"] > 0


def test_the_integration_step_does_not_come_from_the_record(kobe_files):
    # issue 22: a record at 0.01 s is interpolated onto the building's 0.005 s; a control step
    # that does not fit that step makes the simulator take one that divides it
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import load_record

    rec = load_record(kobe_files["at2"])
    building = Building.default(isolation="linear", n_modes=3)
    a = simulate(building, rec, controller=None, control_step=0.005)
    b = simulate(building, rec, controller=None, control_step=0.01)
    c = simulate(building, rec, controller="none", control_step=0.0073)
    assert a.info["integration_step"] == b.info["integration_step"] == 0.005 and a.info["record_step"] == 0.01
    assert np.array_equal(a.base_displacement, b.base_displacement)
    assert c.info["integration_step"] == pytest.approx(0.00365)
    # the same piecewise-linear ground motion on another grid (0.005 s holds every breakpoint of the
    # record's samples, 0.00365 s does not): the exact linear step leaves only that difference
    peak = np.max(np.abs(b.base_displacement[:, 0]))
    assert np.max(np.abs(c.base_displacement[:, 0])) == pytest.approx(peak, rel=5e-4)  # 5e-5 measured


def test_with_a_controller_the_benchmark_control_step_runs_and_the_grid_is_said(capsys, kobe_files):
    s, err = _run_json(capsys, "--record", str(kobe_files["at2"]), "--controller", "passive-on", *FAST)
    assert s["control_step_s"] == pytest.approx(0.005)
    assert s["record_step_s"] == pytest.approx(0.01) and s["integration_step_s"] == pytest.approx(0.005)
    assert "interpolated linearly onto the integration step 0.005 s" in err
    assert s["peaks"]["peak_device_force"] > 0


def test_a_control_step_that_is_not_a_time_names_the_option(capsys, kobe_files):
    status, out, err = _run(capsys, ["run", "--record", str(kobe_files["at2"]), "--controller", "passive-on",
                                     "--control-step", "-0.005", *FAST])
    assert status == 2 and out == ""
    assert "--control-step" in err and len(err.strip().splitlines()) == 1


def test_simulate_runs_a_record_at_0_01_s_with_the_benchmark_control_step(kobe_files):
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import load_record

    rec = load_record(kobe_files["at2"])
    building = Building.default(isolation="linear", n_modes=3, devices="default")
    r = simulate(building, rec, controller="passive-on", control_step=0.005)
    assert r.info["integration_step"] == 0.005 and r.t[-1] == pytest.approx((rec.n_samples - 1) * rec.dt)


# --------------------------------------------------------------------------- item 2: record options
RECORD_OPTIONS = {"dt", "units", "format", "records_dir", "baseline_correct"}


def _subparser(parser, *names):
    for name in names:
        action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
        parser = action.choices[name]
    return parser


@pytest.mark.parametrize("command", [("run",), ("compare",), ("records", "show")])
def test_every_command_taking_a_record_has_the_same_record_options(command):
    parser = _subparser(build_parser(), *command)
    dests = {a.dest for a in parser._actions}
    assert RECORD_OPTIONS <= dests, RECORD_OPTIONS - dests
    assert dests & {"orientation", "orientations"}  # compare runs several: --orientations


def test_single_column_file_in_g_runs_from_the_command_line(capsys, kobe_files):
    s, err = _run_json(capsys, "--record", str(kobe_files["single"]), "--dt", "0.01", "--units", "g",
                       "--controller", "none", *FAST)
    by_at2, _ = _run_json(capsys, "--record", str(kobe_files["at2"]), "--controller", "none", *FAST)
    assert s["peaks"]["peak_base_displacement"] == pytest.approx(by_at2["peaks"]["peak_base_displacement"],
                                                                 rel=1e-6)
    assert s["units_assumed"].startswith("g")


def test_single_column_without_dt_names_the_option(capsys, kobe_files):
    status, _, err = _run(capsys, ["run", "--record", str(kobe_files["single"]), *FAST])
    assert status == 2 and "--dt" in err


def test_compare_takes_record_files(capsys, kobe_files):
    status, out, err = _run(capsys, ["compare", "--records", f"{kobe_files['single']},{kobe_files['at2']},kobe",
                                     "--dt", "0.01", "--units", "g", "--orientations", "FN-x",
                                     "--controllers", "passive-on", "--jobs", "1", "--no-progress", "--json",
                                     *FAST])
    assert status == 0, err
    runs = json.loads(out)["runs"]
    assert [r["record"] for r in runs] == ["kobe_g", "KJM000", "kobe"]  # --dt/--units apply to files only
    assert runs[0]["J"] == pytest.approx(runs[1]["J"], rel=1e-6)


def test_resolver_takes_names_and_files(records_dir, kobe_files):
    from records.resolve import resolve_record

    by_name = resolve_record("kobe", "FP-x", records_dir=records_dir)
    assert by_name.metadata["orientation"] == "FP-x" and by_name.n_components == 2
    one = resolve_record(str(kobe_files["single"]), "FP-x", dt=0.01, units="g")
    assert np.all(one.acceleration[:, 0] == 0) and one.pga[1] > 0  # one component: FP-x puts it on y


# --------------------------------------------------------------------------- item 3: implausible records
def test_wrong_units_are_flagged_and_warned(capsys, kobe_files):
    from records import check_record, load_record

    rec = load_record(kobe_files["cm"])  # cm/s² read as m/s²: PGA about 84 g
    kinds = {f.kind for f in check_record(rec)}
    assert "implausible_pga" in kinds and "implausible_displacement" in kinds
    status, out, err = _run(capsys, ["records", "show", str(kobe_files["cm"])])
    assert status == 0 and "flaws: none found" not in out and "implausible" in out
    assert "units" in out and "m/s2" in out
    s, err = _run_json(capsys, "--record", str(kobe_files["cm"]), "--controller", "none", *FAST)
    assert "warning" in err and "implausible" in err
    assert s["units_assumed"].startswith("m/s2") and s["record_flaws"]
    status, out, err = _run(capsys, ["compare", "--records", str(kobe_files["cm"]), "--orientations", "FN-x",
                                     "--controllers", "passive-off", "--jobs", "1", "--no-progress", *FAST])
    assert status == 0 and "implausible" in err


def test_right_units_give_no_plausibility_flaw(kobe_files):
    from records import check_record, load_record

    rec = load_record(kobe_files["cm"], units="cm/s2")
    assert not [f for f in check_record(rec) if f.kind.startswith("implausible")]


def test_benchmark_records_are_plausible(records_dir):
    from records import BENCHMARK_RECORDS, check_record, load_benchmark_record

    for name in BENCHMARK_RECORDS:
        rec = load_benchmark_record(name, records_dir=records_dir)
        flaws = [f.message for f in check_record(rec) if f.kind.startswith("implausible")]
        assert not flaws, flaws


@pytest.mark.parametrize("dt, n", [(0.5, 4000), (1e-5, 400)])
def test_time_step_that_does_not_fit_is_flagged(dt, n):
    from records import check_record

    t = np.arange(n)
    acc = 2.0 * np.sin(2 * np.pi * t / 50) * np.exp(-((t - n / 2) / (n / 6)) ** 2)
    rec = Record(name="odd", dt=dt, acceleration=acc)
    assert "implausible_time_step" in {f.kind for f in check_record(rec)}


def test_units_assumed_in_record_summaries(records_dir, kobe_files):
    from records import load_benchmark_record, load_record

    assert load_benchmark_record("kobe", records_dir=records_dir).summary()["units_assumed"].startswith("cm/s2")
    assert load_record(kobe_files["at2"]).summary()["units_assumed"].startswith("g")


def test_records_list_shows_the_units(capsys, records_dir):
    status, out, err = _run(capsys, ["records", "list", "--records-dir", str(records_dir)])
    assert status == 0 and "values read as: cm/s2" in out


# --------------------------------------------------------------------------- item 5: synthetic records
def test_compare_synthetic_rows_are_labelled(capsys):
    status, out, err = _run(capsys, ["compare", "--synthetic", "--records", "kobe", "--orientations", "FN-x",
                                     "--controllers", "passive-off", "--jobs", "1", "--no-progress", *FAST])
    assert status == 0, err
    assert "kobe (synthetic)" in out
    status, out, err = _run(capsys, ["compare", "--synthetic", "--records", "kobe", "--orientations", "FN-x",
                                     "--controllers", "passive-off", "--jobs", "1", "--no-progress", "--json",
                                     *FAST])
    run = json.loads(out)["runs"][0]
    assert run["synthetic"] is True and run["label"] == "kobe (synthetic)"


def test_generated_csv_stays_synthetic(tmp_path, capsys):
    from records import benchmark_like, load_record

    status, out, err = _run(capsys, ["records", "generate", "kobe", "--out", str(tmp_path / "k.csv")])
    assert status == 0, err
    back = load_record(tmp_path / "k.csv")
    original = benchmark_like("kobe", "FN-x", seed=0)
    assert back.synthetic and back.name == original.name and back.source == original.source
    status, out, err = _run(capsys, ["records", "show", str(tmp_path / "k.csv")])
    assert out.startswith("SYNTHETIC")


def test_synthetic_pgv_and_pgd_are_compared_with_the_recorded_motion(capsys):
    from records import benchmark_like, get_entry

    rec = benchmark_like("kobe", "FN-x", seed=0)
    comparison = rec.metadata["recorded_comparison"]
    entry = get_entry("kobe")
    assert comparison["recorded_pgv_m_s"] == pytest.approx(list(entry.pgv_m_s))
    assert comparison["pgv_m_s"] == pytest.approx(list(rec.pgv))
    assert comparison["pgd_m"] == pytest.approx(list(rec.pgd))
    assert len(comparison["recorded_pgd_m"]) == 2
    status, out, err = _run(capsys, ["records", "show", "kobe", "--synthetic"])
    assert status == 0 and "recorded kobe" in out and "PGD" in out


# --------------------------------------------------------------------------- item 6: seed orientation names
def test_seed_orientation_aliases(records_dir):
    from records import canonical_orientation, load_benchmark_record

    assert canonical_orientation("FP-y") == "FN-x" and canonical_orientation("FN-y") == "FP-x"
    assert canonical_orientation("fp-Y") == "FN-x"
    a = load_benchmark_record("kobe", "FP-y", records_dir=records_dir)
    b = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    assert np.array_equal(a.acceleration, b.acceleration)
    with pytest.raises(InputError, match="FP-y"):
        canonical_orientation("up")


def test_seed_orientation_names_on_the_command_line(capsys, kobe_files, tmp_path):
    from records import load_record, write_csv

    rec = load_record(kobe_files["cm"], units="cm/s2")
    two = write_csv(rec, tmp_path / "two.csv")
    s, _ = _run_json(capsys, "--record", str(two), "--orientation", "FN-y", "--controller", "none", *FAST)
    ref, _ = _run_json(capsys, "--record", str(two), "--orientation", "FP-x", "--controller", "none", *FAST)
    assert s["orientation"] == "FP-x" and s["peaks"] == ref["peaks"]
    for command in (["compare"], ["identify"], ["records", "show"]):
        parser = _subparser(build_parser(), *command)
        opt = next(a for a in parser._actions if a.dest in ("orientation", "orientations"))
        assert "FP-y" in (opt.help or ""), command


def test_records_show_honours_the_orientation_of_a_file(capsys, tmp_path, kobe_files):
    from records import load_record, write_csv

    rec = load_record(kobe_files["cm"], units="cm/s2")
    two = write_csv(rec, tmp_path / "two.csv")
    shown = {}
    for orientation in ("FN-x", "FP-x", "FP-y"):
        status, out, err = _run(capsys, ["records", "show", str(two), "--orientation", orientation, "--json"])
        assert status == 0, err
        shown[orientation] = json.loads(out)
    assert shown["FN-x"]["pga_g"] == pytest.approx(shown["FP-x"]["pga_g"][::-1])
    assert shown["FP-x"]["labels"] == shown["FN-x"]["labels"][::-1]
    assert shown["FP-y"]["pga_g"] == shown["FN-x"]["pga_g"] and shown["FP-x"]["orientation"] == "FP-x"


def test_seed_orientation_names_in_ensembles_identify_and_generate(tmp_path, capsys):
    from benchmark.applications.ensemble import EnsembleConfig
    from benchmark.applications.cli_identify import _orientation_list
    from records import benchmark_like, load_record

    config = EnsembleConfig.from_dict({"controllers": ["passive-on"], "records": ["kobe"],
                                       "orientations": ["FP-y", "FN-y"]})
    assert config.orientations == ("FN-x", "FP-x")
    assert _orientation_list("FP-y, FN-y") == "FN-x,FP-x"
    status, out, err = _run(capsys, ["records", "generate", "kobe", "--orientation", "FN-y",
                                     "--out", str(tmp_path / "k.csv")])
    assert status == 0, err
    assert np.allclose(load_record(tmp_path / "k.csv").acceleration,
                       benchmark_like("kobe", "FP-x").acceleration, atol=1e-8)


def test_fig11_title_gives_the_seed_orientation_name(tmp_path, monkeypatch):
    from types import SimpleNamespace

    import damper.identification.plots as plots

    titles = []
    monkeypatch.setattr(plots, "_save", lambda fig, path: titles.append(fig._suptitle.get_text()) or path)
    t = np.linspace(0, 1, 50)
    force = np.column_stack([np.sin(6 * t), np.cos(6 * t)]) * 1e5
    errors = {"rel_rms_error": 0.1, "peak_error": 0.2, "energy_error": 0.05}
    for orientation, seed_name in (("FN-x", "FP-y"), ("FP-x", "FN-y")):
        run = SimpleNamespace(t=t, force=force, predicted={"extended": 0.9 * force, "normalized": 1.1 * force},
                              errors={"extended": errors, "normalized": errors}, voltage=np.zeros((50, 2)),
                              record="kobe", orientation=orientation)
        plots.plot_force_errors(run, tmp_path / "f.png")
        assert f"kobe {orientation} (seed: {seed_name})" in titles[-1]


def test_compare_api_gives_the_control_step_per_record(kobe_files):
    from benchmark.applications.comparison import compare

    result = compare(records=[str(kobe_files["at2"])], orientations="FN-x", controllers="passive-on",
                     isolation="linear", n_modes=3, jobs=1, progress=False, warn=False)
    assert result.settings["control_step_by_record"] == {"KJM000": pytest.approx(0.005)}
    assert result.settings["record_units"]["KJM000"].startswith("g")


def test_a_blow_up_on_an_implausible_record_says_so_in_one_line(capsys, tmp_path, kobe_files):
    from records import Record, write_csv

    absurd = write_csv(Record("absurd", 0.01, kobe_files["acc"] * 1e4), tmp_path / "absurd.csv")
    status, out, err = _run(capsys, ["run", "--record", str(absurd), "--json", *FAST])
    # the record was flagged before the run: its blow-up is an input error (exit 2) led by the flag
    assert status == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sbib: error: the record is implausible: ")
    assert "PGA" in lines[0] and "the run then failed" in lines[0]
