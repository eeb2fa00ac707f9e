"""Physics checks of the simulator: energy balance, zero input, sign and mirror symmetry.

* **Energy balance** (within 1 % of the input energy, at every step) for every named
  isolation configuration without devices, and with devices under a passive and a
  semi-active controller; the dissipated energies never decrease.
* **Zero record → zero response**, exactly, with and without devices and controllers.
* **Sign symmetry**: every bearing and damper model is odd, so the negated record gives the
  negated response, exactly (the same operations on negated numbers).
* **Mirror symmetry**: a *symmetric building variant* — superstructure stiffness and damping
  averaged over the reflections x → −x and y → −y of every floor, 92 bearings placed as 23
  quadruplets (±x, ±y) with the same type in each quadruplet, 16 devices as mirrored pairs —
  under a record and its mirror image (ẍ_g → −ẍ_g, or ÿ_g → −ÿ_g) gives the mirrored response:
  u_x → −u_x, θ → −θ (or u_y → −u_y, θ → −θ), bearing and device forces exchanged between
  mirror partners. The plan is not square, so x ↔ y swaps are not a symmetry.

Each run uses the first seconds of a benchmark record (and a short simulation each), so the
file stays within a few seconds.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

ISOLATIONS = ("linear", "friction-lrb", "lead-rubber", "friction-pendulum")


@pytest.fixture(scope="module")
def record(records_dir):
    from records import load_benchmark_record

    full = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    return full.replace(acceleration=full.acceleration[:1600])  # 8 s: the strong pulses of Kobe


@pytest.fixture(scope="module")
def building():
    from benchmark.simulator.building import Building

    return Building.default()


# ---------------------------------------------------------------------------------------------
# energy balance
# ---------------------------------------------------------------------------------------------
def _check_energy(result) -> None:
    e = result.energy
    assert e["input"][-1] > 0
    assert result.energy_balance_error() < 0.01, result.energy_balance_error()
    # viscous dissipation only accumulates (the hysteretic and device terms also hold the
    # recoverable energy stored in their hysteretic states, so they may decrease)
    assert np.all(np.diff(e["damping"]) >= -1e-9 * e["input"].max())
    assert np.all(e["kinetic"] >= 0) and np.all(e["strain"] >= -1e-9 * e["input"].max())


@pytest.mark.parametrize("isolation", ISOLATIONS)
def test_energy_balance_of_every_isolation_configuration(building, record, isolation):
    from benchmark.simulator.simulation import simulate

    result = simulate(building.with_isolation(isolation).without_devices(), record)
    _check_energy(result)
    if isolation != "linear":
        assert result.energy["hysteretic"][-1] > 0.05 * result.energy["input"][-1]


@pytest.mark.parametrize("controller", ["passive-on", "clipped-optimal"])
def test_energy_balance_with_devices(building, record, controller):
    from benchmark.simulator.simulation import simulate

    result = simulate(building, record, controller=controller)
    _check_energy(result)
    assert result.energy["device"][-1] > 0.05 * result.energy["input"][-1]


# ---------------------------------------------------------------------------------------------
# zero record, negated record
# ---------------------------------------------------------------------------------------------
FIELDS = ("base_displacement", "base_velocity", "base_acceleration_absolute", "floor_displacement",
          "floor_acceleration_absolute", "drift_ratio", "isolation_force", "device_force_total",
          "structure_shear", "bearing_force", "device_force", "device_displacement")


@pytest.mark.parametrize("controller", [None, "passive-on", "clipped-optimal"])
def test_zero_record_gives_zero_response(building, record, controller):
    from benchmark.simulator.simulation import simulate

    zero = record.replace(acceleration=np.zeros_like(record.acceleration[:400]))
    b = building if controller else building.without_devices()
    result = simulate(b, zero, controller=controller)
    for name in FIELDS:
        assert not np.any(getattr(result, name)), name
    assert not any(np.any(v) for v in result.energy.values())


@pytest.mark.parametrize("isolation, controller", [("linear", None), ("friction-lrb", None),
                                                   ("friction-lrb", "passive-on"),
                                                   ("friction-lrb", "clipped-optimal")])
def test_negated_record_gives_the_negated_response(building, record, isolation, controller):
    from benchmark.simulator.simulation import simulate

    b = building.with_isolation(isolation)
    b = b if controller else b.without_devices()
    plus = simulate(b, record, controller=controller)
    minus = simulate(b, record.replace(acceleration=-record.acceleration), controller=controller)
    for name in FIELDS:
        assert np.array_equal(getattr(minus, name), -getattr(plus, name)), name
    assert np.array_equal(minus.voltage, plus.voltage)
    for term, values in plus.energy.items():
        assert np.array_equal(minus.energy[term], values), term


# ---------------------------------------------------------------------------------------------
# mirror symmetry with a symmetric building variant
# ---------------------------------------------------------------------------------------------
def _reflection(axis: int) -> np.ndarray:
    """(3×3) action of the mirror on (u_x, u_y, θ): axis 0 flips x, axis 1 flips y; θ always flips."""
    p = np.ones(3)
    p[axis] = -1.0
    p[2] = -1.0
    return np.diag(p)


_SYMMETRIC: dict = {}


def symmetric_variant(axis: int):
    """A benchmark-like building symmetric under the mirror of ``axis`` only (0: x → −x, 1: y → −y).

    The superstructure's K and C are averaged over that reflection; the 92 bearings are the
    plan's first 46 positions and their mirror images (same type for both of a pair); 16 devices
    are the default layout's first 4 x- and 4 y-direction positions and their mirror images.
    The plan stays eccentric along the other axis, so translation along the mirrored axis
    couples with torsion. Returns (building, bearing permutation, device permutation), the
    permutations mapping each bearing/device to its mirror partner.
    """
    if axis in _SYMMETRIC:
        return _SYMMETRIC[axis]
    from benchmark.simulator.building import Building
    from benchmark.simulator.devices import DEFAULT_X_POSITIONS, DEFAULT_Y_POSITIONS, DeviceLayout
    from benchmark.simulator.isolation.configurations import (BearingGroup, IsolationLayer,
                                                    _friction_pendulum_default, _lead_rubber_default)

    base = Building.default()
    sup = base.superstructure
    P = np.kron(np.eye(8), _reflection(axis))
    mats = {name: 0.5 * (np.asarray(getattr(sup, name)) + P @ np.asarray(getattr(sup, name)) @ P)
            for name in ("K", "C")}
    for arr in mats.values():
        arr.setflags(write=False)
    flip = np.ones(2)
    flip[axis] = -1.0
    xy0 = np.asarray(sup.bearing_xy)[:46]
    xy = np.vstack([xy0, xy0 * flip])                      # bearing i and i + 46 are partners
    sym_sup = dataclasses.replace(sup, K=mats["K"], C=mats["C"], bearing_xy=xy,
                                  source=f"{sup.source} (symmetrised about axis {axis} for tests)", _modes=())
    fp = [i for i in range(46) if i < 31] + [i + 46 for i in range(31)]
    lrb = [i for i in range(31, 46)] + [i + 46 for i in range(31, 46)]
    layer = IsolationLayer(f"mirror-{axis}", (BearingGroup(_friction_pendulum_default(), fp),
                                              BearingGroup(_lead_rubber_default(), lrb)))
    dev0 = [(p, 0) for p in DEFAULT_X_POSITIONS[:4]] + [(p, 1) for p in DEFAULT_Y_POSITIONS[:4]]
    positions = [tuple(np.asarray(p) * s) for s in (np.ones(2), flip) for p, _ in dev0]
    directions = [d for _ in range(2) for _, d in dev0]
    devices = DeviceLayout.from_positions(positions, directions, base.devices.models[0], name="mirror-16")
    building = Building(sym_sup, layer, devices, name=f"mirror-symmetric variant ({'xy'[axis]})")
    bearing_perm = np.r_[np.arange(46, 92), np.arange(46)]
    device_perm = np.r_[np.arange(8, 16), np.arange(8)]
    _SYMMETRIC[axis] = (building, bearing_perm, device_perm)
    return _SYMMETRIC[axis]


def _close(a, b, name):
    scale = max(np.max(np.abs(a)), np.max(np.abs(b)), 1e-300)
    err = np.max(np.abs(a - b)) / scale
    assert err < 1e-7, f"{name}: mirrored response differs by {err:.2e} of its peak"


@pytest.mark.parametrize("axis", [0, 1], ids=["x-mirror", "y-mirror"])
@pytest.mark.parametrize("controller", [None, "passive-on"])
def test_mirror_image_record_gives_the_mirrored_response(record, axis, controller):
    from benchmark.simulator.simulation import simulate

    building, bearing_perm, device_perm = symmetric_variant(axis)
    b = building if controller else building.without_devices()
    mirrored = record.acceleration.copy()
    mirrored[:, axis] *= -1.0
    r = simulate(b, record, controller=controller)
    m = simulate(b, record.replace(acceleration=mirrored), controller=controller)
    P = np.diag(_reflection(axis))
    # the eccentric plan makes the run torsional, so θ → −θ is a real check
    assert 20.0 * np.max(np.abs(r.base_displacement[:, 2])) > 0.01 * np.max(np.abs(r.base_displacement[:, :2]))
    for name in ("base_displacement", "base_velocity", "base_acceleration_absolute", "isolation_force",
                 "device_force_total", "structure_shear"):
        _close(getattr(m, name), getattr(r, name) * P, name)
    for name in ("floor_displacement", "floor_acceleration_absolute"):
        _close(getattr(m, name), getattr(r, name) * P[None, None, :], name)
    _close(m.drift_ratio, r.drift_ratio * P[None, None, :2], "drift_ratio")
    _close(m.bearing_force, r.bearing_force[:, bearing_perm] * P[None, None, :2], "bearing_force")
    if controller:
        sign = np.where(b.devices.directions == axis, -1.0, 1.0)  # devices along the mirrored axis flip
        _close(m.device_force, r.device_force[:, device_perm] * sign, "device_force")
    for term, values in r.energy.items():
        _close(m.energy[term], values, f"energy {term}")


@pytest.mark.parametrize("axis", [0, 1], ids=["x-mirror", "y-mirror"])
def test_symmetric_variant_is_mirror_symmetric_but_eccentric(axis):
    building, _, _ = symmetric_variant(axis)
    Kb, _ = building.isolation_linear_matrices()
    other = 1 - axis
    assert abs(Kb[axis, 2]) > 1e-3 * Kb[axis, axis] * 10.0   # eccentric: couples with torsion
    assert abs(Kb[other, 2]) < 1e-9 * Kb[other, other]        # no eccentricity along the mirror
    K = building.superstructure.K
    P = np.kron(np.eye(8), _reflection(axis))
    assert np.allclose(P @ K @ P, K, rtol=0, atol=1e-9 * np.abs(K).max())
    assert np.all(np.linalg.eigvalsh(K) > 0)
