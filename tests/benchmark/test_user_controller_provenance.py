"""A user's controller in results and ensembles: its file hashed however it is named, its printed
output kept off sbib's standard output, a static ``step`` accepted, a failure placed in its run."""

from __future__ import annotations

import json

import h5py
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from controllers.user import load_user_controller, user_controller_file

HALF = ("import numpy as np\nfrom controllers.base import Controller\n"
        "class Half(Controller):\n"
        "    def step(self, m):\n"
        "        return np.full(self.context.n_devices, FRACTION * self.context.voltage_max)\n")


@pytest.fixture
def short_record(tmp_path, records_dir):
    """The first 3 s of kobe as a two-component CSV file."""
    from records import load_benchmark_record, write_csv
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    short = rec.replace(acceleration=rec.acceleration[:600].copy(), name="kobe3", labels=("NS", "EW"))
    return str(write_csv(short, tmp_path / "kobe3.csv"))


def _controller(path, fraction=0.5):
    path.write_text(f"FRACTION = {fraction}\n" + HALF)
    return path


def test_an_edited_user_controller_file_is_not_resumed(tmp_path):
    """Case keys name the controller by its spec; the journal keeps the file's SHA-256, so a
    resume after an edit is refused (the finished runs were another controller's)."""
    from benchmark.applications.ensemble import EnsembleConfig, run_ensemble
    ctl = _controller(tmp_path / "ctl.py")
    toml = tmp_path / "e.toml"
    toml.write_text(f'controllers = ["{ctl}:Half"]\nrecords = ["kobe"]\norientations = ["FN-x"]\n')
    out = tmp_path / "e.h5"
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)  # unchanged: resumes
    _controller(ctl, 0.1)
    with pytest.raises(InputError, match="input_files_sha256.*ctl.py.*do not belong to this ensemble"):
        run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)


def test_a_module_controller_is_hashed_by_its_file(tmp_path, monkeypatch, capsys, short_record):
    """``package.module:Class`` is hashed like ``file.py:Class``: by the module's file."""
    pkg = tmp_path / "mypkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    laws = _controller(pkg / "laws.py")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert user_controller_file("mypkg.laws:Half") == laws.resolve()
    assert user_controller_file("passive-on") is None
    out = tmp_path / "r.h5"
    assert main(["run", "--record", short_record, "--controller", "mypkg.laws:Half", "--out", str(out)]) == 0
    capsys.readouterr()
    with h5py.File(out) as h5:
        controller = json.loads(h5.attrs["inputs"])["controller"]
    assert controller["path"] == str(laws.resolve()) and len(controller["sha256"]) == 64
    assert controller["spec"] == "mypkg.laws:Half"


def test_compare_writes_each_input_file_with_its_hash(tmp_path, capsys, short_record):
    ctl = _controller(tmp_path / "ctl.py")
    out = tmp_path / "c.h5"
    assert main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers",
                 f"passive-on,{ctl}:Half", "--jobs", "1", "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    with h5py.File(out) as h5:
        inputs = json.loads(h5.attrs["inputs"])
    (record,) = inputs["records"].values()
    assert record["path"].endswith("kobe3.csv") and len(record["sha256"]) == 64
    assert inputs["controllers"]["passive-on"] == {"path": "passive-on"}
    assert len(inputs["controllers"][f"{ctl}:Half"]["sha256"]) == 64
    assert len(inputs["structure"]["sha256"]) == 64


def test_what_a_user_controller_prints_stays_off_the_json(tmp_path, capsys, short_record):
    ctl = tmp_path / "chatty.py"
    ctl.write_text("print('module imported')\n" + HALF.replace(
        "    def step(self, m):\n", "    def reset(self, context):\n        super().reset(context)\n"
        "        print('reset called')\n    def step(self, m):\n        print('step')\n")
        .replace("FRACTION", "0.5"))
    assert main(["run", "--record", short_record, "--controller", f"{ctl}:Half", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["J"]["J1"] > 0  # standard output is sbib's JSON alone
    assert "module imported" in err and "reset called" in err


def test_a_static_or_class_step_is_accepted(tmp_path):
    ctl = tmp_path / "sig.py"
    ctl.write_text("import numpy as np\n"
                   "class Static:\n    @staticmethod\n    def step(m):\n        return np.zeros(16)\n"
                   "class Klass:\n    @classmethod\n    def step(cls, m):\n        return np.zeros(16)\n"
                   "class TwoArgs:\n    @staticmethod\n    def step(m, extra):\n        return np.zeros(16)\n")
    load_user_controller(f"{ctl}:Static")
    load_user_controller(f"{ctl}:Klass")
    with pytest.raises(InputError, match=r"TwoArgs.step\(m, extra\) must take one argument"):
        load_user_controller(f"{ctl}:TwoArgs")


def test_compare_names_the_run_a_user_controller_failed_in(tmp_path, capsys, short_record):
    ctl = tmp_path / "late.py"
    ctl.write_text("import numpy as np\nclass Late:\n    def step(self, m):\n        raise ValueError('late')\n")
    status = main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers",
                   f"{ctl}:Late", "--jobs", "1", "--no-progress"])
    err = capsys.readouterr().err
    assert status != 0
    assert "kobe3 FN-x: controller" in err and "raised ValueError" in err
