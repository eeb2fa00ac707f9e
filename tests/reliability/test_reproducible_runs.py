"""Same inputs, same seed → bit-identical results: reruns, fresh processes, process counts.

* :func:`benchmark.simulator.simulation.simulate` with seeded measurement noise and a semi-active
  controller, run twice in this process and once in a fresh interpreter: every array equal
  bit for bit (compared by SHA-256 of the bytes); another seed changes the measurements.
* The virtual laboratory with noise and a seed gives the same test twice.
* ``sbib compare`` and ``sbib ensemble`` (the real simulation run function) with ``--jobs 1``
  and ``--jobs 2`` give identical numbers (slow: a few benchmark runs each).
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

SCRIPT = textwrap.dedent('''
    import hashlib, json, sys
    import numpy as np
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from controllers.noise import MeasurementNoise
    from records import load_benchmark_record

    def run(seed, records_dir=None):
        record = load_benchmark_record("elcentro", "FN-x", records_dir=records_dir)
        record = record.replace(acceleration=record.acceleration[:800])
        building = Building.default(isolation="friction-lrb", n_modes=6)
        noise = MeasurementNoise(acceleration_rms=0.05, displacement_rms=1e-4, force_rms=1e3)
        return simulate(building, record, controller="clipped-optimal", noise=noise, seed=seed)

    def digest(result):
        out = {}
        for name, value in sorted(vars(result.materialize()).items()):  # every derived history too
            if isinstance(value, np.ndarray):
                out[name] = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
            elif isinstance(value, dict) and name == "energy":
                for k, v in sorted(value.items()):
                    out["energy." + k] = hashlib.sha256(v.tobytes()).hexdigest()
        return out

    if __name__ == "__main__":
        print(json.dumps(digest(run(int(sys.argv[1]), sys.argv[2]))))
''')


@pytest.fixture(scope="module")
def runner(tmp_path_factory):
    path = tmp_path_factory.mktemp("repro") / "repro_run.py"
    path.write_text(SCRIPT)
    namespace: dict = {}
    exec(compile(SCRIPT, str(path), "exec"), namespace)  # the same functions in this process
    namespace["path"] = path
    return namespace


def test_seeded_noisy_run_is_bit_identical_on_rerun(runner, records_dir):
    first = runner["digest"](runner["run"](7, records_dir))
    second = runner["digest"](runner["run"](7, records_dir))
    assert first == second
    assert {"measurements", "voltage", "base_displacement", "energy.device"} <= set(first)


@pytest.mark.slow
def test_seeded_noisy_run_is_bit_identical_in_a_fresh_process(runner, records_dir):
    first = runner["digest"](runner["run"](7, records_dir))
    proc = subprocess.run([sys.executable, str(runner["path"]), "7", str(records_dir)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == first


def test_another_seed_gives_other_noise(runner, records_dir):
    a = runner["run"](7, records_dir)
    b = runner["run"](8, records_dir)
    assert not np.array_equal(a.measurements, b.measurements)
    assert np.all(np.isfinite(b.measurements))


def test_laboratory_noise_is_seeded():
    from damper.lab.laboratory import periodic_test

    a = periodic_test("virtual", 0.05, 1.0, 0.3, cycles=2, noise=0.02, seed=11)
    b = periodic_test("virtual", 0.05, 1.0, 0.3, cycles=2, noise=0.02, seed=11)
    c = periodic_test("virtual", 0.05, 1.0, 0.3, cycles=2, noise=0.02, seed=12)
    assert np.array_equal(a.force, b.force) and not np.array_equal(a.force, c.force)


def _cli_json(args: list[str]) -> dict:
    proc = subprocess.run([sys.executable, "-m", "benchmark", *args], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


@pytest.mark.slow
def test_compare_gives_the_same_numbers_on_one_and_two_processes(records_dir):
    args = ["compare", "--records", "kobe,elcentro", "--orientations", "FN-x",
            "--controllers", "passive-on,clipped-optimal", "--records-dir", str(records_dir),
            "--json", "--no-progress"]
    one = _cli_json(args + ["--jobs", "1"])
    two = _cli_json(args + ["--jobs", "2"])
    one.pop("jobs", None), two.pop("jobs", None)
    strip = lambda doc: json.dumps(doc["runs"], sort_keys=True)  # noqa: E731
    assert strip(one) == strip(two)


@pytest.mark.slow
def test_ensemble_gives_the_same_bits_on_one_and_two_processes(tmp_path):
    from benchmark.applications.ensemble import read_ensemble

    config = tmp_path / "repro.toml"
    config.write_text('name = "repro"\nbase_seed = 5\nrun = "simulation"\n'
                      'controllers = ["passive-on", "clipped-optimal"]\nrecords = ["elcentro"]\n'
                      'orientations = ["FN-x", "FP-x"]\n[synthetic]\ntemplates = ["kobe"]\nrealisations = 1\n')
    for jobs in (1, 2):
        proc = subprocess.run([sys.executable, "-m", "benchmark", "ensemble", "--config", str(config),
                               "--out", str(tmp_path / f"jobs{jobs}.h5"), "--jobs", str(jobs), "--no-progress"],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
    one, two = read_ensemble(tmp_path / "jobs1.h5"), read_ensemble(tmp_path / "jobs2.h5")
    assert one.n_cases == two.n_cases == 8
    for name in one.results:
        a, b = np.asarray(one.results[name]), np.asarray(two.results[name])
        assert a.tobytes() == b.tobytes(), name
    digest = hashlib.sha256()
    for name in sorted(one.results):
        digest.update(np.asarray(one.results[name]).tobytes())
    assert digest.hexdigest()
