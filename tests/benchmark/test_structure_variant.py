"""A variant of the benchmark's structure file: its weight and bearing plan reach the named
isolation layers, through the API, ``SBIB_STRUCTURE`` and ``--structure`` (run and compare).

The variant scales every mass by 1.2 (mode shapes renormalised, so ΦᵀMΦ = I still holds and the
fixed-base frequencies are unchanged) and keeps the first 82 of the 92 bearings.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.paths import structure_file
from benchmark.simulator.building import Building
from benchmark.simulator.isolation.configurations import GRAVITY, TOTAL_MASS, WEIGHT_PER_BEARING, get_isolation
from benchmark.simulator.structure import load_superstructure

SCALE = 1.2
N_KEPT = 82


@pytest.fixture
def variant(shared_dir, tmp_path):
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    for key in ("floor_mass", "floor_rot_inertia"):
        data[key] = [SCALE * m for m in data[key]]
    data["base_mass"] *= SCALE
    data["base_rot_inertia"] *= SCALE
    data["mode_shapes_floor8_to_floor1"] = (np.asarray(data["mode_shapes_floor8_to_floor1"])
                                            / math.sqrt(SCALE)).tolist()
    data["bearing_xy"] = data["bearing_xy"][:N_KEPT]
    path = tmp_path / "variant.json"
    path.write_text(json.dumps(data))
    return path, data


def _weights(layer):
    return [g.bearing.weight for g in layer.groups if hasattr(g.bearing, "weight")]


def test_named_layer_carries_the_variants_weight(variant):
    path, _ = variant
    building = Building.default(structure_path=path)
    sup = building.superstructure
    # masses are read in t and converted: the total follows the scale to rounding
    assert sup.total_mass == pytest.approx(SCALE * TOTAL_MASS, rel=1e-12)
    layer = building.isolation
    assert layer.n_bearings == N_KEPT == sup.n_bearings
    w = SCALE * TOTAL_MASS * GRAVITY / N_KEPT
    assert _weights(layer) == [pytest.approx(w, rel=1e-12)]
    # the benchmark's 61-of-92 share of sliding bearings on the smaller plan: 54 of 82
    sizes = [len(g.indices) for g in layer.groups]
    assert sizes == [54, 28]
    # the lead-rubber bearings' post-yield stiffness matches the pendulums' W/R, as in the benchmark
    lrb = layer.groups[1].bearing
    assert lrb.k_initial * lrb.alpha == pytest.approx(w / 2.24, rel=1e-12)
    # and with_isolation by name does the same
    again = Building.default(structure_path=path, isolation="linear").with_isolation("friction-pendulum")
    assert _weights(again.isolation) == [pytest.approx(w, rel=1e-12)]
    assert again.isolation.n_bearings == N_KEPT


def test_benchmark_structure_keeps_the_benchmark_layer(shared_dir):
    building = Building.default(structure_path=shared_dir / "benchmark" / "structure.json")
    assert _weights(building.isolation) == [pytest.approx(WEIGHT_PER_BEARING, rel=1e-12)]
    assert [len(g.indices) for g in building.isolation.groups] == [61, 31]


def test_sbib_structure_environment_variable(variant, monkeypatch):
    path, _ = variant
    monkeypatch.setenv("SBIB_STRUCTURE", str(path))
    assert structure_file() == path
    assert load_superstructure().n_bearings == N_KEPT
    monkeypatch.setenv("SBIB_STRUCTURE", str(path.parent / "absent.json"))
    with pytest.raises(DataNotFoundError, match="SBIB_STRUCTURE"):
        structure_file()


def test_a_floor_count_its_fields_do_not_have_is_refused(variant, tmp_path):
    # other heights are read (tests/benchmark/test_floor_count.py); 10 floors of 8 floors' data are not
    _, data = variant
    path = tmp_path / "ten.json"
    path.write_text(json.dumps({**data, "n_floors": 10}))
    with pytest.raises(InputError, match="'floor_mass' has 8 entries, expected 10 for n_floors = 10"):
        load_superstructure(path)


def test_bad_mass_or_count_for_named_layer():
    with pytest.raises(InputError, match="total_mass"):
        get_isolation("friction-lrb", total_mass=-1.0)
    with pytest.raises(InputError, match="n_bearings"):
        get_isolation("friction-lrb", n_bearings=1)


def _sbib(*args, env=None):
    return subprocess.run([sys.executable, "-m", "benchmark", *args], capture_output=True, text=True,
                          env=env, timeout=600)


def test_run_and_compare_take_structure(variant, shared_dir, tmp_path):
    path, data = variant
    run = _sbib("run", "--record", "kobe", "--orientation", "FN-x", "--json", "--structure", str(path))
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["structure"]["n_bearings"] == N_KEPT
    assert out["structure"]["total_mass_kg"] == pytest.approx(SCALE * TOTAL_MASS, rel=1e-12)
    assert "note: structure" in run.stderr
    base = _sbib("run", "--record", "kobe", "--orientation", "FN-x", "--json")
    assert base.returncode == 0, base.stderr
    # a heavier building on the same friction (per unit weight) sheds a larger base shear
    ratio = out["peaks"]["peak_base_shear"] / json.loads(base.stdout)["peaks"]["peak_base_shear"]
    assert 1.05 < ratio < 1.4
    # compare's worker processes read the same variant (SBIB_STRUCTURE set by --structure)
    cmp_ = _sbib("compare", "--records", "kobe", "--orientations", "FN-x", "--controllers", "passive-off",
                 "--jobs", "2", "--no-progress", "--json", "--structure", str(path))
    assert cmp_.returncode == 0, cmp_.stderr
    row = json.loads(cmp_.stdout)["runs"][0]
    assert row["peaks"]["peak_base_shear"] > 1.05 * json.loads(base.stdout)["peaks"]["peak_base_shear"]
    # a malformed variant: one line, exit status 2, nothing run
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({**data, "floor_mass": data["floor_mass"][:7]}))
    failed = _sbib("run", "--record", "kobe", "--structure", str(bad))
    assert failed.returncode == 2
    assert failed.stderr.strip().count("\n") == 0 and "floor_mass" in failed.stderr


def _edited(shared_dir, tmp_path, **fields):
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    data.update(fields)
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("plan", [[[0.0, 0.0]] * 92, [[float(i), 2.0 * i] for i in range(92)]])
def test_a_plan_that_spans_no_area_is_refused_on_reading(shared_dir, tmp_path, plan):
    """A review (2026-11-26): coincident or collinear bearings ran the whole record, then raised
    scipy's QhullError when the corners were sought."""
    with pytest.raises(InputError, match="span no area"):
        load_superstructure(_edited(shared_dir, tmp_path, bearing_xy=plan))


def test_a_structure_file_that_is_not_an_object(tmp_path):
    path = tmp_path / "list.json"
    path.write_text("[1, 2, 3]")
    with pytest.raises(InputError, match="a JSON list; expected an object"):
        load_superstructure(path)


def test_devices_off_the_base_are_refused(shared_dir, tmp_path):
    """The default layout on a plan a tenth the size: its devices lie 40 m off the base."""
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    small = _edited(shared_dir, tmp_path, bearing_xy=(0.1 * np.asarray(data["bearing_xy"])).tolist())
    Building.default(structure_path=small, devices=None)  # no devices: nothing to place
    with pytest.raises(InputError, match=r"devices: x1 at \(-7.32, 30.69\) m lies off the base"):
        Building.default(structure_path=small)


def test_a_misspelt_structure_field_is_refused(variant, tmp_path):
    """A field close to one sbib reads is a misspelling (``n_floor`` would leave the floor count
    unchecked); fields that resemble none are the file's own notes and are read past."""
    _, data = variant
    path = tmp_path / "typo.json"
    path.write_text(json.dumps({**data, "n_floor": 10}))
    with pytest.raises(InputError, match="did you mean 'n_floors'"):
        load_superstructure(path)
    path.write_text(json.dumps({**data, "retrofit_year": 2024}))
    assert load_superstructure(path).base_mass > 0


def test_the_structure_files_linear_bearing_reaches_the_linear_layer(shared_dir, tmp_path):
    """A probe's variant with k = 1500 kN/m and c = 60 kN·s/m ran with the benchmark's 919.4 and
    27.7 (the field was accepted and ignored): its peak base displacement was the benchmark's."""
    path = _edited(shared_dir, tmp_path, fdz_linear_bearing={"k_per_bearing_kN_per_m": 1500,
                                                             "c_per_bearing_kNs_per_m": 60, "note": "stiffer"})
    bearing = Building.default(structure_path=path, isolation="linear", devices=None).isolation.groups[0].bearing
    assert (bearing.k, bearing.c) == (1.5e6, 6.0e4)
    default = Building.default(isolation="linear", devices=None).isolation.groups[0].bearing
    assert (default.k, default.c) == pytest.approx((919.422e3, 27.717e3), rel=1e-12)
    with pytest.raises(InputError, match="'fdz_linear_bearing.k_per_bearing_kN_per_m' = 'x'"):
        load_superstructure(_edited(shared_dir, tmp_path, fdz_linear_bearing={"k_per_bearing_kN_per_m": "x",
                                                                              "c_per_bearing_kNs_per_m": 60}))


@pytest.mark.parametrize("field, value, shown", [("base_mass", True, "True"), ("modal_damping_ratio", "0.05", "'0.05'")])
def test_booleans_and_strings_are_not_numbers_in_a_structure_file(shared_dir, tmp_path, field, value, shown):
    # numpy reads true as 1 (a base of 1 t ran) and "2051" as 2051
    with pytest.raises(InputError, match=f"field '{field}' holds {shown}; expected numbers"):
        load_superstructure(_edited(shared_dir, tmp_path, **{field: value}))
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    data["floor_mass"][3] = str(data["floor_mass"][3])
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="field 'floor_mass' holds"):
        load_superstructure(path)


@pytest.mark.parametrize("layer, words", [
    ({"name": "kN", "groups": [{"bearings": "1-92", "type": "linear", "parameters": {"k": 919.422, "c": 27.717}}]},
     "isolated period of"),
    ({"name": "kNfp", "groups": [{"bearings": "1-92", "type": "friction-pendulum",
                                  "parameters": {"weight": 2207.8, "radius": 2.24, "mu_max": 0.06, "mu_min": 0.03,
                                                 "rate_parameter": 20.0, "yield_displacement": 5e-4}}]},
     "isolated period of"),
    ({"name": "heavy", "groups": [{"bearings": "1-92", "type": "friction-pendulum",
                                   "parameters": {"weight": 2.2e7, "radius": 2.24, "mu_max": 0.06, "mu_min": 0.03,
                                                  "rate_parameter": 20.0, "yield_displacement": 5e-4}}]},
     "carry 2024 MN together, the building weighs 203 MN"),
])
def test_an_isolation_file_in_other_units_is_refused(tmp_path, layer, words):
    """A probe's linear bearings in kN/m (a 98-s period: the base moved with the ground) and its
    pendulums' weights in kN ran without a word."""
    path = tmp_path / "iso.json"
    path.write_text(json.dumps(layer))
    with pytest.raises(InputError, match=words):
        Building.default(isolation=str(path), devices=None)


def test_a_layer_for_92_bearings_on_another_plan_says_to_give_n_bearings(variant, tmp_path):
    path, _ = variant
    iso = tmp_path / "iso.json"
    iso.write_text(json.dumps({"name": "lrb", "groups": [{"bearings": f"1-{N_KEPT}", "type": "linear",
                                                          "parameters": {"k": 1e6, "c": 3e4}}]}))
    with pytest.raises(InputError, match='give its "n_bearings"'):
        Building.default(isolation=str(iso), structure_path=path, devices=None)


def test_a_device_in_a_notch_of_the_plan_is_refused(shared_dir):
    """Inside the L-shaped plan's bounding box but 17.5 m from every bearing: off the slab."""
    from benchmark.simulator.devices import DeviceLayout, DeviceSlot
    from damper.models.registry import get_model_class
    model = get_model_class("virtual")()
    layout = DeviceLayout((DeviceSlot(30.0, -40.0, 0, model, "notch"), DeviceSlot(0.0, 0.0, 1, model, "in")))
    with pytest.raises(InputError, match=r"notch at \(30, -40\) m is .* from the nearest bearing"):
        Building.default(devices=layout)
    with pytest.raises(InputError, match="x = True; expected a position in m"):
        DeviceSlot(True, 0.0, 0, model, "x")


def test_bearing_loops_are_drawn_for_a_plan_of_another_size(variant, tmp_path, records_dir):
    """The figure's default bearings were 0 and 91: a 60-bearing plan failed and --json was lost."""
    from benchmark.simulator.plots import plot_bearing_hysteresis
    from benchmark.simulator.simulation import simulate
    from records import load_benchmark_record
    path, _ = variant
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    short = record.replace(acceleration=record.acceleration[:400].copy())
    result = simulate(Building.default(structure_path=path, devices=None), short, bearing_histories=True)
    assert plot_bearing_hysteresis(result, tmp_path / "b.png").stat().st_size > 10_000
