"""``sbib identify --data`` output (issue #16 item 9): progress on stderr, parameters with units,
JSON on stdout only with ``--json``."""

from __future__ import annotations

import json

import pytest

from benchmark.applications.cli import main
from damper.io.data import write_csv
from damper.lab.laboratory import periodic_test


@pytest.fixture(scope="module")
def csv_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("idata") / "virtual_0V.csv"
    write_csv(periodic_test("virtual", 0.02, 1.0, 0.0, cycles=3, sample_rate=200.0, noise=0.01, seed=4), path)
    return str(path)


def _is_json(text: str) -> bool:
    try:
        json.loads(text)
    except ValueError:
        return False
    return True


def test_text_output_has_units_and_no_json(csv_file, tmp_path, capsys):
    assert main(["identify", "--data", csv_file, "--model", "extended", "--bootstrap", "0",
                 "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    out = captured.out
    assert not _is_json(out) and "{" not in out, out
    assert "kappa_x = " in out and " N/m" in out and " N s/m" in out and " 1/m" in out
    assert "kappa_w = " in out and " kN" not in out.split("kappa_w = ")[1].split(",")[0]
    # progress on stderr: a line when it starts and one per identification
    assert "identify" in captured.err and "1/1" in captured.err


def test_json_only_with_the_option(csv_file, tmp_path, capsys):
    assert main(["identify", "--data", csv_file, "--model", "extended", "--bootstrap", "0",
                 "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["tests"][0]["units"]["kappa_x"] == "N/m"


def test_nested_summaries_print_as_text(capsys):
    from benchmark.applications.cli_identify import _print_tree

    _print_tree({"extended": {"mean_rel_rms_error": 0.0123, "runs": [1, {"a": 2.0}]}, "n": 3}, "  ")
    out = capsys.readouterr().out
    assert "{" not in out and "mean_rel_rms_error: 0.0123" in out and "  n: 3" in out


def test_one_model_file_per_form_with_laws_over_the_levels(tmp_path, capsys):
    """Files at two voltages give one file per model form with tabulated laws through the levels."""
    from damper.io.model_file import read_model_file
    from damper.models.voltage_laws import Tabulated
    files = []
    for v in (0.0, 1.0):
        path = tmp_path / f"virtual_{v:g}V.csv"
        write_csv(periodic_test("virtual", 0.02, 1.0, v, cycles=3, sample_rate=200.0, noise=0.01, seed=4), path)
        files.append(str(path))
    assert main(["identify", "--data", *files, "--bootstrap", "0", "--out", str(tmp_path / "o"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data["model_files"]) == {"normalized", "extended"}
    for form, path in data["model_files"].items():
        mf = read_model_file(path)
        assert mf.model.name == f"{form}_bouc_wen" and mf.input.levels == (0.0, 1.0)
        assert isinstance(mf.model.kappa_w, Tabulated)
        for s in (s for s in data["tests"] if s["model"] == form):
            assert mf.model.coefficients(s["level"])["kappa_w"] == pytest.approx(s["parameters"]["kappa_w"], rel=1e-12)
        assert len(mf.provenance["inputs"]) == 2 and mf.quality["by_file"]
    # one file at one level: constant parameters, and a note that there is nothing to command
    assert main(["identify", "--data", files[1], "--model", "normalized", "--bootstrap", "0",
                 "--out", str(tmp_path / "one")]) == 0
    assert "model file (normalized)" in capsys.readouterr().out
    mf = read_model_file(tmp_path / "one" / "normalized_model.json")
    assert mf.input.single_level and any("nothing" in n or "does not depend" in n for n in mf.notes)


def test_the_model_file_holds_the_one_model_per_level_the_run_reports(tmp_path, capsys):
    # with two tests at a level, the file had held the median of each parameter over the two
    # per-test fits (a set never fitted nor scored) while the run reported the joint fit
    from damper.io.data import write_csv
    from damper.io.model_file import read_model_file
    from damper.lab.laboratory import periodic_test
    files = []
    for v in (0.0, 1.0):
        for k, (amplitude, frequency) in enumerate(((0.02, 1.0), (0.01, 2.0))):
            path = tmp_path / f"virtual_{k}_{v:g}V.csv"
            write_csv(periodic_test("virtual", amplitude, frequency, v, cycles=3, sample_rate=200.0, noise=0.01,
                                    seed=4 + k), path)
            files.append(str(path))
    assert main(["identify", "--data", *files, "--model", "normalized", "--bootstrap", "0", "--no-plots",
                 "--out", str(tmp_path / "o"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    mf = read_model_file(data["model_files"]["normalized"])
    for entry in data["levels"].values():
        coefficients = mf.model.coefficients(entry["level"])
        for name in ("kappa_w", "kappa_xdot", "rho", "n"):
            assert coefficients[name] == pytest.approx(entry["parameters"][name], rel=1e-12), name
        assert mf.quality["by_level"][f"{entry['level']:g} V"]["mean_rel_rms_error"] == pytest.approx(entry["mean_error"])


def test_test_names_from_files_make_safe_unique_figures_and_failures_name_the_file(csv_file, tmp_path, capsys):
    """A test's name comes from its file's '# name:' line: it may not place a figure outside
    --out, two files with one name keep two figures, and a failing file is named by its file."""
    text = open(csv_file).read().splitlines()
    assert text[0].startswith("# name:")
    escape = tmp_path / "escape.csv"
    escape.write_text("\n".join(["# name: ../../escaped/a:b*"] + text[1:]) + "\n")
    twin = tmp_path / "twin.csv"
    twin.write_text("\n".join(["# name: ../../escaped/a:b*"] + text[1:]) + "\n")
    short = tmp_path / "short.csv"
    short.write_text("\n".join(text[:25]) + "\n")
    out = tmp_path / "out"
    assert main(["identify", "--data", str(escape), str(twin), str(short), "--model", "normalized",
                 "--bootstrap", "0", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*.png"))
    assert all(p.parts[0] == "out" and len(p.parts) == 2 for p in written), written
    assert len([p for p in written if p.name.startswith("fit_")]) == 2, written
    assert "short.csv [normalized]: not identified" in printed, printed


@pytest.mark.parametrize("count", ["-1", "1"])
def test_a_bootstrap_without_a_spread_is_refused(csv_file, capsys, count):
    # -1 ran as '-1 bootstrap refits'; 1 printed numpy's 'Degrees of freedom <= 0' per fit
    assert main(["identify", "--data", csv_file, "--bootstrap", count, "--no-plots"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"sbib: error: --bootstrap {count}: expected 0 (none) or at least 2 refits", err
