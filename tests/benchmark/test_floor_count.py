"""A structure file with another number of floors (``n_floors``): read, stepped, controlled, scored.

The variant keeps the benchmark's lower five floors and condenses the upper three out of the
stiffness (``K_c = K_11 - K_12 K_22^-1 K_21``: the same frame with the upper floors' masses
removed), then writes the file's fields (modes ordered top floor first, mass-normalised in t)
as the benchmark's own file gives them. The oracle (``solve_ivp`` on the continuous equations,
:mod:`benchmark.simulator.oracle`) builds its matrices from the superstructure's shapes, so it
checks the kernel on a building whose height is not the benchmark's.
"""

from __future__ import annotations

import json
import subprocess
import sys

import h5py
import numpy as np
import pytest
import scipy.linalg

from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from benchmark.simulator.devices import DeviceLayout
from benchmark.simulator.evaluation import evaluate
from benchmark.simulator.oracle import OracleModel
from benchmark.simulator.peaks import peaks_of
from benchmark.simulator.simulation import simulate
from benchmark.simulator.structure import load_superstructure
from controllers.measurements import layout_of, measurement_layout, measurement_names
from records import Record, load_benchmark_record

FLOORS = 5


def _variant_data(shared_dir, floors: int) -> tuple[dict, np.ndarray, np.ndarray]:
    """The benchmark's file cut to ``floors`` floors; returns (data, M [t], K_c [kN/m])."""
    data = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    sup = load_superstructure(shared_dir / "benchmark" / "structure.json")
    n = 3 * floors
    M = sup.M / 1e3
    K = sup.K / 1e3
    Kc = K[:n, :n] - K[:n, n:] @ np.linalg.solve(K[n:, n:], K[n:, :n])
    Kc = 0.5 * (Kc + Kc.T)
    w2, phi = scipy.linalg.eigh(Kc, M[:n, :n])
    order = np.ravel([[3 * (floors - f) + j for j in range(3)] for f in range(1, floors + 1)])
    phi_file = np.empty_like(phi)
    phi_file[order] = phi
    data.update(n_floors=floors, omega_squared=w2.tolist(), mode_shapes_floor8_to_floor1=phi_file.tolist(),
                floor_mass=data["floor_mass"][:floors], floor_rot_inertia=data["floor_rot_inertia"][:floors],
                floor_height_above_base=data["floor_height_above_base"][:floors + 1])
    return data, M[:n, :n], Kc


@pytest.fixture(scope="module")
def five(shared_dir, tmp_path_factory):
    data, M, Kc = _variant_data(shared_dir, FLOORS)
    path = tmp_path_factory.mktemp("floors") / "five_storeys.json"
    path.write_text(json.dumps(data))
    return path, M, Kc


def _truncate(record: Record, seconds: float) -> Record:
    n = int(round(seconds / record.dt)) + 1
    return Record(name=record.name, dt=record.dt, acceleration=np.array(record.acceleration[:n]),
                  labels=record.labels, source=record.source, synthetic=record.synthetic,
                  metadata=dict(record.metadata))


def test_the_variant_is_read_with_its_floors(five):
    path, M, Kc = five
    sup = load_superstructure(path)
    assert sup.n_floors == FLOORS and sup.n_dof == 3 * FLOORS
    assert sup.R.shape == (3 * FLOORS, 3) and sup.storey_heights.shape == (FLOORS,)
    # K = Φ⁻ᵀ ω² Φ⁻¹ rebuilt from the written modes: the condensed stiffness, to the eigen-solver's
    # rounding (relative 1e-9 of its largest entry leaves four orders of magnitude for it)
    np.testing.assert_allclose(sup.K / 1e3, Kc, atol=1e-9 * np.abs(Kc).max())
    np.testing.assert_allclose(np.diag(sup.M) / 1e3, np.diag(M), rtol=1e-12)
    assert sup.floor_slice(FLOORS) == slice(3 * FLOORS - 3, 3 * FLOORS)
    with pytest.raises(InputError, match=f"expected 1..{FLOORS}"):
        sup.floor_slice(FLOORS + 1)


def test_the_layout_follows_the_floor_count():
    lay = measurement_layout(2, FLOORS)
    assert lay.n_accelerations == 3 + 3 * FLOORS == lay.base_displacement
    assert lay.n_measurements == 3 + 3 * FLOORS + 3 + 4
    assert layout_of(lay.n_measurements, 2) == lay
    assert measurement_layout(16) == layout_of(62, 16)  # the benchmark's: 30 + 2·16
    assert len(measurement_names(2, FLOORS)) == lay.n_measurements
    assert measurement_names(2, FLOORS)[3 * FLOORS + 2] == f"a_floor{FLOORS}_theta [rad/s2]"
    with pytest.raises(InputError, match="whole number of floors"):
        layout_of(lay.n_measurements + 1, 2)


@pytest.mark.parametrize("field,entries", [("floor_mass", 8), ("omega_squared", 24)])
def test_fields_that_disagree_with_n_floors_are_named(shared_dir, five, tmp_path, field, entries):
    data = json.loads(five[0].read_text())
    bench = json.loads((shared_dir / "benchmark" / "structure.json").read_text())
    data[field] = bench[field]  # the benchmark's 8 floors' entries in a 5-floor file
    path = tmp_path / "mixed.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match=f"'{field}' has {entries} entries, expected .* for n_floors = {FLOORS}"):
        load_superstructure(path)
    del data["n_floors"]
    data[field] = json.loads(five[0].read_text())[field]
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="the default: give n_floors"):
        load_superstructure(path)


@pytest.mark.parametrize("value", [0, 2.5, True, "5"])
def test_a_bad_floor_count_is_refused(five, tmp_path, value):
    data = json.loads(five[0].read_text())
    data["n_floors"] = value
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="field 'n_floors'"):
        load_superstructure(path)


def test_a_five_storey_run_matches_solve_ivp(five, records_dir):
    """Nonlinear isolation and two dampers at constant voltage on the 5-storey variant, against
    the oracle at the 0.5 % on peaks of the benchmark's own oracle tests."""
    from controllers.passive import ConstantVoltage
    from damper.models.virtual import VirtualBenchmarkDamper

    path, _, _ = five
    layout = DeviceLayout.from_positions([(1.82, 30.69), (-17.25, -16.18)], [0, 1], VirtualBenchmarkDamper())
    building = Building.default(isolation="friction-lrb", devices=layout, structure_path=path)
    record = _truncate(load_benchmark_record("sylmar", "FN-x", records_dir=records_dir), 4.0)
    result = simulate(building, record, controller=ConstantVoltage(0.5))
    assert result.floor_acceleration_absolute.shape == (len(record.acceleration), FLOORS, 3)
    assert result.drift_ratio.shape == (len(record.acceleration), FLOORS, 2)
    assert result.measurements.shape[1] == measurement_layout(2, FLOORS).n_measurements
    oracle = OracleModel(building, record, voltage=0.5)
    ref = peaks_of(oracle.result(oracle.solve(len(record.acceleration)))).as_dict()
    mine = peaks_of(result).as_dict()
    for key in ref:
        assert mine[key] == pytest.approx(ref[key], rel=5e-3), key


@pytest.mark.parametrize("controller", ["clipped-optimal", "skyhook", "lyapunov"])
def test_model_based_controllers_design_on_the_variant(five, records_dir, controller):
    """Every design that reads the building (LQG on its linear plant, skyhook's device rows)
    runs on five floors and lowers the peak base displacement against the passive-off run (the
    whole record: Kobe's largest isolator excursion comes after its first 8 s, where every
    controller of the benchmark building is still at the passive-off run's 0.13 m)."""
    path, _, _ = five
    building = Building.default(isolation="friction-lrb", devices="default", structure_path=path)
    record = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    off = simulate(building, record, controller="passive-off")
    run = simulate(building, record, controller=controller)
    assert np.all(np.isfinite(run.voltage)) and np.ptp(run.voltage) > 0  # the law switched
    reference = simulate(Building.default(isolation="friction-lrb", devices=None, structure_path=path), record)
    j = evaluate(run, reference)
    assert all(np.isfinite(v) for v in j.values() if v is not None)
    assert peaks_of(run).base_displacement < peaks_of(off).base_displacement


def test_sbib_run_takes_a_five_storey_file(five, records_dir, tmp_path):
    path, _, _ = five
    out = tmp_path / "run.h5"
    proc = subprocess.run([sys.executable, "-m", "benchmark", "run", "--structure", str(path),
                           "--record", "kobe", "--controller", "clipped-optimal", "--records-dir", str(records_dir),
                           "--out", str(out), "--json"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["structure"]["n_floors"] == FLOORS and f"({FLOORS} floors," in proc.stderr
    assert 0 < doc["J"]["J5"] < 10
    with h5py.File(out) as f:
        shapes = []
        f.visititems(lambda name, obj: shapes.append(obj.shape) if "floor_acceleration" in name
                     and isinstance(obj, h5py.Dataset) else None)
    assert shapes and all(s[1] == FLOORS for s in shapes)


def test_measurement_noise_on_the_variant(five, records_dir):
    """The noise model's vector follows the height (its rotation entries, scaled by the radius, are
    every third of the accelerations and base displacements), a run with it is seeded as on the
    benchmark, and a noise object that takes no n_floors is refused by name, not by a TypeError."""
    from benchmark.simulator.sensors import noise_samples
    from controllers.noise import MeasurementNoise

    noise = MeasurementNoise(acceleration_rms=0.1, displacement_rms=1e-3, force_rms=10.0, rotation_radius=20.0)
    lay = measurement_layout(2, FLOORS)
    rms = noise.rms_vector(2, FLOORS)
    assert rms.shape == (lay.n_measurements,)
    theta = np.arange(2, lay.base_displacement + 3, 3)
    np.testing.assert_allclose(rms[theta[:-1]], 0.1 / 20.0)
    assert rms[theta[-1]] == pytest.approx(1e-3 / 20.0)  # the base rotation
    np.testing.assert_allclose(rms[lay.slices()["device_force"]], 10.0)
    samples, ranges = noise_samples(noise, 50, 2, seed=3, n_floors=FLOORS)
    assert samples.shape == (50, lay.n_measurements) and ranges.shape == (lay.n_measurements,)

    class Old:  # written for the benchmark's signature
        def sample(self, n_steps, n_devices, rng=None):
            return np.zeros((n_steps, 30 + 2 * n_devices))

    with pytest.raises(InputError, match="take no n_floors, and the building has 5 floors"):
        noise_samples(Old(), 50, 2, seed=3, n_floors=FLOORS)
    assert noise_samples(Old(), 50, 2, seed=3)[0].shape == (50, 34)  # the benchmark's height: as before

    path, _, _ = five
    building = Building.default(isolation="friction-lrb", devices="default", structure_path=path)
    record = _truncate(load_benchmark_record("kobe", "FN-x", records_dir=records_dir), 3.0)
    runs = [simulate(building, record, controller="clipped-optimal", noise=noise, seed=7) for _ in range(2)]
    clean = simulate(building, record, controller="clipped-optimal")
    np.testing.assert_array_equal(runs[0].voltage, runs[1].voltage)
    assert not np.array_equal(runs[0].measurements, clean.measurements)

