"""``sbib run``: JSON output, files, orientation of record files, and one-line errors."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.simulator.evaluation import PEAK_NAMES

SPEC_KEYS = {"record", "orientation", "isolation", "controller", "peaks", "J", "elapsed_s"}


def run_json(capsys, *args):
    status = main(["run", *args, "--json"])
    out, err = capsys.readouterr()
    assert status == 0, err
    lines = [line for line in out.splitlines() if line.strip()]
    assert len(lines) == 1, out  # exactly one JSON object on stdout
    return json.loads(lines[0])


@pytest.fixture(scope="module")
def short_record_files(tmp_path_factory, records_dir):
    """The first 6 s of kobe as a CSV file (two components) and as a one-component file."""
    from records import load_benchmark_record, write_csv
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    # plain labels: the catalogue's labels ("N-S (FN)") do not survive the CSV round trip yet
    short = rec.replace(acceleration=rec.acceleration[:1200].copy(), name="kobe6", labels=("NS", "EW"))
    d = tmp_path_factory.mktemp("records")
    two = write_csv(short, d / "kobe6.csv")
    one = write_csv(short.select([1]).replace(name="kobe6y"), d / "kobe6y.csv")
    return two, one


def test_reference_run_json_by_name(capsys, records_dir):
    s = run_json(capsys, "--record", "elcentro", "--orientation", "FP-x", "--isolation", "linear",
                 "--controller", "none", "--records-dir", str(records_dir))
    assert SPEC_KEYS <= set(s)
    assert (s["record"], s["orientation"], s["isolation"], s["controller"]) == ("elcentro", "FP-x", "linear", "none")
    assert tuple(s["peaks"]) == PEAK_NAMES
    assert 0.02 < s["peaks"]["peak_base_displacement"] < 1.5
    assert s["peaks"]["peak_device_force"] == 0.0
    assert s["peaks"]["peak_base_shear"] > s["peaks"]["peak_structure_shear"] > 0
    # against itself every defined criterion is 1; J6 and J9 are undefined without devices
    assert set(s["J"]) == {"J1", "J2", "J3", "J4", "J5", "J7", "J8"}
    assert all(v == pytest.approx(1.0) for v in s["J"].values())
    assert s["elapsed_s"] > 0


def test_record_file_orientation_output_and_plots(capsys, tmp_path, short_record_files):
    two, one = short_record_files
    out = tmp_path / "res.h5"
    a = run_json(capsys, "--record", str(two), "--orientation", "FN-x", "--isolation", "friction-lrb",
                 "--out", str(out), "--plot", str(tmp_path / "fig"))
    b = run_json(capsys, "--record", str(two), "--orientation", "FP-x", "--isolation", "friction-lrb")
    # the one-component file is the y component of the two-component one; FP-x puts it on y
    c = run_json(capsys, "--record", str(one), "--orientation", "FP-x", "--isolation", "friction-lrb")
    assert a["peaks"] != b["peaks"]
    assert c["peaks"]["peak_base_displacement"] < a["peaks"]["peak_base_displacement"]
    with h5py.File(out) as f:
        assert f.attrs["format"] == "sbib-result" and f.attrs["isolation"] == "friction-lrb"
        ub = f["run/time_histories/base_displacement"]
        assert ub.attrs["units"] == "m, m, rad" and ub.shape == (1200, 3)
        assert f["run/peaks"].attrs["peak_base_displacement"] == pytest.approx(
            a["peaks"]["peak_base_displacement"])
        assert "lead-rubber" in f.attrs["isolation_json"]
        assert f["evaluation"].attrs["J3"] == pytest.approx(1.0)
        # provenance: the command, and each input file by absolute path and content (a probe found
        # relative paths and no digest; the record's units were not stored)
        import hashlib
        inputs = json.loads(f.attrs["inputs"])
        assert inputs["record"]["path"] == str(two.resolve()) == f.attrs["record_source"]
        assert inputs["record"]["sha256"] == hashlib.sha256(two.read_bytes()).hexdigest()
        assert inputs["structure"]["sha256"] and f.attrs["record_units"] and "--record" in f.attrs["command"]
    assert sorted(p.split("_")[-1] for p in a["plots"]) == ["bearings.png", "envelopes.png", "orbit.png"]


def test_a_pair_of_one_component_files_runs_as_the_two_component_file(capsys, tmp_path, short_record_files):
    # PEER, K-NET and ESM give each component in its own file: X+Y joins them (records.resolve);
    # the pair of kobe6's two components must give the same run as kobe6 itself
    from records import load_record, write_csv
    two, one_y = short_record_files
    one_x = write_csv(load_record(two).select([0]).replace(name="kobe6x"), tmp_path / "kobe6x.csv")
    out = tmp_path / "pair.h5"
    a = run_json(capsys, "--record", str(two), "--isolation", "friction-lrb")
    b = run_json(capsys, "--record", f"{one_x}+{one_y}", "--isolation", "friction-lrb", "--out", str(out))
    for name, value in a["peaks"].items():
        # the same samples through the same run, only written and read back as CSV (write_csv
        # keeps 10 significant digits): the peaks agree far below the integrator's own error
        assert b["peaks"][name] == pytest.approx(value, rel=1e-7, abs=1e-12), name
    import hashlib
    with h5py.File(out) as f:
        files = json.loads(f.attrs["inputs"])["record"]["files"]
    assert [d["sha256"] for d in files] == [hashlib.sha256(p.read_bytes()).hexdigest() for p in (one_x, one_y)]


def test_default_file_is_lean_and_full_histories_is_an_option(capsys, tmp_path, short_record_files):
    two, _ = short_record_files
    lean, full = tmp_path / "lean.h5", tmp_path / "full.h5"
    a = run_json(capsys, "--record", str(two), "--isolation", "friction-lrb", "--out", str(lean))
    b = run_json(capsys, "--record", str(two), "--isolation", "friction-lrb", "--out", str(full),
                 "--full-histories")
    assert a["peaks"] == b["peaks"]
    with h5py.File(lean) as f, h5py.File(full) as g:
        kept = set(f["run/time_histories"])
        assert {"base_displacement", "floor_acceleration_absolute", "base_shear"} <= kept
        assert not {"bearing_force", "bearing_state", "state"} & kept
        assert {"bearing_force", "bearing_state", "state"} <= set(g["run/time_histories"])
        assert g["run/time_histories/bearing_force"].shape == (1200, 92, 2)
        # single precision by default, double with --full-histories (issue 14: <= 5 MB per run)
        assert f.attrs["precision"] == "single" and g.attrs["precision"] == "double"
        assert f["run/time_histories/base_displacement"].dtype == np.float32
        assert g["run/time_histories/base_displacement"].dtype == np.float64
    assert lean.stat().st_size < 0.5 * full.stat().st_size


def test_controlled_run_has_device_criteria(capsys, short_record_files):
    pytest.importorskip("damper.models.virtual", reason="the default damper model is not available yet")
    two, _ = short_record_files
    s = run_json(capsys, "--record", str(two), "--isolation", "linear", "--controller", "passive-on")
    assert s["peaks"]["peak_device_force"] > 0
    assert 0 < s["J"]["J6"] < 1 and 0 < s["J"]["J9"] < 1
    assert s["J"]["J3"] < 1.0  # passive dampers at full voltage reduce the base displacement
    # the key of the J's travels with them (issue #16 item 7)
    assert s["criteria"]["J6"]["normalised_by"] == "controlled run"
    assert s["criteria"]["J3"]["normalised_by"] == "uncontrolled run" and "Narasimhan" in s["criteria"]["J3"]["source"]


@pytest.mark.parametrize("args, message", [
    (["--record", "kobe", "--isolation", "rubber-duck"], "isolation 'rubber-duck' unknown"),
    (["--record", "nowhere/missing.txt"], "file not found"),
    (["--record", "atlantis"], "atlantis"),
    (["--record", "kobe", "--controller", "magic"], "controller 'magic' unknown"),
    (["--record", "kobe", "--substep-tolerance", "-1"], "substep_tolerance"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, records_dir, args, message):
    status = main(["run", *args, "--records-dir", str(records_dir)])
    out, err = capsys.readouterr()
    assert status == 2
    assert message in err and len(err.strip().splitlines()) == 1
    assert out == ""


def test_python_api_returns_results(records_dir, short_record_files):
    from benchmark.applications.cli_run import run_command
    two, _ = short_record_files
    s = run_command(str(two), "FN-x", "linear", "none")
    assert s["result"] is s["reference"]
    assert np.max(np.hypot(*s["result"].base_displacement[:, :2].T)) == pytest.approx(
        s["peaks"]["peak_base_displacement"])
