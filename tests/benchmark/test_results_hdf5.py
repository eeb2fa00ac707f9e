"""HDF5 result files: round trip, units on every time history, provenance, atomic writing."""

from __future__ import annotations

from dataclasses import dataclass, field

import h5py
import numpy as np
import pytest

import benchmark.simulator.results as results_module
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.simulator.evaluation import evaluate
from benchmark.simulator.peaks import peaks_of
from benchmark.simulator.isolation import get_isolation
from benchmark.simulator.results import FIELD_UNITS, read_evaluation, read_result, write_result


@dataclass
class Run:
    t: np.ndarray
    base_displacement: np.ndarray
    base_acceleration_absolute: np.ndarray
    floor_displacement: np.ndarray
    floor_acceleration_absolute: np.ndarray
    drift_ratio: np.ndarray
    isolation_force: np.ndarray
    device_force_total: np.ndarray
    base_shear: np.ndarray
    structure_shear: np.ndarray
    bearing_force: np.ndarray
    device_force: np.ndarray
    voltage: np.ndarray
    bearing_state: np.ndarray | None = None
    energy: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)


def make_run(seed=0, n=3000, n_dev=4, scale=1.0):
    rng = np.random.default_rng(seed)
    r = lambda *shape: scale * rng.standard_normal((n,) + shape)  # noqa: E731
    return Run(t=np.arange(n) * 0.005, base_displacement=r(3), base_acceleration_absolute=r(3),
               floor_displacement=r(8, 3), floor_acceleration_absolute=r(8, 3), drift_ratio=r(8, 2),
               isolation_force=r(3), device_force_total=r(3), base_shear=r(3), structure_shear=r(3),
               bearing_force=r(92, 2), device_force=r(n_dev), voltage=np.abs(r(n_dev)),
               energy={"input": np.cumsum(np.abs(r())), "device": np.cumsum(np.abs(r())) / 3},
               info={"record": "kobe", "orientation": "FP-x", "isolation": "friction-lrb",
                     "controller": "passive-on", "settings": {"control_step": 0.005, "n_modes": None}})


def test_round_trip_with_units_provenance_and_evaluation(tmp_path):
    run, ref = make_run(0), make_run(1, n_dev=0, scale=2.0)
    ref.info["controller"] = "none"
    J = evaluate(run, ref)
    path = write_result(run, tmp_path / "sub" / "out.h5", reference=ref, evaluation=J,
                        isolation=get_isolation("friction-lrb"), record_source="/x/kobe.txt")
    back = read_result(path)
    assert np.array_equal(back.base_displacement, run.base_displacement)
    assert np.array_equal(back.bearing_force, run.bearing_force)
    assert np.array_equal(back.energy["device"], run.energy["device"])
    assert back.info == run.info
    assert back.units["base_displacement"] == "m, m, rad"
    assert back.units["voltage"] == "V"
    assert back.peak_record == pytest.approx(peaks_of(run).as_record())
    assert back.peaks == peaks_of(run)  # double precision: the same histories, the same peaks
    assert back.attrs["record"] == "kobe" and back.attrs["record_source"] == "/x/kobe.txt"
    assert back.attrs["package"] == "sbib" and "git_commit" in back.attrs
    assert "lead-rubber" in back.attrs["isolation_json"]
    assert evaluate(back, read_result(path, "reference")) == pytest.approx(J)
    stored = read_evaluation(path)
    assert list(stored) == [f"J{i}" for i in range(1, 10)]
    assert stored["J3"] == pytest.approx(J["J3"])
    with h5py.File(path) as f:
        def check(name, obj):
            if isinstance(obj, h5py.Dataset):
                assert obj.attrs["units"], name
        f.visititems(check)
        assert set(f["run/time_histories"]) <= set(FIELD_UNITS)
    # no temporary files left beside the result
    assert [p.name for p in (tmp_path / "sub").iterdir()] == ["out.h5"]


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def boom(group, result, dtype, *args):
        group.create_dataset("partial", data=np.zeros(3))
        raise RuntimeError("disk full")
    monkeypatch.setattr(results_module, "_write_run", boom)
    with pytest.raises(RuntimeError):
        write_result(make_run(), tmp_path / "out.h5")
    assert list(tmp_path.iterdir()) == []


def test_existing_file_is_replaced_only_when_complete(tmp_path, monkeypatch):
    path = write_result(make_run(0), tmp_path / "out.h5")
    before = read_result(path).base_displacement.copy()
    monkeypatch.setattr(results_module, "_write_run", lambda g, r, d, *a: (_ for _ in ()).throw(KeyboardInterrupt()))
    with pytest.raises(KeyboardInterrupt):
        write_result(make_run(5), path)
    assert np.array_equal(read_result(path).base_displacement, before)


def test_reader_errors(tmp_path):
    with pytest.raises(DataNotFoundError):
        read_result(tmp_path / "none.h5")
    (tmp_path / "text.h5").write_text("hello")
    with pytest.raises(InputError, match="not an HDF5 file"):
        read_result(tmp_path / "text.h5")
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f.attrs["format"] = "something"
    with pytest.raises(InputError, match="sbib-result"):
        read_result(tmp_path / "other.h5")
    path = write_result(make_run(), tmp_path / "ok.h5")
    with pytest.raises(InputError, match="reference"):
        read_result(path, "reference")
    assert read_evaluation(path) == {}


def test_single_precision_halves_the_file_and_reads_back_as_float64(tmp_path):
    """``precision="single"`` stores float32 (the time vector excepted), reads back float64 within
    float32 rounding, and J's recomputed from it agree with the stored ones; the default is double."""
    run, ref = make_run(0), make_run(1, n_dev=0, scale=2.0)
    J = evaluate(run, ref)
    double = write_result(run, tmp_path / "double.h5", reference=ref, evaluation=J)
    single = write_result(run, tmp_path / "single.h5", reference=ref, evaluation=J, precision="single")
    with h5py.File(single) as f:
        assert f.attrs["precision"] == "single"
        assert f["run/time_histories/base_displacement"].dtype == np.float32
        assert f["run/time_histories/t"].dtype == np.float64
        assert f["run/energy/input"].dtype == np.float32
    with h5py.File(double) as f:
        assert f.attrs["precision"] == "double"
        assert f["run/time_histories/base_displacement"].dtype == np.float64
    assert single.stat().st_size < 0.6 * double.stat().st_size
    back = read_result(single)
    assert back.base_displacement.dtype == np.float64
    np.testing.assert_allclose(back.base_displacement, run.base_displacement, rtol=1e-6, atol=1e-7)
    assert not np.array_equal(back.base_displacement, run.base_displacement)  # really rounded
    recomputed = evaluate(back, read_result(single, "reference"))
    assert recomputed == pytest.approx(J, rel=1e-5)
    with pytest.raises(InputError, match="precision 'half' unknown"):
        write_result(run, tmp_path / "bad.h5", precision="half")
    assert not (tmp_path / "bad.h5").exists()


def test_reading_another_sbib_file_names_it(tmp_path):
    # a compare file read back said "attribute 'format' is None; expected 'sbib-result' (a file
    # written by sbib)", though sbib had written it
    import h5py
    with h5py.File(tmp_path / "cmp.h5", "w") as f:
        f.attrs["kind"] = "controller comparison"
    with h5py.File(tmp_path / "ens.h5", "w") as f:
        f.attrs["n_cases"], f.attrs["config"] = 3, "controllers = ['none']"
    with pytest.raises(InputError, match="an `sbib compare --out` file"):
        read_result(tmp_path / "cmp.h5")
    with pytest.raises(InputError, match="an ensemble file .*read_ensemble"):
        read_result(tmp_path / "ens.h5")
