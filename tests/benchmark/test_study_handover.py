"""The main job runs the identification's validation runs once: the suite keeps them in full.

``compare(measure=...)`` returns the runs of a controller as the identification study's
:class:`~benchmark.applications.identification_validation.MeasuredRun`; they must be exactly what
:func:`~benchmark.applications.identification_validation.measure_run` computes on the study's
building, or the hand-over would change the identification's results.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmark.applications.comparison import compare
from benchmark.applications.identification_validation import MeasuredRun, measure_run
from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from damper.lab.laboratory import resolve_device


def test_suite_runs_handed_over_equal_the_validation_runs():
    result = compare(records=("kobe",), orientations="FN-x", controllers=("passive-on", "clipped-optimal"),
                     synthetic=True, jobs=1, progress=False, warn=False, measure=("clipped-optimal",))
    assert list(result.measured) == [("kobe", "FN-x", "clipped-optimal")]
    handed = result.measured[("kobe", "FN-x", "clipped-optimal")]
    assert isinstance(handed, MeasuredRun)
    own = measure_run(Building.default(damper_model=resolve_device("virtual")), "kobe", "FN-x",
                      "clipped-optimal", synthetic=True)
    for name in ("t", "displacement", "velocity", "voltage", "force"):
        np.testing.assert_array_equal(getattr(handed, name), getattr(own, name), err_msg=name)
    assert json.dumps(handed.J_device, sort_keys=True) == json.dumps(own.J_device, sort_keys=True)
    for name in ("t", "base_shear", "structure_shear", "base_displacement", "drift_ratio",
                 "floor_acceleration_absolute"):
        np.testing.assert_array_equal(getattr(handed.reference, name), getattr(own.reference, name),
                                      err_msg=name)
    # the run in the suite's table is the same run
    run = next(r for r in result.runs if r.controller == "clipped-optimal")
    assert json.dumps(run.J, sort_keys=True) == json.dumps(handed.J_device, sort_keys=True)


def test_measure_names_a_compared_controller():
    with pytest.raises(InputError, match="measure"):
        compare(records=("kobe",), orientations="FN-x", controllers=("passive-on",), synthetic=True,
                jobs=1, progress=False, warn=False, measure=("clipped-optimal",))
