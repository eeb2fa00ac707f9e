"""Golden values: a handful of building runs, an identification and a diagnosis, pinned.

These guard refactors that must not change results (issue #15: "results are bit-identical before
and after"). The comparison is exact to 1e-12 relative (the kernels use fast-math reassociation,
so a different CPU's vector width may move the last bits; on one machine the values are
bit-identical). A change that is *meant* to move results (a new integrator, issue #14) regenerates
the file on purpose and says so in its commit::

    SBIB_REGENERATE_GOLDEN=1 python -m pytest tests/golden -q

The file ``golden_values.json`` beside this module holds the pinned numbers.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).with_name("golden_values.json")
REGENERATE = os.environ.get("SBIB_REGENERATE_GOLDEN") == "1"
RTOL = 1e-12


def _run_values(isolation: str, devices: str | None, controller: str | None, n_modes: int | None,
                orientation: str) -> dict:
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import load_benchmark_record

    record = load_benchmark_record("kobe", orientation)
    kwargs = {"isolation": isolation}
    if devices is None:
        kwargs["devices"] = None
    if n_modes is not None:
        kwargs["n_modes"] = n_modes
    building = Building.default(**kwargs)
    result = simulate(building, record, controller=controller)
    out = {
        "base_displacement_abs_max": np.abs(result.base_displacement).max(axis=0).tolist(),
        "base_displacement_end": result.base_displacement[-1].tolist(),
        "base_displacement_sum": float(np.sum(result.base_displacement)),
    }
    if controller is not None:
        out["voltage_sum"] = float(np.sum(result.voltage))
        out["device_force_abs_max"] = float(np.abs(result.device_force).max())
    return out


CASES = {
    "linear_nodevices_kobe_FN-x": dict(isolation="linear", devices=None, controller=None, n_modes=None,
                                       orientation="FN-x"),
    "frictionlrb_nodevices_kobe_FP-x": dict(isolation="friction-lrb", devices=None, controller=None,
                                            n_modes=None, orientation="FP-x"),
    "frictionlrb_clipped_kobe_FN-x": dict(isolation="friction-lrb", devices="default",
                                          controller="clipped-optimal", n_modes=None, orientation="FN-x"),
    "frictionlrb_passiveon_9modes_kobe_FN-x": dict(isolation="friction-lrb", devices="default",
                                                   controller="passive-on", n_modes=9, orientation="FN-x"),
}


def _identification_values() -> dict:
    from damper.identification import identify
    from damper.laboratory import periodic_test

    test = periodic_test("virtual", amplitude=0.1, frequency=1.0, voltage=0.5, cycles=4,
                         sample_rate=200.0).select(t_start=2.0)
    out = {}
    for model in ("normalized", "extended"):
        ident = identify(test, model=model)
        out[model] = {k: float(v) for k, v in ident.parameters.items()}
    return out


def _diagnosis_values() -> dict:
    from damper.augmented import AugmentedModel
    from damper.bouc_wen import NormalizedBoucWen
    from damper.diagnosis import diagnose
    from damper.diagnosis.synthetic import sinusoidal_tests
    from damper.effects import Stiffness

    device = AugmentedModel(NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5), [Stiffness(3e4)])
    d = diagnose(sinusoidal_tests(device, noise=0.01, seed=1))
    return {"error_before": float(d.error_before), "error_after": float(d.error_after),
            "effects": [type(e).__name__ for e in d.final_model.effects]}


def _compute(name: str):
    if name in CASES:
        return _run_values(**CASES[name])
    if name == "identification_virtual_0.5V":
        return _identification_values()
    if name == "diagnosis_stiffness":
        return _diagnosis_values()
    raise KeyError(name)


NAMES = list(CASES) + ["identification_virtual_0.5V", "diagnosis_stiffness"]


def _compare(got, want, where: str):
    if isinstance(want, dict):
        assert set(got) == set(want), where
        for k in want:
            _compare(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list) and want and isinstance(want[0], str):
        assert got == want, where
    else:
        np.testing.assert_allclose(np.asarray(got, dtype=float), np.asarray(want, dtype=float),
                                   rtol=RTOL, atol=0.0, err_msg=where)


@pytest.fixture(scope="module")
def golden() -> dict:
    if REGENERATE or not GOLDEN.exists():
        return {}
    return json.loads(GOLDEN.read_text())


@pytest.mark.parametrize("name", NAMES)
def test_golden_value(name, golden, records_dir):
    got = _compute(name)
    if REGENERATE:
        data = json.loads(GOLDEN.read_text()) if GOLDEN.exists() else {}
        data[name] = got
        GOLDEN.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
        return
    assert name in golden, f"no golden value for {name}: regenerate with SBIB_REGENERATE_GOLDEN=1"
    _compare(got, golden[name], name)
