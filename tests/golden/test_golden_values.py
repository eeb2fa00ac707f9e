"""Golden values: a handful of building runs, an identification and a diagnosis, pinned.

These guard refactors that must not change results (issue #15). They describe the *method*, not
the machine: numba compiles for the host CPU (vector width, fused multiply-add, fast-math
reassociation), so the last bits of every sum differ between CPUs, and each quantity is compared
with a tolerance chosen from how strongly the method amplifies such last-bit differences
(:data:`TOLERANCES`, the reason beside each). Measured on 2026-11-24: this file, written on another
machine, differs from a run here by up to 5e-10 relative (the passive 9-mode run's end
displacement) and 1.2e-10 (a fitted kappa_x); perturbing the record or the test force by 4e-16
relative (a last-bit change) moves the values by no more; numba's generic target gives the same.
Every tolerance below is at least 100x what was seen and far below what a change of method moves
(a sub-step tolerance, an integrator or a fit option move these values by 1e-6 or more). ``make test`` also runs this module
with numba compiled for the generic x86-64 target (``NUMBA_CPU_NAME=generic``), so a CPU change
cannot break it again.

A change that is *meant* to move results (a new integrator, issue #14) regenerates the file on
purpose and says so in its commit::

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


class Tolerance(tuple):
    """``(rtol, atol_fraction)``: ``|got - want| <= rtol |want| + atol_fraction * scale``.

    ``scale`` is the largest magnitude among the values of the same quantity group (the peak
    displacement for end values and sums of displacements), so a value that is small because it
    ends near zero is not held to a relative tolerance it cannot meet.
    """

    def __new__(cls, rtol: float, atol_fraction: float = 0.0):
        return super().__new__(cls, (rtol, atol_fraction))


#: The tolerance of each kind of quantity, with the reason.
TOLERANCES: dict[str, Tolerance] = {
    # Linear building: a stable linear recursion; roundoff enters each step at ~1e-16 and is
    # damped, so the response differs by ~steps * eps at most (6000 steps: ~1e-12). Peaks are taken
    # where the response is large; the end value and the sum are compared against the peak.
    "linear": Tolerance(1e-10, 1e-10),
    # Nonlinear bearings (friction pendulum, lead-rubber): the nonlinear forces are iterated to a
    # relative tolerance of 1e-6 per step and the hysteretic states are sub-stepped; a last-bit
    # change can move the iteration count at a step where the residual sits at the threshold,
    # shifting the state by a fraction of that tolerance, which the dissipative system damps.
    "nonlinear": Tolerance(1e-7, 1e-7),
    # Switching control (clipped-optimal): each control step's voltage is a sign test on the
    # observer's force error; where that error crosses zero a last-bit change can flip one step's
    # voltage (0 <-> 10 V), a force step of one device for 1 ms. Peaks move by far less than 1e-4,
    # the voltage sum by a few steps of 10 V in ~37 000 V.
    "switching": Tolerance(1e-4, 1e-4),
    "switching_voltage_sum": Tolerance(1e-3),
    # Least-squares fits stop at xtol = ftol = gtol = 1e-10 (damper/fitting.py) on scaled
    # parameters with a finite-difference Jacobian; along the poorly conditioned directions of a
    # Bouc-Wen fit (n against rho and sigma) the optimum is located to ~1e-10 / cond. A parameter
    # at its bound (normalized kappa_x = 0) is exact.
    "fit": Tolerance(1e-7, 0.0),
    # A diagnosis: fits as above, then relative RMS errors of the fitted models.
    "diagnosis": Tolerance(1e-6, 0.0),
}


def _tolerance(name: str, key: str) -> Tolerance:
    """The tolerance of quantity ``key`` of golden case ``name`` (see :data:`TOLERANCES`)."""
    if name.startswith("identification"):
        return TOLERANCES["fit"]
    if name.startswith("diagnosis"):
        return TOLERANCES["diagnosis"]
    case = CASES[name]
    if case["controller"] == "clipped-optimal":
        return TOLERANCES["switching_voltage_sum" if key == "voltage_sum" else "switching"]
    return TOLERANCES["linear" if case["isolation"] == "linear" else "nonlinear"]


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
    from damper.lab.laboratory import periodic_test

    test = periodic_test("virtual", amplitude=0.1, frequency=1.0, voltage=0.5, cycles=4,
                         sample_rate=200.0).select(t_start=2.0)
    out = {}
    for model in ("normalized", "extended"):
        ident = identify(test, model=model)
        out[model] = {k: float(v) for k, v in ident.parameters.items()}
    return out


def _diagnosis_values() -> dict:
    from damper.diagnosis.augmented import AugmentedModel
    from damper.models.bouc_wen import NormalizedBoucWen
    from damper.diagnosis import diagnose
    from damper.diagnosis.synthetic import sinusoidal_tests
    from damper.diagnosis.effects import Stiffness

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


def _scale(name: str, key: str, want: dict) -> float:
    """The magnitude an absolute tolerance of ``key`` is a fraction of (see :class:`Tolerance`)."""
    if key.startswith("base_displacement"):
        return float(np.max(np.abs(want["base_displacement_abs_max"])))
    return float(np.max(np.abs(np.asarray(want[key], dtype=float)), initial=0.0))


def _compare(got, want, name: str, where: str | None = None, top: dict | None = None):
    where = where or name
    top = want if top is None else top
    if isinstance(want, dict):
        assert set(got) == set(want), where
        for k in want:
            _compare(got[k], want[k], name, f"{where}.{k}", top)
    elif isinstance(want, list) and want and isinstance(want[0], str):
        assert got == want, where
    else:
        key = where.rsplit(".", 1)[-1]
        rtol, atol_fraction = _tolerance(name, key)
        atol = atol_fraction * _scale(name, key, top) if atol_fraction else 0.0
        np.testing.assert_allclose(np.asarray(got, dtype=float), np.asarray(want, dtype=float),
                                   rtol=rtol, atol=atol, err_msg=f"{where} (rtol {rtol:g}, atol {atol:g})")


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


@pytest.mark.parametrize("name", NAMES)
def test_tolerances_catch_a_change_of_method(name, golden):
    """Each tolerance is tight enough to see a change of method (a value moved by 1e-3 relative).

    The golden values themselves, moved by 1e-3 relative (the size of change a looser sub-step
    tolerance or another integrator makes), must fail the comparison; moved by 1e-13 (last bits),
    they must pass.
    """
    if REGENERATE or name not in golden:
        pytest.skip("no golden file to compare with")

    def moved(value, factor):
        if isinstance(value, dict):
            return {k: moved(v, factor) for k, v in value.items()}
        if isinstance(value, list) and value and isinstance(value[0], str):
            return value
        return (np.asarray(value, dtype=float) * factor).tolist()

    want = golden[name]
    _compare(moved(want, 1 + 1e-13), want, name)
    with pytest.raises(AssertionError):
        _compare(moved(want, 1 + 1e-3), want, name)
