"""identification.h5 stays small by default (<= 10 MB at the main job's size: 14 validation runs
of 6000 samples x 16 devices with 13 predicted forces each); full histories on request."""

from __future__ import annotations

from types import SimpleNamespace

import h5py
import numpy as np

from benchmark.applications.identification_study import _write_hdf5

N, DEVICES, RUNS = 6000, 16, 14
MODELS = ["original", "proposed", "normalized", "extended", "normalized+lag", "extended+lag",
          "extended-free-kx", "extended-free-kx+lag", "extended-free-kx-pchip",
          "extended-free-kx-pchip+lag", "loop-from-normalized", "closed-loop-normalized",
          "closed-loop-extended"]


def _validation(rng) -> SimpleNamespace:
    t = np.arange(N) * 0.005
    runs = []
    for i in range(RUNS):
        force = rng.normal(size=(N, DEVICES)) * 1e5 * (1 + np.arange(DEVICES))  # device 15 largest
        runs.append(SimpleNamespace(
            record=f"r{i // 2}", orientation=("FN-x", "FP-x")[i % 2], t=t,
            displacement=rng.normal(size=(N, DEVICES)) * 0.1, velocity=rng.normal(size=(N, DEVICES)),
            voltage=rng.uniform(0, 1, size=(N, DEVICES)), force=force,
            predicted={m: force * (1 + 0.01 * rng.normal(size=force.shape)) for m in MODELS},
            errors={"x": 0.1}, J={"J1": 1.0}))
    return SimpleNamespace(controller="clipped-optimal", runs=runs)


def test_default_file_is_small_and_full_on_request(tmp_path):
    rng = np.random.default_rng(1)
    validation = _validation(rng)
    fig6 = SimpleNamespace(time=np.arange(10.0), displacement=np.zeros(10), force=np.zeros(10))
    small = _write_hdf5(tmp_path / "small.h5", {}, fig6, validation, "virtual")
    assert small.stat().st_size <= 10e6, small.stat().st_size
    with h5py.File(small) as h5:
        g = h5["validation/r0/FN-x"]
        assert g.attrs["device_index"] == DEVICES - 1
        np.testing.assert_allclose(g["force"][:], validation.runs[0].force[:, -1], rtol=1e-6)
        assert g["force"].dtype == np.float32 and "compact" in h5.attrs["histories"]
    two = SimpleNamespace(controller=validation.controller, runs=validation.runs[:2])
    full = _write_hdf5(tmp_path / "full.h5", {}, fig6, two, "virtual", full_histories=True)
    with h5py.File(full) as h5:
        g = h5["validation/r0/FN-x"]
        assert g["force"].shape == (N, DEVICES) and g["force"].dtype == np.float64
        assert "device_index" not in g.attrs
    assert full.stat().st_size > small.stat().st_size  # two full runs outweigh fourteen compact ones
