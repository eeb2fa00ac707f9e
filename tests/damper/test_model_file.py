"""The damper model file: round trip, the building's form, scaling, and one-line refusals."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError
from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.diagnosis.effects import Inertia, Offset, RollOff, ShearThinning, Stiffness
from damper.io.model_file import (FORMAT, InputSpec, capacity_force, read_model_file, write_model_file)
from damper.models.series_dashpot import SeriesDashpotBoucWen, SpencerBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial, Tabulated


def _augmented():
    base = NormalizedBoucWen(kappa_xdot=Tabulated((0.0, 0.5, 1.0), (1500.0, 4300.0, 7700.0)),
                             kappa_w=Tabulated((0.0, 0.5, 1.0), (130.0, 700.0, 1130.0)),
                             rho=3000.0, sigma=1.1, n=2.5)
    return AugmentedModel(base, (RollOff(0.0168), Stiffness(900.0), Inertia(15.0)))


def _write(tmp_path, name="m.json"):
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    return write_model_file(tmp_path / name, _augmented(), input=spec, quality={"held_out_rel_rms_error": 0.08},
                            provenance={"inputs": [], "command": "test"})


def test_round_trip_keeps_model_laws_effects(tmp_path):
    path = _write(tmp_path)
    doc = json.loads(path.read_text())
    assert doc["format"] == FORMAT and doc["model"] == "normalized_bouc_wen"
    assert doc["parameters"]["kappa_w"] == {"law": "tabulated", "inputs": [0.0, 0.5, 1.0],
                                            "values": [130.0, 700.0, 1130.0], "unit": "N"}
    assert doc["parameters"]["rho"]["unit"] == "1/m"
    mf = read_model_file(path)
    assert mf.input.quantity == "current" and mf.input.unit == "A" and mf.input.levels == (0.0, 0.5, 1.0)
    assert [e.name for e in mf.effects] == ["roll_off", "stiffness", "inertia"]
    # the same forces as the model written
    t = np.linspace(0.0, 2.0, 801)
    x = 0.01 * np.sin(2 * np.pi * t)
    for v in (0.0, 0.3, 1.0):
        np.testing.assert_allclose(mf.augmented().simulate(t, x, v=v).force,
                                   _augmented().simulate(t, x, v=v).force, rtol=1e-12, atol=1e-9)


def test_building_model_folds_kernel_effects_and_lists_the_rest(tmp_path):
    mf = read_model_file(_write(tmp_path))
    model, dropped = mf.building_model()
    assert isinstance(model, SeriesDashpotBoucWen)
    assert model.kappa_x == pytest.approx(900.0) and model.roll_off_velocity == pytest.approx(0.0168)
    assert len(dropped) == 1 and dropped[0].startswith("inertia")
    # without the additive inertia, the building's model is the augmented model's force
    aug = AugmentedModel(mf.model, tuple(e for e in mf.effects if e.name != "inertia"))
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.01 * np.sin(2 * np.pi * t)
    ref = aug.simulate(t, x, v=0.5).force
    got = simulate(model, t, x, v=0.5).force
    assert np.max(np.abs(got - ref)) < 1e-3 * np.max(np.abs(ref))


def test_spencer_base_with_effects_reads_back_and_runs(tmp_path):
    """What ``sbib diagnose --model spencer`` writes (a Spencer-type base with the loop's effects)
    is read back, simulates as written, and gives the building its base with the rest listed."""
    laws = {k: Tabulated((0.0, 1.1, 2.3), vals) for k, vals in
            (("kappa_xdot", (20.0, 880.0, 1530.0)), ("kappa_w", (58.0, 650.0, 830.0)),
             ("c1", (900.0, 27700.0, 29000.0)))}
    base = SpencerBoucWen(2180.0, 890.0, laws["kappa_xdot"], laws["kappa_w"], laws["c1"], 1.08e4, 0.67, 1.1,
                          field_lag=0.0067, voltage_range=(0.0, 2.3))
    written = AugmentedModel(base, (Offset(-140.0), Inertia(3.0), ShearThinning(740.0)))
    path = write_model_file(tmp_path / "spencer.json", written)
    mf = read_model_file(path)
    assert mf.model_name == "spencer_bouc_wen"
    assert [e.name for e in mf.effects] == ["offset", "inertia", "shear_thinning"]
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.01 * np.sin(2 * np.pi * t)
    np.testing.assert_allclose(mf.augmented().simulate(t, x, v=1.0).force,
                               written.simulate(t, x, v=1.0).force, rtol=1e-12, atol=1e-9)
    model, dropped = mf.building_model()
    # the shear thinning runs as a force term around the base (damper.models.force_terms)
    assert model.inner == base and model.terms == {"shear_thinning": 740.0}
    assert [d.split()[0] for d in dropped] == ["offset", "inertia"]


def test_every_registered_parameter_has_a_unit():
    """The force similitude scales a parameter by its unit (N...): a parameter without one would be
    left as it is (the Spencer-type base's k0 and c1 once were, which made a scaled model stiff
    beyond its sub-step limit); such a model now refuses to scale."""
    import dataclasses

    from damper.io.model_file import parameter_unit
    from damper.models.registry import MODELS
    for name, cls in MODELS.items():
        for f in dataclasses.fields(cls):
            if f.name != "voltage_range":
                assert parameter_unit(name, f.name) is not None, (name, f.name)


def test_scaled_spencer_base_scales_its_series_elements(tmp_path):
    base = SpencerBoucWen(2180.0, 890.0, 600.0, 650.0, 27700.0, 1.08e4, 0.67, 1.1, field_lag=0.0067,
                          voltage_range=(0.0, 2.3))
    mf = read_model_file(write_model_file(tmp_path / "s.json", base))
    big = mf.scaled(400.0).model
    for p in ("kappa_x", "k0", "kappa_xdot", "kappa_w", "c1"):
        assert getattr(big, p).value(1.0) == pytest.approx(400.0 * getattr(base, p).value(1.0)) \
            if hasattr(getattr(base, p), "value") else getattr(big, p) == pytest.approx(400.0 * getattr(base, p))
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.01 * np.sin(2 * np.pi * t)
    np.testing.assert_allclose(simulate(big, t, x, v=1.0).force, 400.0 * simulate(base, t, x, v=1.0).force,
                               rtol=1e-9, atol=1e-6)


def test_field_starts_off_when_the_range_reaches_below_zero():
    """A range read from measurements may dip below 0 V (the Dyke channel: -0.44 V); the field of a
    coil without command is 0, not the bottom of the range."""
    base = SpencerBoucWen(0.0, 890.0, 600.0, 650.0, 27700.0, 1.08e4, 0.67, 1.1, field_lag=0.0067,
                          voltage_range=(-0.44, 2.3))
    assert base.initial_state()[2] == 0.0
    assert SpencerBoucWen(0.0, 890.0, 600.0, 650.0, 27700.0, 1.08e4, 0.67, 1.1,
                          voltage_range=(0.5, 2.3)).initial_state()[2] == 0.5


def test_scaling_multiplies_every_force(tmp_path):
    mf = read_model_file(_write(tmp_path))
    big = mf.scaled(400.0)
    assert big.scale == 400.0
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.01 * np.sin(2 * np.pi * t)
    small_force = simulate(mf.building_model()[0], t, x, v=1.0).force
    big_force = simulate(big.building_model()[0], t, x, v=1.0).force
    np.testing.assert_allclose(big_force, 400.0 * small_force, rtol=1e-9, atol=1e-6)
    assert capacity_force(big.building_model()[0]) == pytest.approx(400.0 * capacity_force(mf.building_model()[0]),
                                                                    rel=1e-9)


def test_extended_and_constant_models(tmp_path):
    model = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 2e5)), kappa_w=5e4, rho=40.0,
                            sigma=1.0, n=1.5)
    mf = read_model_file(write_model_file(tmp_path / "e.json", model))
    assert mf.model == model and mf.input.quantity == "voltage" and mf.building_model() == (model, [])


def _bad(tmp_path, mutate, name="bad.json"):
    doc = json.loads(_write(tmp_path, "good.json").read_text())
    mutate(doc)
    path = tmp_path / name
    path.write_text(json.dumps(doc) if not isinstance(doc, str) else doc)
    return path


@pytest.mark.parametrize("mutate, words", [
    (lambda d: d.update(model="bouc_wen_typo"), "unknown model 'bouc_wen_typo'"),
    (lambda d: d["parameters"].pop("rho"), "missing rho"),
    (lambda d: d["parameters"].update(kappa_x={"value": 1.0, "unit": "N/m"}), "kappa_x not a parameter"),
    (lambda d: d["parameters"]["kappa_w"].update(unit="kN"), "unit 'kN'; expected N"),
    (lambda d: d["parameters"]["rho"].pop("unit"), "unit missing"),
    (lambda d: d["parameters"]["kappa_w"].update(inputs=[0.0, 0.5, 2.0]), "outside the input range"),
    (lambda d: d["parameters"]["kappa_w"].update(values=[130.0, -700.0, 1130.0]), "kappa_w"),
    (lambda d: d["parameters"]["sigma"].update(value=0.2), "sigma"),
    (lambda d: d.update(format="something"), "format"),
    (lambda d: d.update(extra_field=1), "unknown field(s) extra_field"),
    (lambda d: d["effects"].append({"name": "magic", "value": 1.0, "unit": "N"}), "unknown effect 'magic'"),
    (lambda d: d["effects"][0].update(unit="mm/s"), "expected m/s"),
    (lambda d: d["input"].update(unit="V"), "input.unit"),
    (lambda d: d["parameters"]["kappa_w"].update(law="cubic"), "law"),
])
def test_bad_files_refused_in_one_line(tmp_path, mutate, words):
    path = _bad(tmp_path, mutate)
    with pytest.raises(InputError) as info:
        read_model_file(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message and words in message


def test_not_json_and_missing_file(tmp_path):
    path = tmp_path / "x.json"
    path.write_text("{not json")
    with pytest.raises(InputError, match="not a JSON file"):
        read_model_file(path)
    with pytest.raises(DataNotFoundError, match="not found"):
        read_model_file(tmp_path / "none.json")


def test_write_is_atomic(tmp_path):
    class Unserialisable:
        pass
    with pytest.raises(TypeError):
        write_model_file(tmp_path / "m.json", _augmented().base, quality={"x": Unserialisable()})
    assert list(tmp_path.iterdir()) == []


def test_oscillator_file_is_not_a_building_device(tmp_path):
    from damper.hysteresis import noel_schoukens as hb
    from damper.hysteresis.files import save_model
    path = save_model(tmp_path / "osc.json", hb.true_system(), fs=750.0)
    mf = read_model_file(path)
    with pytest.raises(InputError) as info:
        mf.building_model()
    assert "\n" not in str(info.value) and "force-driven oscillator" in str(info.value)


def test_a_statistic_that_could_not_be_estimated_is_written_as_null(tmp_path):
    """``sbib identify --data A B --bootstrap 1``: standard errors from one refit are NaN, which
    strict JSON cannot hold (it raised ValueError after the fits); they are unknown: null."""
    spec = InputSpec("current", "A", (0.0, 1.0), (0.0, 0.5, 1.0))
    path = write_model_file(tmp_path / "m.json", _augmented(), input=spec,
                            quality={"standard_errors": {"rho": float("nan"), "n": np.float64(0.1)},
                                     "held_out": [0.08, float("inf")]},
                            provenance={"inputs": [], "command": "test"})
    doc = json.loads(path.read_text())
    assert doc["quality"]["standard_errors"] == {"rho": None, "n": 0.1}
    assert doc["quality"]["held_out"] == [0.08, None]
    assert read_model_file(path).quality["standard_errors"]["rho"] is None
