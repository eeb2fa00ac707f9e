"""The model-based controllers on a building reduced below their design order (``--n-modes 3``):
the design keeps every mode the building has. It had refused with 'n_modes must lie in [1, 6],
got 9', a number the user never gave (the design's own order)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.simulator.building import Building
from benchmark.simulator.simulation import simulate
from records import Record


@pytest.mark.parametrize("controller", ["clipped-optimal", "lyapunov"])
@pytest.mark.parametrize("n_modes", [3, 5])
def test_a_building_reduced_below_the_design_order_runs(controller, n_modes):
    rng = np.random.default_rng(2)
    record = Record("noise", 0.005, 0.5 * rng.standard_normal((201, 2)))
    building = Building.default(isolation="linear", devices="default", n_modes=n_modes)
    result = simulate(building, record, controller=controller)
    assert np.all(np.isfinite(result.peaks.as_dict()["base_displacement"]))
