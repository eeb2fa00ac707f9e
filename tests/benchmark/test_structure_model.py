"""The superstructure read from structure.json: SI conversion, floor order, STRUC.mat cross-check."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.io

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.simulator.structure import load_superstructure, location_matrix, transformation


@pytest.fixture(scope="module")
def struc(shared_dir):
    return scipy.io.loadmat(shared_dir / "benchmark" / "STRUC.mat", squeeze_me=True)["STRUC"]


@pytest.fixture(scope="module")
def sup(shared_dir):
    return load_superstructure(shared_dir / "benchmark" / "structure.json")


def test_matrices_match_struc_mat_in_si(sup, struc):
    # STRUC.mat is in t and kN: ×10³ gives kg and N.
    for name in ("M", "K", "C"):
        ref = np.asarray(struc[name].item(), dtype=float) * 1e3
        mine = getattr(sup, name)
        assert np.abs(mine - ref).max() <= 1e-10 * np.abs(ref).max(), name
    assert np.array_equal(sup.R, np.asarray(struc["R"].item(), dtype=float))
    np.testing.assert_allclose(sup.storey_heights, struc["dh"].item(), rtol=1e-12)
    np.testing.assert_allclose(sup.m_base, struc["m"].item() * 1e3, rtol=1e-12)
    np.testing.assert_allclose(sup.H, struc["H"].item(), rtol=1e-9, atol=1e-9)


def test_floor_order_is_mass_orthonormal(sup):
    # Φ rows were re-ordered floor 1 → 8; ΦᵀMΦ = I up to the file's rounding (about 1 %).
    dev = np.abs(sup.phi.T @ sup.M @ sup.phi - np.eye(24)).max()
    assert dev < 0.02
    assert sup.M[0, 0] == pytest.approx(2580e3)  # floor 1 is the heaviest
    assert sup.M[-3, -3] == pytest.approx(2051e3)


def test_periods_and_damping(sup):
    omega, psi = sup.undamped_modes()
    periods = 2 * np.pi / omega
    np.testing.assert_allclose(periods[:3], [0.897, 0.780, 0.658], atol=1e-3)
    np.testing.assert_allclose(psi.T @ sup.M @ psi, np.eye(24), atol=1e-9)
    # C = Φ⁻ᵀ diag(2ζω) Φ⁻¹ and K = Φ⁻ᵀ diag(ω²) Φ⁻¹ with the benchmark's own modes, 5 % damping.
    phi = sup.phi
    np.testing.assert_allclose(phi.T @ sup.C @ phi, np.diag(2 * 0.05 * sup.omega), atol=1e-9)
    np.testing.assert_allclose(phi.T @ sup.K @ phi, np.diag(sup.omega ** 2), rtol=1e-9, atol=1e-6)
    assert sup.total_mass == pytest.approx((2580 + 2247 + 2057 + 5 * 2051 + 3565.73) * 1e3)


def test_transformation_and_location_matrix(sup):
    T = transformation(np.array([[2.0, -3.0]]))
    np.testing.assert_array_equal(T[0], [[1, 0, 3.0], [0, 1, 2.0]])
    # A pure rotation θ moves the point (x, y) by θ(−y, x).
    ub = np.array([0.0, 0.0, 0.01])
    np.testing.assert_allclose(T[0] @ ub, [0.03, 0.02])
    H = location_matrix(sup.bearing_xy)
    assert H[0, 0] == 92 and H[0, 2] == pytest.approx(-sup.bearing_xy[:, 1].sum())
    with pytest.raises(InputError, match=r"shape \(n, 2\)"):
        transformation(np.zeros((3, 3)))


def test_reduced_model_and_mass_participation(sup):
    mp = sup.mass_participation()
    np.testing.assert_allclose(mp.sum(axis=0), 1.0, rtol=1e-9)
    # The first three modes carry most of the mass in x, y, θ; 12 modes carry > 97 %.
    assert np.all(mp[:3].sum(axis=0) > 0.7)
    assert np.all(mp[:12].sum(axis=0) > 0.97)
    red = sup.reduced(6)
    assert red.n_q == 6 and red.is_reduced and red.basis.shape == (24, 6)
    np.testing.assert_allclose(red.Mq, np.eye(6), atol=1e-12)
    np.testing.assert_allclose(np.diag(red.Kq), sup.undamped_modes()[0][:6] ** 2, rtol=1e-9)
    assert red.full().n_q == 24
    with pytest.raises(InputError, match="n_modes"):
        sup.reduced(0)
    with pytest.raises(InputError, match="n_modes"):
        sup.reduced(25)


def test_bad_files_raise_clear_errors(tmp_path, shared_dir):
    with pytest.raises(DataNotFoundError, match="not found"):
        load_superstructure(tmp_path / "absent.json")
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    bad = dict(data, floor_mass=data["floor_mass"][::-1])  # wrong floor order
    (tmp_path / "reversed.json").write_text(json.dumps(bad))
    with pytest.raises(InputError, match="mass-normalised"):
        load_superstructure(tmp_path / "reversed.json")
    bad = dict(data)
    del bad["omega_squared"]
    (tmp_path / "missing.json").write_text(json.dumps(bad))
    with pytest.raises(InputError, match="'omega_squared' missing"):
        load_superstructure(tmp_path / "missing.json")
    (tmp_path / "broken.json").write_text("{ not json")
    with pytest.raises(InputError, match="line 1"):
        load_superstructure(tmp_path / "broken.json")


def test_negative_masses_and_damping_are_named(tmp_path, shared_dir):
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    masses = list(data["floor_mass"])
    masses[3] = -masses[3]
    (tmp_path / "neg.json").write_text(json.dumps(dict(data, floor_mass=masses)))
    with pytest.raises(InputError, match=r"'floor_mass' must be positive, got -[\d.]+ at entry 3"):
        load_superstructure(tmp_path / "neg.json")
    (tmp_path / "zeta.json").write_text(json.dumps(dict(data, modal_damping_ratio=5.0)))
    with pytest.raises(InputError, match=r"'modal_damping_ratio' must lie in \[0, 1\), got 5"):
        load_superstructure(tmp_path / "zeta.json")


def test_implausible_units_and_a_repeated_bearing_are_refused(tmp_path, shared_dir):
    # each was run without a word by a probe: heights in mm (drift ratios 1000x too small),
    # frequencies in Hz in place of omega² (a 5.9-s fixed-base period), a bearing given twice
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    cases = {
        "mm.json": (dict(data, floor_height_above_base=[1e3 * h for h in data["floor_height_above_base"]]),
                    r"storey 1 is [\d.]+ m high; a storey is 1-20 m \(heights in mm or cm\?\)"),
        "hz.json": (dict(data, omega_squared=[w ** 0.5 / (2 * math.pi) for w in data["omega_squared"]]),
                    r"fundamental period is 5.9\d* s; a building superstructure.s is 0.05-5 s"),
        "twice.json": (dict(data, bearing_xy=[data["bearing_xy"][0]] + data["bearing_xy"][:-1]),
                       "bearings 1 and 2 are 0 m apart"),
    }
    for name, (doc, words) in cases.items():
        (tmp_path / name).write_text(json.dumps(doc))
        with pytest.raises(InputError, match=words):
            load_superstructure(tmp_path / name)
