"""``result.peaks``: named peaks with units, never the max over mixed x, y, θ columns (issue #16, 14)."""

from __future__ import annotations

import dataclasses
from dataclasses import fields
from types import SimpleNamespace

import numpy as np
import pytest

from benchmark.simulator.evaluation import J_NAMES, evaluate
from benchmark.simulator.peaks import PEAK_FIELD_UNITS, PEAK_NAMES, PEAK_RECORD_KEYS, Peaks, peaks_of


def fake_result(n_devices=0, rotation=0.0, n=2001):
    """A base moving on a circle of radius 0.3 m (resultant peak known exactly)."""
    t = np.linspace(0.0, 10.0, n)
    c, s = np.cos(np.pi * t), np.sin(np.pi * t)
    ub = np.stack([0.3 * c, 0.3 * s, rotation * c], axis=1)
    drift = np.zeros((n, 8, 2))
    drift[:, :, 0] = 0.002 * c[:, None]
    acc = np.zeros((n, 8, 3))
    acc[:, :, 0] = c[:, None] * np.linspace(1.0, 1.7, 8)
    shear = np.stack([4e6 * c, 4e6 * s, np.zeros_like(t)], axis=1)
    device_force = np.zeros((n, n_devices))
    device_total = np.zeros((n, 3))
    if n_devices:
        device_force[:, 0] = 1e6 * c
        device_total[:, 0] = 1e6 * c
    return SimpleNamespace(t=t, base_displacement=ub, drift_ratio=drift, floor_acceleration_absolute=acc,
                           base_shear=shear, structure_shear=0.5 * shear, device_force=device_force,
                           device_force_total=device_total, energy={}, info={})


def test_peaks_of_a_known_response_are_named_and_in_si():
    r = fake_result(n_devices=1, rotation=-0.002)
    p = peaks_of(r)
    assert isinstance(p, Peaks)
    # a circle of radius 0.3 m: the resultant peak is 0.3 m, each direction 0.3 m too
    assert p.base_displacement == pytest.approx(0.3)
    assert p.base_displacement_x == pytest.approx(0.3)
    assert p.base_displacement_y == pytest.approx(0.3, rel=1e-3)
    assert p.base_rotation == pytest.approx(0.002)
    assert p.base_shear == pytest.approx(4e6)
    assert p.device_force == pytest.approx(1e6)
    assert p.single_device_force == pytest.approx(1e6)
    assert set(p.units) == {f.name for f in fields(p)} == set(PEAK_FIELD_UNITS)
    assert p.units["base_displacement"] == "m" and p.units["base_rotation"] == "rad"
    assert "base_displacement" in str(p) and " m" in str(p)


def test_file_record_uses_the_one_mapping_of_fields_to_keys():
    r = fake_result(n_devices=1)
    p = peaks_of(r)
    q = p.as_record()
    assert tuple(q) == PEAK_NAMES
    assert all(q[key] == getattr(p, name) for name, key in PEAK_RECORD_KEYS.items())
    assert q["peak_base_displacement"] == p.base_displacement
    assert q["peak_device_force"] == p.device_force
    assert p.base_torque == pytest.approx(float(np.max(np.abs(r.base_shear[:, 2]))))


def test_relative_differences_of_two_runs():
    p = peaks_of(fake_result(n_devices=1))
    q = dataclasses.replace(p, base_shear=2 * p.base_shear)
    d = p.relative_differences(q)
    assert d["base_shear"] == pytest.approx(-0.5) and d["base_displacement"] == 0.0
    none = peaks_of(fake_result())
    assert none.relative_differences(none)["device_force"] == 0.0


def test_simulation_result_has_named_peaks_and_js(shared_dir):
    """The README's API: ``result.peaks`` and ``evaluate(result, reference)`` on a real run."""
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import Record

    t = np.arange(0.0, 4.0, 0.005)
    ag = np.stack([3.0 * np.sin(2 * np.pi * 0.7 * t), 1.5 * np.sin(2 * np.pi * 0.4 * t)], axis=1)
    record = Record(name="pulse", dt=0.005, acceleration=ag, labels=("x", "y"))
    building = Building.default(isolation="linear",
                                structure_path=shared_dir / "benchmark" / "structure.json")
    reference = simulate(building, record)
    result = simulate(building, record, controller="passive-on")
    ub = result.base_displacement
    expected = float(np.max(np.hypot(ub[:, 0], ub[:, 1])))
    assert result.peaks.base_displacement == pytest.approx(expected, rel=1e-12)
    # the pitfall the issue reports: the flat max mixes x, y [m] and θ [rad]
    assert result.base_displacement.max() != pytest.approx(expected)
    assert result.peaks.base_rotation == pytest.approx(float(np.max(np.abs(ub[:, 2]))))
    J = evaluate(result, reference)
    assert tuple(J) == J_NAMES
    assert J["J3"] == pytest.approx(result.peaks.base_displacement / reference.peaks.base_displacement)
    assert reference.peaks.device_force == 0.0 and J["J6"] is not None
    assert isinstance(result.energy_balance_error(), float)
    assert 0.0 <= result.energy_balance_error() < 1e-2


def test_readme_kobe_example_numbers_match_result_peaks(shared_dir, records_dir):
    """The README's Kobe example (peak base displacement, J3, J5, J9) is what ``result.peaks`` and
    ``evaluate`` give today, so the numbers a reader compares with cannot drift."""
    import re
    from pathlib import Path

    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import load_benchmark_record

    readme = " ".join((Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8").split())
    m = re.search(r"Example \(Kobe FN-x, `friction-lrb`, clipped-optimal[^)]*\): peak base displacement "
                  r"(?P<ub>[\d.]+) m \(J3 = (?P<J3>[\d.]+) of the uncontrolled (?P<ub0>[\d.]+) m\), peak floor "
                  r"acceleration (?P<acc>[\d.]+) m/s² \(J5 = (?P<J5>[\d.]+)\), peak drift ratio "
                  r"(?P<drift>[\d.]+) %, J9 = (?P<J9>[\d.]+)\.", readme)
    assert m, "README's Kobe example sentence not found (update this test with the README)"
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    building = Building.default(structure_path=shared_dir / "benchmark" / "structure.json")
    reference = simulate(building, record)
    result = simulate(building, record, controller="clipped-optimal")
    J = evaluate(result, reference)
    assert result.peaks.base_displacement == pytest.approx(float(m["ub"]), abs=0.0005)
    assert reference.peaks.base_displacement == pytest.approx(float(m["ub0"]), abs=0.0005)
    assert result.peaks.floor_acceleration == pytest.approx(float(m["acc"]), abs=0.005)
    assert 100 * result.peaks.drift_ratio == pytest.approx(float(m["drift"]), abs=0.005)
    for j in ("J3", "J5", "J9"):
        assert J[j] == pytest.approx(float(m[j]), abs=0.005), j
