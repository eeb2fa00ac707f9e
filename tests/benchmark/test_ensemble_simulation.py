"""The ensemble's simulation run function: grid parameters, motions, and a real small ensemble."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmark.applications.ensemble import EnsembleConfig, read_ensemble, run_ensemble
from benchmark.applications.ensemble_simulation import _split, build_building, load_motion
from benchmark.foundation.errors import InputError


def test_grid_parameter_names_are_checked():
    plain, iso, dev = _split((("control_step", 0.01), ("isolation.mu", 0.05), ("device.kappa_x", 1e5),
                              ("probe.delay", 0.0)))
    assert plain == {"control_step": 0.01} and iso == (("mu", 0.05),) and dev == (("kappa_x", 1e5),)
    with pytest.raises(InputError, match="grid parameter 'stiffness' unknown"):
        _split((("stiffness", 1.0),))
    with pytest.raises(InputError, match="'device.'"):
        _split((("device.", 1.0),))


def test_unknown_fields_name_the_parameter(shared_dir):
    with pytest.raises(InputError, match="device.no_such_field"):
        build_building(None, (), (("no_such_field", 1.0),))
    with pytest.raises(InputError, match="isolation.no_such_field"):
        build_building(None, (("no_such_field", 1.0),), ())


def test_motion_scaled_to_pga_and_seeded(shared_dir):
    a = load_motion("kobe", "FN-x", True, 123, 2.5)
    assert np.max(np.abs(a.acceleration)) == pytest.approx(2.5, rel=1e-12)
    b = load_motion("kobe", "FP-x", True, 123, math.nan)
    c = load_motion("kobe", "FN-x", True, 123, math.nan)
    assert np.array_equal(b.acceleration[:, ::-1], c.acceleration)  # same pair, swapped
    assert not np.array_equal(load_motion("kobe", "FN-x", True, 124, math.nan).acceleration, c.acceleration)


@pytest.mark.slow
def test_small_simulation_ensemble_is_consistent_and_process_independent(tmp_path, shared_dir):
    cfg = tmp_path / "sim.toml"
    cfg.write_text('base_seed = 5\ncontrollers = ["none", "passive-off", "clipped-optimal"]\n'
                   'orientations = ["FN-x"]\npga = [3.0]\n[synthetic]\ntemplates = ["kobe"]\nrealisations = 1\n')
    config = EnsembleConfig.from_toml(cfg)
    s1 = run_ensemble(config, tmp_path / "one.h5", jobs=1, progress=False)
    assert s1.complete and s1.n_failed == 0, read_ensemble(tmp_path / "one.h5").cases["error"]
    res = read_ensemble(tmp_path / "one.h5")
    none = res.mask(controller="none")
    # the uncontrolled run evaluated against itself
    assert res.results["J3"][none][0] == pytest.approx(1.0)
    for name in ("J1", "J3", "J4", "peak_base_displacement", "peak_base_shear"):
        assert np.all(np.isfinite(res.results[name])), name
    # J3 is the ratio of the peak base displacements of the run and the uncontrolled run
    d = res.results["peak_base_displacement"]
    assert np.allclose(res.results["J3"], d / d[none][0])
    # every metric says its unit (probed: the results had none)
    import h5py
    with h5py.File(tmp_path / "one.h5") as f:
        units = {name: f["results"][name].attrs["units"] for name in f["results"]}
    assert units["peak_base_shear"] == "N" and units["peak_base_displacement"] == "m" and units["J3"] == "1"
    assert set(units) == set(res.results)
    s2 = run_ensemble(config, tmp_path / "two.h5", jobs=2, progress=False)
    assert s2.complete
    other = read_ensemble(tmp_path / "two.h5")
    for name in res.results:
        assert res.results[name].tobytes() == other.results[name].tobytes(), name
