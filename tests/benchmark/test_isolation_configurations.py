"""Isolation configurations: grouping, packing, named layers, periods, JSON files."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import scipy.linalg

from benchmark.foundation.errors import DataNotFoundError, InputError, ParameterError
from benchmark.simulator.isolation import (BearingGroup, IsolationLayer, LinearBearing, MAX_PARAMS, MAX_STATES,
                                 get_isolation, isolation_from_dict, load_isolation)
from benchmark.simulator.isolation.configurations import (DEFAULT_NONLINEAR, ISOLATION_NAMES, TOTAL_MASS,
                                                parse_bearing_numbers)


def test_linear_configuration_values():
    layer = get_isolation("linear")
    assert layer.is_linear and layer.n_bearings == 92
    assert np.all(layer.linear_stiffness() == 919.422e3)
    assert np.all(layer.linear_damping() == 27.717e3)
    packed = layer.pack()
    assert packed.params.shape == (92, MAX_PARAMS) and packed.states.shape[0] == 92
    assert np.all(packed.type_ids == 0) and np.all(packed.n_states == 0)


def test_default_nonlinear_layer_groups_1_61_and_62_92():
    layer = get_isolation(DEFAULT_NONLINEAR)
    packed = layer.pack()
    assert np.all(packed.type_ids[:61] == 2) and np.all(packed.type_ids[61:] == 1)
    assert packed.states.shape == (92, MAX_STATES)
    assert np.all(packed.n_states == 2)
    assert not layer.is_linear
    d = layer.describe()
    assert [g["bearings"] for g in d["groups"]] == ["1-61", "62-92"]


def test_total_mass_constant_matches_structure_file(shared_dir):
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    assert TOTAL_MASS == pytest.approx((sum(data["floor_mass"]) + data["base_mass"]) * 1e3, rel=1e-12)


@pytest.mark.parametrize("name, periods", [
    ("linear", (3.38, 3.18, 2.67)),            # the published isolated periods of the FDZ values
    ("friction-lrb", (3.27, 3.08, 2.59)),      # post-yield periods of the default nonlinear layer
])
def test_isolated_periods_with_the_benchmark_masses(shared_dir, name, periods):
    from benchmark.simulator.structure import load_superstructure, location_matrix
    s = load_superstructure()
    layer = get_isolation(name)
    k = layer.linear_stiffness()
    # rigid-building estimate: post-yield (sliding) period near 3 s
    assert 2 * np.pi * np.sqrt(s.total_mass / k.sum()) == pytest.approx(3.05, abs=0.1)
    R = np.tile(np.eye(3), (8, 1))
    M = s.M
    Mt = np.block([[M, M @ R], [R.T @ M, R.T @ M @ R + s.m_base]])
    Kt = scipy.linalg.block_diag(s.K, location_matrix(s.bearing_xy, k))
    w2 = scipy.linalg.eigh(Kt, Mt, eigvals_only=True)[:3]
    assert 2 * np.pi / np.sqrt(w2) == pytest.approx(periods, abs=0.01)


def test_every_named_configuration_builds_and_describes():
    for name in ISOLATION_NAMES:
        layer = get_isolation(name)
        again = isolation_from_dict(json.loads(layer.to_json()))
        assert again.describe()["groups"] == layer.describe()["groups"]
        assert np.array_equal(again.pack().params, layer.pack().params)


def test_substep_tolerance_override():
    layer = get_isolation("friction-lrb", substep_tolerance=0.05)
    assert np.all(layer.pack().params[:61, 10] == 0.05)
    assert np.all(layer.pack().params[61:, 7] == 0.05)
    with pytest.raises(ParameterError, match="substep_tolerance"):
        get_isolation("friction-lrb", substep_tolerance=-1)


def test_grouping_errors_name_the_bearing():
    b = LinearBearing(1e6)
    with pytest.raises(ParameterError, match="bearing 5 is in groups 0 and 1"):
        IsolationLayer("x", (BearingGroup(b, range(0, 50)), BearingGroup(b, range(4, 92))))
    with pytest.raises(ParameterError, match="92 belong to no group"):
        IsolationLayer("x", (BearingGroup(b, range(0, 91)),))
    with pytest.raises(ParameterError, match="outside"):
        IsolationLayer("x", (BearingGroup(b, range(0, 93)),))
    with pytest.raises(InputError, match="unknown"):
        get_isolation("rubber-duck")


def test_parse_bearing_numbers():
    assert parse_bearing_numbers("1-3,7") == (0, 1, 2, 6)
    assert parse_bearing_numbers([92]) == (91,)
    with pytest.raises(InputError, match="outside 1..92"):
        parse_bearing_numbers("90-93")
    with pytest.raises(InputError, match="'a-b'"):
        parse_bearing_numbers("a-b")


def test_json_file_configuration(tmp_path):
    cfg = {"name": "mixed", "groups": [
        {"type": "linear", "bearings": "1-46", "parameters": {"k": 9e5, "c": 2e4}},
        {"type": "lead-rubber", "bearings": "47-92",
         "parameters": {"k_initial": 9e6, "alpha": 0.1, "yield_force": 1e5}}]}
    path = tmp_path / "layer.json"
    path.write_text(json.dumps(cfg))
    layer = get_isolation(str(path))
    assert layer.name == "mixed" and layer.pack().type_ids[46] == 1
    assert layer.linear_stiffness()[50] == pytest.approx(9e5)
    bad = dict(cfg, groups=[dict(cfg["groups"][0], bearings="1-92", parameters={"k": 1, "stiffness": 2})])
    path.write_text(json.dumps(bad))
    with pytest.raises(InputError, match=r"groups\[0\].parameters: unknown field"):
        load_isolation(path)
    path.write_text("{ not json")
    with pytest.raises(InputError, match="invalid JSON"):
        load_isolation(path)
    with pytest.raises(DataNotFoundError):
        load_isolation(tmp_path / "missing.json")


@pytest.mark.parametrize("params, words", [(5, "parameters = 5; expected an object"),
                                           ({"k": True, "c": 0.0}, "parameters.k = True; expected a number"),
                                           ({"k": "1e7", "c": 0.0}, "parameters.k = '1e7'; expected a number")])
def test_bearing_parameters_must_be_numbers(params, words):
    """A review (2026-11-26): a string weight passed the checks and failed in the bearing's
    stiffness with a traceback; ``true`` ran as k = 1 N/m."""
    data = {"name": "x", "n_bearings": 2, "groups": [{"type": "linear", "bearings": [1, 2], "parameters": params}]}
    with pytest.raises(InputError, match=re.escape(words)):
        isolation_from_dict(data)


def test_a_misspelt_field_is_refused_not_defaulted(tmp_path):
    """``"paramters"`` would have left every parameter of the group at its default, and
    ``"n_bearing"`` the count at 92, without a word."""
    group = {"type": "linear", "bearings": "1-92", "parameters": {"k": 9e5, "c": 2e4}}
    path = tmp_path / "layer.json"
    for cfg, message in (({"groups": [{**{k: v for k, v in group.items() if k != "parameters"},
                                       "paramters": group["parameters"]}]}, "did you mean 'parameters'"),
                         ({"groups": [{**group, "params": {}}]}, "did you mean 'parameters'"),
                         ({"groups": [{**group, "stiffness": 1.0}]}, "expected bearings, label, parameters, type"),
                         ({"n_bearing": 92, "groups": [group]}, "did you mean 'n_bearings'")):
        path.write_text(json.dumps(cfg))
        with pytest.raises(InputError, match=message) as info:
            load_isolation(path)
        assert str(path) in str(info.value) and "\n" not in str(info.value)
    # free-form notes are read past, at the top and in a group
    path.write_text(json.dumps({"name": "ok", "comment": "a test rig", "groups": [{**group, "note": "all linear"}]}))
    assert load_isolation(path).name == "ok"
