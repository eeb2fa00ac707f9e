"""A user's damper model file and a user's controller in the building (sbib run / sbib compare)."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from benchmark.applications.cli import main
from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import NormalizedBoucWen
from damper.diagnosis.effects import Inertia, RollOff
from damper.io.model_file import InputSpec, capacity_force, read_model_file, write_model_file
from damper.models.voltage_laws import Tabulated

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = f"{ROOT / 'examples' / 'my_controller.py'}:StrokeProportional"


@pytest.fixture(scope="module")
def short_record(tmp_path_factory, records_dir):
    """The first 6 s of kobe as a two-component CSV file."""
    from records import load_benchmark_record, write_csv
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    short = rec.replace(acceleration=rec.acceleration[:1200].copy(), name="kobe6", labels=("NS", "EW"))
    return str(write_csv(short, tmp_path_factory.mktemp("records") / "kobe6.csv"))


def _lab_model(roll_off=True, levels=(0.0, 0.5, 1.0)):
    """A lab-scale (about 2 kN) model on coil current, like the diagnosis of the UTFSM damper."""
    if len(levels) > 1:
        base = NormalizedBoucWen(kappa_xdot=Tabulated(levels, (1500.0, 4300.0, 7700.0)[:len(levels)]),
                                 kappa_w=Tabulated(levels, (130.0, 700.0, 1130.0)[:len(levels)]),
                                 rho=3000.0, sigma=1.1, n=2.5)
    else:
        base = NormalizedBoucWen(kappa_xdot=4300.0, kappa_w=700.0, rho=3000.0, sigma=1.1, n=2.5)
    effects = (RollOff(0.0168), Inertia(15.0)) if roll_off else ()
    return AugmentedModel(base, effects)


@pytest.fixture(scope="module")
def model_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("models")
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    final = write_model_file(d / "final.json", _lab_model(), input=spec)
    base = write_model_file(d / "base.json", _lab_model(roll_off=False), input=spec)
    same = write_model_file(d / "same.json", _lab_model(roll_off=False), input=spec)
    single = write_model_file(d / "single.json", _lab_model(roll_off=False, levels=(0.5,)),
                              input=InputSpec("current", "A", (0.0, 1.0), (0.5,)))
    return {"final": final, "base": base, "same": same, "single": single, "dir": d}


def _run(capsys, *args):
    status = main(["run", *args, "--json"])
    out, err = capsys.readouterr()
    assert status == 0, err
    return json.loads(out), err


def test_example_controller_runs_in_the_building(capsys, short_record):
    s, _ = _run(capsys, "--record", short_record, "--controller", EXAMPLE)
    assert s["controller"] == EXAMPLE
    assert s["peaks"]["peak_device_force"] > 0 and s["J"]["J3"] < 1.0  # the devices worked
    # the law as written: v = v_max min(1, |x|/0.15) from the measured strokes (no noise by default)
    from benchmark.applications.cli_run import run_command
    run = run_command(short_record, controller=EXAMPLE, warn=False)
    result = run["result"]
    v, x = np.asarray(result.voltage), np.asarray(result.device_displacement)
    steps = np.arange(0, v.shape[0] - 1, int(round(0.005 / (result.t[1] - result.t[0]))))
    expected = np.minimum(1.0, np.abs(x[steps]) / 0.15)
    assert np.max(np.abs(v[steps + 1] - expected)) < 0.02  # measured a step earlier: the stroke moves little
    assert v.max() > 1e-3  # 6 s of kobe: strokes of a few mm


BAD_CONTROLLERS = {
    "no_argument_step": ("class C:\n    def step(self):\n        return [0.0]\n", "must take one argument"),
    "two_argument_step": ("class C:\n    def step(self, y, t):\n        return y\n", "must take one argument"),
    "needs_arguments": ("class C:\n    def __init__(self, gain):\n        pass\n    def step(self, y):\n"
                        "        return y\n", "cannot be built with no arguments"),
    "raises": ("class C:\n    def step(self, y):\n        return 1 / 0\n", "raised ZeroDivisionError"),
    "out_of_range": ("import numpy as np\nclass C:\n    def reset(self, context):\n        self.n = context.n_devices\n"
                     "    def step(self, y):\n        return np.full(self.n, 5.0)\n", "outside [0, 1]"),
    # a probe (2026-11-28): 1.000001 had been printed as "command 1 ... outside [0, 1]"
    "just_over": ("import numpy as np\nclass C:\n    def reset(self, context):\n        self.n = context.n_devices\n"
                  "    def step(self, y):\n        return np.full(self.n, 1.000001)\n", "command 1.000001 for device 0"),
    "wrong_count": ("class C:\n    def step(self, y):\n        return [0.0, 0.0]\n", "shape (2,)"),
    "no_step": ("class C:\n    pass\n", "has no step"),
    "syntax": ("class C(:\n", "SyntaxError"),
    "missing_class": ("class D:\n    pass\n", "has no C"),
    "reset_raises": ("class C:\n    def reset(self, context):\n        raise KeyError('gain')\n"
                     "    def step(self, y):\n        return y\n", "reset(context) raised KeyError"),
    # a review (2026-11-26): sys.exit() in user code ended sbib with status 0 and no output, and
    # compiled() was called unguarded (a traceback)
    "exits": ("import sys\nclass C:\n    def step(self, y):\n        sys.exit(0)\n", "raised SystemExit"),
    "compiled_raises": ("class C:\n    def compiled(self):\n        raise RuntimeError('no')\n"
                        "    def step(self, y):\n        return y\n", "compiled() raised RuntimeError"),
    "compiled_junk": ("class C:\n    def compiled(self):\n        return 42\n"
                      "    def step(self, y):\n        return y\n", "compiled() returned int"),
    # a probe (2026-11-27): None read as 'voltages of shape ()', complex commands ran with a
    # ComplexWarning on stderr and the imaginary part dropped
    "returns_none": ("class C:\n    def step(self, y):\n        pass\n", "returned None"),
    "complex": ("import numpy as np\nclass C:\n    def reset(self, context):\n        self.n = context.n_devices\n"
                "    def step(self, y):\n        return np.full(self.n, 0.5 + 0.1j)\n", "returned complex commands"),
}


@pytest.mark.parametrize("case", sorted(BAD_CONTROLLERS))
def test_bad_controller_is_refused_in_one_line(capsys, tmp_path, short_record, case):
    source, words = BAD_CONTROLLERS[case]
    path = tmp_path / f"{case}.py"
    path.write_text(source)
    spec = f"{path}:C"
    assert main(["run", "--record", short_record, "--controller", spec]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and spec in err and words in err, err


def test_model_file_in_the_building_scaled_with_stated_mapping(capsys, tmp_path, short_record, model_files):
    out = tmp_path / "r.h5"
    s, err = _run(capsys, "--record", short_record, "--controller", "clipped-optimal", "--damper",
                  str(model_files["final"]), "--damper-scale", "1000kN", "--devices", "8", "--out", str(out))
    d = s["damper"]
    assert d["n_devices"] == 8 and d["layout"] == "perimeter-8"
    (c,) = d["dampers"]
    # the scale maps the fitted device (the inertia the building cannot run included) onto 1000 kN
    assert c["scale"] == pytest.approx(1e6 / capacity_force(read_model_file(model_files["final"]).augmented()),
                                       rel=1e-9)
    assert c["model"] == "series_dashpot_bouc_wen" and "current in A" in c["input_mapping"]
    assert any(n.startswith("inertia") for n in c["notes"]) and "inertia" in err
    # 15 kg of inertia is ~1 % of the force at the capacity test: a note with its share, no warning
    share = [n for n in c["notes"] if "the building runs it without inertia" in n]
    assert share and not share[0].startswith("warning:"), c["notes"]
    with h5py.File(out) as h5:
        assert json.loads(h5.attrs["damper"])["dampers"][0]["scale"] == pytest.approx(c["scale"])
        # the command of a model identified on current is in amperes
        assert h5["run/time_histories/voltage"].attrs["units"] == "A"
    # the reference stays the building without devices
    ref, _ = _run(capsys, "--record", short_record, "--controller", "clipped-optimal")
    assert s["reference_peaks"] == ref["reference_peaks"]
    assert s["peaks"] != ref["peaks"]


def _current_model_file(path, effect):
    """A model file of a device fitted on the current at three levels, with one ``effect``."""
    levels = (0.0, 0.5, 1.0)
    base = NormalizedBoucWen(kappa_xdot=Tabulated(levels, (10.0, 20.0, 30.0)),
                             kappa_w=Tabulated(levels, (130.0, 700.0, 1130.0)), rho=3000.0, sigma=1.1, n=2.5)
    return write_model_file(path, AugmentedModel(base, (effect,)), input=InputSpec("current", "A", (0.0, 1.0), levels))


def test_effects_without_a_building_kernel_warn_with_their_share(capsys, tmp_path, short_record):
    """A diagnosis whose final model carries a large `direction` factor (no building kernel: a
    force jump at every reversal): the building runs it without that term, and the run says how
    much of the device's force is missing instead of a bare note."""
    from damper.diagnosis.effects import Direction
    from damper.io.model_file import dropped_share
    path = _current_model_file(tmp_path / "direction.json", Direction(0.6))
    source = read_model_file(path)
    share = dropped_share(source.augmented(), source.building_model()[0])
    assert 0.3 < share < 1.0
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(path),
                  "--damper-scale", "1000kN")
    assert f"warning: direction.json: the building runs it without direction, {100 * share:.0f} % of its force" in err


def test_shear_thinning_runs_in_the_building(capsys, tmp_path, short_record):
    """The UTFSM chain's final model moved 18 % of its force into shear_thinning, which the
    building used to leave out with that warning; it now runs as a force term
    (damper.models.force_terms), so nothing is left out and the device's force differs from the
    base alone's."""
    from damper.diagnosis.effects import ShearThinning
    from damper.io.model_file import dropped_share
    path = _current_model_file(tmp_path / "thinning.json", ShearThinning(2000.0))
    source = read_model_file(path)
    model, dropped = source.building_model()
    assert dropped == [] and dropped_share(source.augmented(), model) < 1e-9
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(path),
                  "--damper-scale", "1000kN")
    assert "without shear_thinning" not in err
    assert s["damper"]["dampers"][0]["model"] == "normalized_bouc_wen + shear_thinning"
    plain = write_model_file(tmp_path / "plain.json", source.model, input=source.input)
    p, _ = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(plain),
                "--damper-scale", "1000kN")
    assert s["J"] != p["J"]


def test_a_dropped_field_lag_is_judged_under_a_switching_command(tmp_path):
    # a lag carries nothing at a constant input: it had read '0 %' of the force (a note, not a
    # warning), while under clipped-optimal control it moved J6 by a fifth in a probe's run
    from damper.diagnosis.effects import VoltageLag
    from damper.io.model_file import dropped_share
    source = read_model_file(_current_model_file(tmp_path / "lag.json", VoltageLag(0.03)))
    assert dropped_share(source.augmented(), source.building_model()[0]) > 0.1


def test_a_constant_offset_neither_sizes_the_device_nor_counts_as_force_left_out(capsys, tmp_path, short_record):
    """A probe: the Dyke base model's -142 N offset (a load cell's zero) was in its capacity (the
    device came out at 926 kN for a 1000-kN target) and read as '13 % of its force' left out."""
    from damper.diagnosis.effects import Offset
    from damper.io.model_file import capacity_force
    path = _current_model_file(tmp_path / "offset.json", Offset(-300.0))
    source = read_model_file(path)
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(path),
                  "--damper-scale", "1000kN")
    assert "a constant force" in err and "without offset" not in err and "warning: offset" not in err
    # the building's device (no offset) is what reaches 1000 kN
    assert s["damper"]["dampers"][0]["scale"] == pytest.approx(1e6 / capacity_force(source.building_model()[0]),
                                                                rel=1e-9)


def test_the_dropped_share_drives_only_the_commands_a_controller_gives(tmp_path, monkeypatch):
    """A probe's Dyke final model (input range from -0.44 V, the rig's command) failed numerically
    at -0.44 V in the switching measure, and that measure stopped every building run with it;
    controllers command [0, v_max], so the measure switches between 0 and the top."""
    import damper.io.model_file as mf
    from damper.diagnosis.effects import VoltageLag
    path = _current_model_file(tmp_path / "lag.json", VoltageLag(0.03))
    doc = json.loads(path.read_text())
    doc["input"]["range"] = [-0.44, 1.0]
    path.write_text(json.dumps(doc))
    source = read_model_file(path)
    seen = []
    real = mf.AugmentedModel.simulate
    monkeypatch.setattr(mf.AugmentedModel, "simulate", lambda self, t, x, xd, xdd, v: seen.append(np.min(v)) or
                        real(self, t, x, xd, xdd, v))
    assert mf.dropped_share(source.augmented(), source.building_model()[0]) > 0.1
    assert min(seen) == 0.0


def test_a_dropped_share_that_cannot_be_measured_does_not_stop_the_run(capsys, tmp_path, short_record, monkeypatch):
    import damper.io.model_file as mf
    from benchmark.foundation.errors import NumericalError
    from damper.diagnosis.effects import VoltageLag

    def fail(*args, **kwargs):
        raise NumericalError("spencer_bouc_wen: force is not finite")

    monkeypatch.setattr(mf, "_capacity_cycle", fail)
    path = _current_model_file(tmp_path / "lag.json", VoltageLag(0.03))
    monkeypatch.setattr("benchmark.applications.damper_choice.capacity_force", lambda model: 2e3)
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(path),
                  "--damper-scale", "500")
    assert "a share of its force that could not be measured" in err and s["J"]["J3"] > 0


def test_input_range_beyond_the_fitted_levels_is_said(capsys, tmp_path, short_record, model_files):
    doc = json.loads(Path(model_files["final"]).read_text())
    doc["input"]["range"] = [0.0, 2.0]
    wide = tmp_path / "wide.json"
    wide.write_text(json.dumps(doc))
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper", str(wide),
                  "--damper-scale", "300")
    assert "input range [0, 2] A goes beyond the levels it was fitted at (0-1 A)" in err


def test_single_level_model_says_nothing_to_command(capsys, short_record, model_files):
    s, err = _run(capsys, "--record", short_record, "--controller", "clipped-optimal", "--damper",
                  str(model_files["single"]), "--damper-scale", "300")
    assert "nothing to command" in err and "nothing to command" in " ".join(s["damper"]["dampers"][0]["notes"])


def test_layout_file_with_a_model_per_slot(capsys, tmp_path, short_record, model_files):
    layout = tmp_path / "layout.json"
    layout.write_text(json.dumps({"name": "two", "devices": [
        {"x": 1.82, "y": 30.69, "direction": "x", "model": str(model_files["final"])},
        {"x": -17.25, "y": 7.35, "direction": "y"}]}))
    s, _ = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper",
                str(model_files["base"]), "--damper-scale", "200", "--devices", str(layout))
    assert s["damper"]["n_devices"] == 2 and s["damper"]["layout"] == "two"
    assert sorted(c["damper"] for c in s["damper"]["dampers"]) == ["base.json", "final.json"]


@pytest.mark.parametrize("args, words", [
    (["--damper", "nosuchmodel"], "not a model file"),
    (["--damper-scale", "-3"], "--damper-scale"),
    (["--devices", "3"], "even number"),
])
def test_bad_damper_options_one_line(capsys, short_record, args, words):
    assert main(["run", "--record", short_record, "--controller", "passive-on", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and words in err, err


def test_bad_model_file_one_line(capsys, tmp_path, short_record, model_files):
    doc = json.loads(Path(model_files["base"]).read_text())
    doc["parameters"]["kappa_w"]["unit"] = "kN"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc))
    assert main(["run", "--record", short_record, "--controller", "passive-on", "--damper", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(bad) in err and "expected N" in err


def test_compare_dampers_same_runs_differences_and_figures(capsys, tmp_path, short_record, model_files):
    files = ",".join(str(model_files[k]) for k in ("base", "same", "final"))
    status = main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers",
                   f"clipped-optimal,{EXAMPLE}", "--dampers", files, "--damper-scale", "1000kN", "--jobs", "1",
                   "--json", "--plot", str(tmp_path / "figs")])
    out, err = capsys.readouterr()
    assert status == 0, err
    doc = json.loads(out)
    assert len(doc["runs"]) == 6 and {r["damper"] for r in doc["runs"]} == {"base.json", "same.json", "final.json"}
    scales = {d["damper"]: d["scale"] for d in doc["settings"]["damper"]["dampers"]}
    assert len(set(scales.values())) == 1  # one device, one similitude: the first model's factor
    for entry in doc["model_differences"]:
        same, final = entry["models"]["same.json"], entry["models"]["final.json"]
        assert entry["reference"] == "base.json"
        # the same model in another file: the same runs
        assert all(v == pytest.approx(0.0, abs=1e-12) for v in same["dJ"].values() if v is not None)
        assert same["force_difference"]["peak"] == pytest.approx(0.0, abs=1e-6)
        assert same["force_difference"]["replay_peak"] < 1e-3 * final["force_difference"]["replay_peak"]
        # the roll-off changes the device's force
        assert final["force_difference"]["replay_relative_rms"] > 0.01
    figures = sorted(p.name for p in (tmp_path / "figs").glob("force_difference_*.png"))
    assert len(figures) == 2


def test_ensemble_toml_takes_damper_devices_and_scale(tmp_path, model_files):
    from benchmark.applications.ensemble import EnsembleConfig
    from benchmark.applications.ensemble_simulation import build_building
    from benchmark.foundation.errors import InputError
    toml = tmp_path / "e.toml"
    rel = model_files["final"]
    toml.write_text(f'controllers = ["clipped-optimal"]\nrecords = ["kobe"]\ndamper = "{rel}"\n'
                    'devices = 4\ndamper_scale = "1000kN"\n')
    config = EnsembleConfig.from_toml(toml)
    case = config.cases()[0]
    assert "|damper=final.json|devices=4|damper_scale=1000kN" in case.key
    building = build_building(None, (), (), case.building)
    assert building.devices.n_devices == 4
    assert {m.name for m in building.devices.models} == {"series_dashpot_bouc_wen"}
    bad = tmp_path / "bad.toml"
    bad.write_text('controllers = ["clipped-optimal"]\nrecords = ["kobe"]\ndamper = "missing.json"\n')
    with pytest.raises(InputError) as info:
        EnsembleConfig.from_toml(bad)
    assert "\n" not in str(info.value) and "missing.json" in str(info.value)


@pytest.mark.slow
def test_chain_diagnose_compare_run(capsys, tmp_path, shared_dir, monkeypatch):
    """The README's chain: UTFSM 10 mm 1 Hz tests at every current -> base and final models with
    current laws -> both in the same kobe runs -> the example controller."""
    monkeypatch.chdir(tmp_path)
    folder = shared_dir / "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados"
    files = sorted(str(p) for p in folder.glob("10mm1Hz*A.txt"))
    assert len(files) == 5
    assert main(["diagnose", "--data", *files, "--out", "d", "--quiet"]) == 0
    capsys.readouterr()
    for name in ("base_model", "final_model"):
        mf = read_model_file(tmp_path / "d" / f"{name}.json")
        assert mf.input.quantity == "current" and mf.input.range == (0.0, 1.0)
        assert mf.input.levels == (0.0, 0.25, 0.5, 0.75, 1.0)
        doc = json.loads((tmp_path / "d" / f"{name}.json").read_text())
        assert doc["parameters"]["kappa_w"]["law"] == "tabulated"  # a current law over 0-1 A
        assert len(doc["provenance"]["inputs"]) == 5
    assert main(["compare", "--dampers", "d/base_model.json,d/final_model.json", "--damper-scale", "1000kN",
                 "--records", "kobe", "--controllers", "clipped-optimal", "--out", "c.h5", "--plot", "figs/"]) == 0
    out = capsys.readouterr().out
    assert "clipped-optimal [base_model.json]" in out and "clipped-optimal [final_model.json]" in out
    assert "dJ:" in out
    assert len(list((tmp_path / "figs").glob("force_difference_kobe_*_clipped-optimal.png"))) == 2
    assert main(["run", "--record", "kobe", "--controller", EXAMPLE]) == 0


def test_a_run_beyond_the_fitted_motion_is_said(capsys, tmp_path, short_record):
    """A model file that says which motion it was fitted on (``quality.fitted_motion``, written by
    sbib diagnose): a building run whose devices move far beyond it is warned about (a probe's
    UTFSM model, fitted on 9.7 mm and 63 mm/s, had run at 0.22 m and 0.87 m/s without a word)."""
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    path = write_model_file(tmp_path / "lab.json", _lab_model(), input=spec,
                            quality={"fitted_motion": {"stroke_m": 0.001, "velocity_m_s": 0.006}})
    doc, err = _run(capsys, "--record", short_record, "--damper", str(path), "--damper-scale", "1000kN",
                    "--controller", "passive-on")
    assert "times the largest stroke and velocity the model was fitted on (1 mm, 6 mm/s)" in err
    assert any("extrapolation" in n for n in doc["notes"])
    wide = write_model_file(tmp_path / "wide.json", _lab_model(), input=spec,
                            quality={"fitted_motion": {"stroke_m": 1.0, "velocity_m_s": 5.0}})
    _, err = _run(capsys, "--record", short_record, "--damper", str(wide), "--damper-scale", "1000kN",
                  "--controller", "passive-on")
    assert "extrapolation" not in err


def test_an_uncontrolled_run_says_its_damper_is_not_used(capsys, tmp_path, short_record):
    """``--controller none`` runs no devices: the damper's own notes (here, an input range past its
    fitted levels) would describe nothing that ran, so the run says the options were not used."""
    spec = InputSpec("current", "A", (0.0, 2.0), (0.0, 0.5, 1.0))
    path = write_model_file(tmp_path / "lab.json", _lab_model(), input=spec)
    doc, err = _run(capsys, "--record", short_record, "--damper", str(path), "--controller", "none")
    assert "--controller none runs the building without devices; --damper not used" in err
    assert "fitted at" not in err and doc["peaks"]["peak_device_force"] == 0
    _, err = _run(capsys, "--record", short_record, "--damper", str(path), "--controller", "passive-on")
    assert "fitted at" in err and "not used" not in err


def test_compare_says_a_run_beyond_the_fitted_motion_too(capsys, tmp_path, short_record):
    """sbib compare warns as sbib run does, once per model, naming only the model that was driven
    beyond its fitted motion (a probe found the warning in sbib run alone)."""
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    narrow = write_model_file(tmp_path / "lab.json", _lab_model(), input=spec,
                              quality={"fitted_motion": {"stroke_m": 0.001, "velocity_m_s": 0.006}})
    wide = write_model_file(tmp_path / "wide.json", _lab_model(), input=spec,
                            quality={"fitted_motion": {"stroke_m": 1.0, "velocity_m_s": 5.0}})
    status = main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers", "passive-on",
                   "--dampers", f"{narrow},{wide}", "--damper-scale", "1000kN", "--jobs", "1",
                   "--out", str(tmp_path / "c.h5"), "--no-progress"])
    _, err = capsys.readouterr()
    assert status == 0, err
    lines = [line for line in err.splitlines() if "extrapolation" in line]
    assert len(lines) == 1 and "lab.json" in lines[0] and "wide.json" not in lines[0]
    with h5py.File(tmp_path / "c.h5") as h5:
        assert "extrapolation" in json.loads(h5.attrs["settings"])["damper"]["motion_notes"][0]


def test_an_ensemble_says_a_run_beyond_the_fitted_motion_too(capsys, tmp_path, short_record):
    """sbib ensemble warns as sbib run and sbib compare do, over the largest stroke and velocity of
    its runs (its runs had returned peaks and J's only, so nothing could be said), prints the
    warning and keeps it in the file; a model fitted on wide motions gets no warning."""
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    for name, fitted, warned in (("lab.json", (0.001, 0.006), True), ("wide.json", (1.0, 5.0), False)):
        path = write_model_file(tmp_path / name, _lab_model(), input=spec,
                                quality={"fitted_motion": {"stroke_m": fitted[0], "velocity_m_s": fitted[1]}})
        toml = tmp_path / f"{name}.toml"
        toml.write_text(f'controllers = ["passive-on", "passive-off"]\nrecords = ["{short_record}"]\n'
                        f'orientations = ["FN-x"]\ndamper = "{path}"\ndamper_scale = "1000kN"\n')
        out = tmp_path / f"{name}.h5"
        assert main(["ensemble", "--config", str(toml), "--out", str(out), "--no-progress", "--jobs", "1"]) == 0
        err = capsys.readouterr().err
        lines = [line for line in err.splitlines() if "extrapolation" in line]
        with h5py.File(out) as h5:
            stroke = h5["results/peak_device_stroke"][()]
            assert h5["results/peak_device_stroke"].attrs["units"] == "m"
            assert h5["results/peak_device_velocity"].attrs["units"] == "m/s"
            notes = json.loads(h5.attrs.get("motion_notes", "[]"))
        assert np.all(stroke > 0.001)  # each run's own stroke, in its row
        if warned:
            assert len(lines) == 1 and name in lines[0] and f"{stroke.max():.3g} m" in lines[0]
            assert notes == [lines[0].removeprefix("sbib ensemble: ")]
        else:
            assert not lines and not notes


def test_an_ensemble_states_its_devices_as_sbib_run_does(tmp_path, model_files, capsys):
    """The ensemble's HDF5 file names its damper models (file and SHA-256, scale, input mapping,
    effects) and the command prints their notes; a probe's ensemble of a model run without one of
    its effects had said nothing of it and kept only the TOML's text."""
    from benchmark.applications.ensemble import building_description
    toml = tmp_path / "e.toml"
    toml.write_text(f'controllers = ["passive-off"]\nrecords = ["kobe"]\norientations = ["FN-x"]\n'
                    f'damper = "{model_files["final"]}"\ndamper_scale = "1000kN"\n')
    out = tmp_path / "e.h5"
    assert main(["ensemble", "--config", str(toml), "--out", str(out), "--no-progress", "--jobs", "1"]) == 0
    err = capsys.readouterr().err
    assert "sbib ensemble: note:" in err and "inertia" in err  # no building kernel for inertia
    with h5py.File(out) as h5:
        described = json.loads(h5.attrs["damper"])
    assert described["layout"]["n_devices"] == 16
    (d,) = described["dampers"]
    assert d["scale"] > 1 and "current in A" in d["input_mapping"]
    assert described["files"][0]["path"] == str(Path(model_files["final"]).resolve())
    assert len(described["files"][0]["sha256"]) == 64
    assert building_description(()) is None


def test_ensemble_does_not_resume_runs_of_an_edited_damper_file(tmp_path, model_files):
    """The case keys name the damper file, not its content: the journal keeps the file's SHA-256
    and a resume after an edit is refused (the finished runs were of another device)."""
    import shutil
    from benchmark.applications.ensemble import EnsembleConfig, run_ensemble
    from benchmark.foundation.errors import InputError
    model = tmp_path / "m.json"
    shutil.copy(model_files["final"], model)
    toml = tmp_path / "e.toml"
    toml.write_text(f'controllers = ["passive-off"]\nrecords = ["kobe"]\ndamper = "{model}"\n')
    out = tmp_path / "e.h5"
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)  # unchanged: resumes
    doc = json.loads(model.read_text())
    doc["notes"] = list(doc.get("notes", [])) + ["edited"]
    model.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="building_files_sha256.*do not belong to this ensemble"):
        run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)


def test_compare_two_diagnoses_with_the_same_file_name(capsys, tmp_path, short_record, model_files):
    """sbib diagnose always writes final_model.json: two of them from two folders are two models,
    labelled by their paths; the same file twice is still refused."""
    import shutil
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        shutil.copy(model_files["base" if d == "a" else "final"], tmp_path / d / "final_model.json")
    a, b = str(tmp_path / "a" / "final_model.json"), str(tmp_path / "b" / "final_model.json")
    status = main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers", "passive-off",
                   "--dampers", f"{a},{b}", "--damper-scale", "300", "--jobs", "1", "--json", "--no-progress"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert {r["damper"] for r in json.loads(out)["runs"]} == {a, b}
    main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers", "passive-off",
          "--dampers", f"{a},{b}", "--damper-scale", "300", "--jobs", "1", "--out", str(tmp_path / "c.h5"),
          "--no-progress"])
    capsys.readouterr()
    with h5py.File(tmp_path / "c.h5") as h5:
        # the model files were identified on the coil current: their command history is in A
        g = h5["runs"][next(iter(h5["runs"]))]["FN-x/passive-off"]
        assert {g[m]["voltage"].attrs["units"] for m in g} == {"A"}
        assert {g[m]["device_force_total"].attrs["units"] for m in g} == {"N (x, y)"}
    # one model (--damper): the runs carry no model label, and the unit is still the model's A
    assert main(["compare", "--records", short_record, "--orientations", "FN-x", "--controllers", "passive-off",
                 "--damper", a, "--damper-scale", "300", "--jobs", "1", "--out", str(tmp_path / "one.h5"),
                 "--no-progress"]) == 0
    capsys.readouterr()
    with h5py.File(tmp_path / "one.h5") as h5:
        g = h5["runs"][next(iter(h5["runs"]))]["FN-x/passive-off"]
        assert g["voltage"].attrs["units"] == "A"
    assert main(["compare", "--records", short_record, "--controllers", "passive-off",
                 "--dampers", f"{a},{a}", "--damper-scale", "300", "--no-progress"]) == 2
    assert "given twice" in capsys.readouterr().err


def test_ensemble_records_a_user_controller_that_raises_as_failed(tmp_path):
    """A controller raising at its 100th step fails that case (status, error kept); the other
    cases run and the HDF5 file is written."""
    import h5py
    from benchmark.applications.ensemble import EnsembleConfig, run_ensemble
    (tmp_path / "ctl.py").write_text(
        "import numpy as np\nfrom controllers.base import Controller\n"
        "class Half(Controller):\n    name = 'half'\n"
        "    def step(self, m):\n        return 0.5 * self.context.voltage_max\n"
        "class Boom(Half):\n    name = 'boom'\n"
        "    def reset(self, context):\n        super().reset(context); self.k = 0\n"
        "    def step(self, m):\n        self.k += 1\n"
        "        if self.k == 100:\n            raise RuntimeError('boom at step 100')\n"
        "        return super().step(m)\n")
    ctl = tmp_path / "ctl.py"
    toml = tmp_path / "e.toml"
    toml.write_text(f'controllers = ["{ctl}:Half", "{ctl}:Boom"]\nrecords = ["kobe"]\norientations = ["FN-x"]\n')
    out = tmp_path / "e.h5"
    summary = run_ensemble(EnsembleConfig.from_toml(toml), out, progress=False)
    assert summary.n_run == 2 and summary.n_failed == 1 and out.exists()
    with h5py.File(out) as h5:
        status = [s.decode() if isinstance(s, bytes) else s for s in h5["cases/status"][()]]
        error = [s.decode() if isinstance(s, bytes) else s for s in h5["cases/error"][()]]
    assert sorted(status) == ["failed", "ok"]
    assert any("raised RuntimeError at t = " in e and "boom at step 100" in e for e in error)


def test_a_run_that_blows_up_on_an_implausible_record_is_an_input_error(tmp_path, capsys, records_dir):
    """kobe's cm/s² values in a CSV whose header says g (PGA 825 "g"): the run was flagged before it
    started; when it blows up the one line leads with the record, exit status 2 (not 3)."""
    from records import load_benchmark_record
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    gal = rec.acceleration * 100.0  # m/s² -> cm/s², then declared as g
    path = tmp_path / "kobe_gal_as_g.csv"
    path.write_text("time [s],ax [g],ay [g]\n" + "".join(
        f"{k * rec.dt:.4f},{a:.6g},{b:.6g}\n" for k, (a, b) in enumerate(gal)))
    assert main(["run", "--record", str(path), "--controller", "passive-on"]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("sbib: error: the record is implausible: ") and "the run then failed" in err


def test_a_laboratory_model_run_unscaled_is_said(capsys, short_record, model_files):
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper",
                  str(model_files["final"]))
    assert "warning: final.json: capacity" in err and "give --damper-scale" in err
    s, err = _run(capsys, "--record", short_record, "--controller", "passive-on", "--damper",
                  str(model_files["final"]), "--damper-scale", "1000kN")
    assert "give --damper-scale" not in err


def test_an_oversized_scale_is_said(capsys, short_record):
    """Probed: `--damper-scale 1000MN` (kN meant) ended in a bare numerical failure."""
    from benchmark.applications.damper_choice import resolve_damper
    assert not [n for n in resolve_damper(None, "2000kN").notes if "capacity" in n]
    notes = [n for n in resolve_damper(None, "1000MN").notes if "capacity" in n]
    assert len(notes) == 1 and "1000 MN after --damper-scale" in notes[0] and "kN for MN" in notes[0]
    assert [n for n in resolve_damper(None, 50).notes if "times the benchmark damper's" in n]


def test_a_scale_that_leaves_the_devices_doing_nothing_is_said():
    """A review (2026-11-26): ``--damper-scale 1e-9`` ran silently with devices that did nothing."""
    from benchmark.applications.damper_choice import resolve_damper
    notes = [n for n in resolve_damper(None, 1e-9).notes if "capacity" in n]
    assert len(notes) == 1 and "after --damper-scale" in notes[0] and "barely act" in notes[0]


def test_a_registered_model_without_defaults_says_a_model_file_is_needed(capsys, short_record):
    # '--damper spencer' listed 14 missing parameters and no way forward
    assert main(["run", "--record", short_record, "--controller", "passive-on", "--damper", "spencer"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "has no default parameters; give a model file" in err and "virtual" in err, err


def test_compare_names_the_run_a_controller_fails_numerically_in(capsys, tmp_path, short_record):
    # a probe (2026-11-28): a NaN in the second record's run was printed without its record and
    # orientation, where a controller's exception named them
    path = tmp_path / "nan.py"
    path.write_text("import numpy as np\nclass C:\n    def reset(self, context):\n        self.n = context.n_devices\n"
                    "    def step(self, y):\n        return np.full(self.n, np.nan)\n")
    status = main(["compare", "--records", short_record, "--orientations", "FP-x", "--controllers", f"{path}:C",
                   "--jobs", "1", "--no-progress"])
    err = capsys.readouterr().err.strip()
    assert status == 3 and "\n" not in err and "kobe6 FP-x: controller" in err and "non-finite" in err, err


def test_identified_model_files_carry_the_fitted_motion(tmp_path):
    # a probe (2026-11-28): sbib identify --data's files had no quality.fitted_motion, so a run far
    # beyond the tests was not said to extrapolate, as it is for sbib diagnose's files
    from benchmark.applications.model_files import write_identified_models
    from damper.identification.measured import identify_files
    from damper.io.data import write_csv
    from damper.lab.laboratory import periodic_test

    path = tmp_path / "t.csv"
    write_csv(periodic_test("virtual", 0.02, 1.0, 0.0, cycles=3, sample_rate=100.0), path)
    result = identify_files([path], models=("normalized",), n_bootstrap=0)
    files = write_identified_models(result, tmp_path / "m", [str(path)])
    fitted = read_model_file(files["normalized"]).quality["fitted_motion"]
    assert fitted["stroke_m"] == pytest.approx(0.02, rel=0.02)
    assert fitted["velocity_m_s"] == pytest.approx(2 * np.pi * 0.02, rel=0.05)
