"""J1–J9, peaks and corner responses on results whose answers are known in closed form."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from benchmark.simulator.peaks import peaks_of
from benchmark.simulator.evaluation import (J_NAMES, PEAK_NAMES, corner_responses, evaluate,
                                  plan_corners)

H = np.array([4.42] * 4 + [3.66] * 4)


def fake_result(scale=1.0, n_devices=0, n=2001, record="kobe", rotation=0.0):
    """Circular responses of constant resultant, so peaks and RMS are known exactly."""
    t = np.linspace(0.0, 10.0, n)
    w = 2 * np.pi * 0.5
    c, s = np.cos(w * t), np.sin(w * t)
    ub = np.stack([0.3 * scale * c, 0.3 * scale * s, rotation * np.ones_like(t)], axis=1)
    floor = np.zeros((n, 8, 3))
    floor_acc = np.zeros((n, 8, 3))
    for f in range(8):
        floor[:, f, 0] = 0.01 * (f + 1) * scale * c    # storey drift 0.01 m in every storey
        floor_acc[:, f, 0] = (1.0 + 0.1 * f) * scale * c
        floor_acc[:, f, 1] = (1.0 + 0.1 * f) * scale * s
    drift = np.zeros((n, 8, 2))
    drift[:, :, 0] = 0.01 * scale * c[:, None] / H[None, :]
    base_shear = np.stack([4e6 * scale * c, 4e6 * scale * s, np.zeros_like(t)], axis=1)
    structure_shear = 0.5 * base_shear
    device_force = np.zeros((n, n_devices))
    device_total = np.zeros((n, 3))
    energy = {"input": np.linspace(0, 1e7, n), "device": np.zeros(n)}
    if n_devices:
        device_force[:, 0] = 1e6 * c
        device_total[:, 0] = 1e6 * c
        energy["device"] = np.linspace(0, 4e6, n)
    return SimpleNamespace(t=t, base_displacement=ub, floor_displacement=floor,
                           floor_acceleration_absolute=floor_acc, drift_ratio=drift,
                           base_shear=base_shear, structure_shear=structure_shear,
                           device_force=device_force, device_force_total=device_total,
                           energy=energy, info={"record": record, "orientation": "FN-x",
                                                "isolation": "linear"})


def test_peaks_known_values():
    p = peaks_of(fake_result()).as_record()
    assert tuple(p) == PEAK_NAMES
    assert p["peak_base_displacement"] == pytest.approx(0.3)
    assert p["rms_base_displacement"] == pytest.approx(0.3)
    assert p["peak_base_shear"] == pytest.approx(4e6)
    assert p["peak_structure_shear"] == pytest.approx(2e6)
    assert p["peak_drift_ratio"] == pytest.approx(0.01 / 3.66)
    assert p["peak_floor_acceleration"] == pytest.approx(1.7)
    assert p["rms_floor_acceleration"] == pytest.approx(1.7)
    assert p["peak_device_force"] == 0.0


def test_reference_against_itself_gives_ones_and_no_device_criteria():
    r = fake_result()
    J = evaluate(r, r)
    assert tuple(J) == J_NAMES
    for k in ("J1", "J2", "J3", "J4", "J5", "J7", "J8"):
        assert J[k] == pytest.approx(1.0)
    assert J["J6"] is None and J["J9"] is None


def test_controlled_run_ratios():
    J = evaluate(fake_result(scale=0.6, n_devices=2), fake_result())
    for k in ("J1", "J2", "J3", "J4", "J5", "J7", "J8"):
        assert J[k] == pytest.approx(0.6)
    assert J["J6"] == pytest.approx(1e6 / (0.6 * 4e6))
    assert J["J9"] == pytest.approx(0.4)


def test_mismatched_cases_are_refused():
    with pytest.raises(InputError, match="record"):
        evaluate(fake_result(record="kobe"), fake_result(record="jiji"))
    with pytest.raises(InputError, match="samples"):
        evaluate(fake_result(n=100), fake_result(n=101))
    with pytest.raises(InputError, match="base_shear"):
        peaks_of(SimpleNamespace())


def test_zero_reference_gives_none():
    ref = fake_result(scale=0.0)
    J = evaluate(fake_result(), ref)
    assert J["J1"] is None and J["J3"] is None


def test_corner_responses_rotation_and_drift():
    corners = np.array([[-17.25, 30.69], [32.83, -11.16]])
    res = fake_result(rotation=0.001)
    out = corner_responses(res, corners=corners, storey_heights=H)
    # base corner: translation (0.3 circle) plus the rotation's (-θ y, θ x)
    ub = res.base_displacement
    expected = [np.max(np.hypot(ub[:, 0] - 0.001 * cy, ub[:, 1] + 0.001 * cx)) for cx, cy in corners]
    assert out["peak_corner_base_displacement"] == pytest.approx(expected)
    assert out["max_corner_base_displacement"] > peaks_of(res).base_displacement
    # no floor rotation: corner drift = centre drift = 0.01 m / storey height
    assert out["peak_corner_drift_ratio"] == pytest.approx([0.01 / 3.66] * 2)


def test_plan_corners_of_the_benchmark(shared_dir):
    from benchmark.simulator.structure import load_superstructure
    c = plan_corners(load_superstructure().bearing_xy)
    assert {tuple(p) for p in c} == {(-17.25, 30.69), (-17.25, -47.79), (12.53, -47.79),
                                     (32.83, -11.16), (32.83, 30.69)}
    with pytest.raises(InputError):
        plan_corners(np.zeros((2, 2)))
