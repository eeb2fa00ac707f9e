"""Device layout and building assembly: default layout, kinematics, validation, linear model."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.simulator.devices import DEFAULT_X_POSITIONS, DEFAULT_Y_POSITIONS, DeviceLayout, DeviceSlot
from benchmark.foundation.errors import InputError
from benchmark.simulator.linear_model import equivalent_linear_bearing, linear_model
from benchmark.simulator.sensors import measurement_names, noise_samples
from benchmark.simulator.structure import load_superstructure, transformation


@pytest.fixture(scope="module")
def structure_path(shared_dir):
    return shared_dir / "benchmark" / "structure.json"


def test_default_layout_is_documented_and_balanced(structure_path):
    layout = DeviceLayout.default()
    assert layout.n_devices == 16
    assert np.sum(layout.directions == 0) == 8 and np.sum(layout.directions == 1) == 8
    # Every device sits at a bearing position; each direction's devices are centred near the CM.
    bearings = {tuple(p) for p in load_superstructure(structure_path).bearing_xy}
    assert all(tuple(p) in bearings for p in DEFAULT_X_POSITIONS + DEFAULT_Y_POSITIONS)
    assert abs(np.mean([y for _, y in DEFAULT_X_POSITIONS])) < 1.0
    assert abs(np.mean([x for x, _ in DEFAULT_Y_POSITIONS])) < 3.0
    np.testing.assert_array_equal(layout.voltage_max, 1.0)


def test_device_kinematics_follow_the_base():
    layout = DeviceLayout.default()
    G = layout.influence()
    T = transformation(layout.xy)
    ub = np.array([0.1, -0.05, 0.002])
    expected = np.array([T[j] @ ub for j in range(16)])[np.arange(16), layout.directions]
    np.testing.assert_allclose(G @ ub, expected)
    # A device force F along x at (x, y) acts on the base as (F, 0, −y F).
    j = 0
    f = G[j] * 1000.0
    np.testing.assert_allclose(f, [1000.0, 0.0, -layout.xy[j, 1] * 1000.0])


def test_slot_validation():
    model = DeviceLayout.default().models[0]
    with pytest.raises(InputError, match="direction"):
        DeviceSlot(0.0, 0.0, "z", model)
    with pytest.raises(InputError, match="not a damper model"):
        DeviceSlot(0.0, 0.0, 0, object())
    with pytest.raises(InputError, match="finite"):
        DeviceSlot(np.nan, 0.0, 0, model)
    with pytest.raises(InputError, match="at least one"):
        DeviceLayout(())


def test_building_default_and_variants(structure_path):
    b = Building.default(structure_path=structure_path)
    assert b.isolation.name == "friction-lrb" and b.n_devices == 16 and b.n_bearings == 92
    assert b.without_devices().devices is None
    assert b.reduced(9).superstructure.n_q == 9
    assert b.with_isolation("linear").isolation.name == "linear"
    Kb, Cb = b.with_isolation("linear").isolation_linear_matrices()
    np.testing.assert_allclose(Kb, 919.422e3 * b.superstructure.H)
    np.testing.assert_allclose(Cb, 27.717e3 * b.superstructure.H)
    with pytest.raises(InputError, match="devices"):
        Building.default(devices="many", structure_path=structure_path)


def test_linear_model_isolated_periods_and_shapes(structure_path):
    b = Building.default(isolation="linear", structure_path=structure_path)
    lm = linear_model(b)
    # Isolated periods of the linear configuration (DOMAIN.md §1: 3.38/3.18/2.67 s).
    np.testing.assert_allclose(lm.isolated_periods(), [3.38, 3.18, 2.67], atol=0.01)
    assert lm.A.shape == (54, 54) and lm.B.shape == (54, 16) and lm.E.shape == (54, 2)
    assert lm.C.shape == (62, 54) and lm.D.shape == (62, 16)
    assert len(lm.output_names) == 62 and lm.output_names[27] == "u_base_x [m]"
    assert np.all(np.linalg.eigvals(lm.A).real < 0)
    ss = lm.to_statespace()
    assert ss.ninputs == 18 and ss.noutputs == 62


def test_equivalent_linearisation(structure_path):
    from benchmark.simulator.isolation.configurations import get_isolation

    layer = get_isolation("friction-lrb")
    lrb = layer.groups[1].bearing
    k, c = equivalent_linear_bearing(lrb, amplitude=0.2, period=3.0)
    # First-harmonic (describing-function) stiffness: between the post-yield and the secant one.
    secant = lrb.post_yield_stiffness + lrb.characteristic_strength / 0.2
    assert lrb.post_yield_stiffness < k < secant
    # Energy-equivalent damping: loop area ≈ 4 Qd (a − Y) = π c ω a².
    omega = 2 * np.pi / 3.0
    area = 4 * lrb.characteristic_strength * (0.2 - lrb.yield_displacement)
    assert c == pytest.approx(area / (np.pi * omega * 0.2 ** 2), rel=0.1)
    lin = get_isolation("linear").groups[0].bearing
    assert equivalent_linear_bearing(lin, 0.1, 3.0) == pytest.approx((lin.k, lin.c), rel=1e-6)
    with pytest.raises(InputError, match="amplitude"):
        equivalent_linear_bearing(lin, 0.0, 3.0)


def test_noise_samples_and_names():
    assert len(measurement_names(2)) == 34
    samples, ranges = noise_samples(np.full(34, 0.1), 1000, 2, seed=3)
    assert samples.shape == (1000, 34) and np.all(np.isinf(ranges))
    assert samples.std() == pytest.approx(0.1, rel=0.05)
    again, _ = noise_samples(np.full(34, 0.1), 1000, 2, seed=3)
    np.testing.assert_array_equal(samples, again)
    with pytest.raises(InputError, match="ambiguous"):
        noise_samples(0.1, 10, 2)
    with pytest.raises(InputError, match="shape"):
        noise_samples(np.zeros((5, 3)), 10, 2)
