"""The loop on real dampers (issue 24, items 2, 3): the Spencer-type base and shear thinning.

* :class:`~damper.models.series_dashpot.SpencerBoucWen` is Spencer et al.'s model (same force as
  :class:`~damper.models.spencer.Spencer` with its laws tabulated), usable as the loop's base;
* its fit (:func:`~damper.diagnosis.base_fit.fit_spencer_base`) starts from values read from the
  data and recovers a Spencer-type device with a field lag under switched voltage;
* the ``shear_thinning`` effect follows its equation and is found alone, in a pair and with noise.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from benchmark.applications import speed_diagnose
from benchmark.applications.cli import main
from benchmark.foundation.errors import ParameterError
from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import NormalizedBoucWen
from damper.io.data import write_csv
from damper.diagnosis import diagnose
from damper.diagnosis.synthetic import sinusoidal_tests, step_voltage_tests
from damper.diagnosis.effects import Inertia, Motion, Offset, RollOff, ShearThinning, Stiffness, VoltageLag
from damper.models.series_dashpot import SpencerBoucWen
from damper.models.response import simulate
from damper.models.spencer import Spencer
from damper.models.voltage_laws import Polynomial, Tabulated

BASE = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5)


def _lin(a, b, nodes=(0.0, 2.25)):
    return Tabulated(nodes, tuple(a + b * v for v in nodes))


def _spencer_as_loop_base(s: Spencer) -> SpencerBoucWen:
    z0 = s.z0
    return SpencerBoucWen(s.k1, s.k0, _lin(s.c0a, s.c0b), _lin(s.alpha_a * z0, s.alpha_b * z0),
                          _lin(s.c1a, s.c1b), s.A / z0, s.gamma / (s.beta + s.gamma), s.n,
                          field_lag=1.0 / s.eta, voltage_range=s.voltage_range,
                          substep_tolerance=s.substep_tolerance)


def test_spencer_bouc_wen_is_spencers_model():
    s = Spencer.prototype_1997(x0=0.0)
    t = np.linspace(0.0, 2.0, 4001)
    x = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    xd = 0.01 * 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t)
    v = np.where((t // 0.3) % 2 == 0, 0.0, 2.25)
    f_ref = simulate(s, t, x, xd, v).force
    f = simulate(_spencer_as_loop_base(s), t, x, xd, v).force
    assert np.max(np.abs(f - f_ref)) <= 2e-3 * np.max(np.abs(f_ref))


def test_spencer_base_refuses_the_terms_it_carries():
    base = _spencer_as_loop_base(Spencer.prototype_1997(x0=0.0))
    for effect in (Stiffness(1e3), RollOff(0.01), VoltageLag(0.01)):
        with pytest.raises(ParameterError, match="already has"):
            AugmentedModel(base, (effect,))
    with pytest.raises(ParameterError, match="field_lag"):
        SpencerBoucWen(0.0, 0.0, 1.0, 1.0, 1.0, 10.0, 1.0, 1.0, field_lag=-0.01)


def test_spencer_base_recovers_a_spencer_type_device_with_a_field_lag():
    # a device of Spencer's structure, voltage laws linear in the field, a 20 ms lag, a preload
    device = AugmentedModel(SpencerBoucWen(
        500.0, 2000.0, Polynomial((1500.0, 2500.0)), Polynomial((300.0, 900.0)),
        Polynomial((3.0e4, 1.0e4)), 300.0, 1.0, 2.0, field_lag=0.02, voltage_range=(0.0, 1.0)),
        (Offset(-50.0),))
    tests = step_voltage_tests(device, amplitude=0.01, frequency=1.5, switch_period=0.23,
                               samples_per_cycle=300, noise=0.01, seed=3)
    d = diagnose(tests, model="spencer", max_effects=0)
    assert d.base_model.base_kind == "spencer"
    assert d.error_before <= 0.03, d.error_before  # noise 1 %
    assert d.base_model.base.field_lag == pytest.approx(0.02, rel=0.3)
    assert d.base_model.effect("offset").f0 == pytest.approx(-50.0, abs=25.0)


# ----------------------------------------------------------------------------- shear thinning

def _motion(freq=1.0, amp=0.01, n=801):
    t = np.linspace(0.0, 3.0 / freq, n)
    w = 2 * np.pi * freq
    return Motion(t, amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t), 0.0)


def test_shear_thinning_follows_its_equation():
    m = _motion()
    fb = simulate(BASE, m.t, m.x, m.xdot, 0.0).force
    f = AugmentedModel(BASE, (ShearThinning(300.0),)).force(m)
    # k sgn(v) |v|^0.5, its sign linear within 0.1 mm/s (damper.models.force_terms)
    eps = 1e-4
    np.testing.assert_allclose(f - fb, 300.0 * np.clip(m.xdot / eps, -1, 1) * np.sqrt(np.maximum(np.abs(m.xdot), eps)),
                               rtol=1e-12, atol=1e-9)
    with pytest.raises(ParameterError, match="shear_thinning.k"):
        ShearThinning(-1.0)


def _share(device, effect_free) -> float:
    num = den = 0.0
    for t in sinusoidal_tests(effect_free, noise=0.0):
        m = Motion(t.time, t.displacement, t.velocity, np.gradient(t.velocity, t.time), 0.0)
        f1, f0 = device.force(m), effect_free.force(m)
        num += float(np.sum((f1 - f0) ** 2))
        den += float(np.sum(f1 ** 2))
    return math.sqrt(num / den)


def _check(d, names, noise):
    for n in names:
        assert n in d.effects, (n, d.effects, d.error_before, d.error_after)
    floor = noise / math.sqrt(1.0 + noise ** 2)
    before = math.sqrt(max(d.error_before ** 2 - floor ** 2, 0.0))
    after = math.sqrt(max(d.error_after ** 2 - floor ** 2, 0.0))
    assert after <= 0.5 * before, (d.effects, d.error_before, d.error_after)


@pytest.mark.parametrize("noise", [0.0, 0.02])
def test_shear_thinning_alone_is_found(noise):
    device = AugmentedModel(BASE, (ShearThinning(600.0),))
    assert _share(device, AugmentedModel(BASE)) >= 0.08
    _check(diagnose(sinusoidal_tests(device, noise=noise, seed=7)), ["shear_thinning"], noise)


def test_shear_thinning_with_inertia_is_found():
    device = AugmentedModel(BASE, (ShearThinning(500.0), Inertia(60.0)))
    _check(diagnose(sinusoidal_tests(device, noise=0.02, seed=8)), ["shear_thinning", "inertia"], 0.02)


def test_bench_row_on_the_real_recording_says_when_the_data_are_absent(monkeypatch, tmp_path):
    monkeypatch.setattr(speed_diagnose, "shared_dir", lambda: tmp_path)
    row = speed_diagnose._bench_dyke(timeout=10.0)
    assert row.case == "diagnose-dyke" and row.project_s is None
    assert row.note.startswith("not measured") and "not found" in row.note


def test_cli_model_spencer_writes_its_report(tmp_path, capsys):
    device = AugmentedModel(SpencerBoucWen(
        500.0, 2000.0, Polynomial((1500.0, 2500.0)), Polynomial((300.0, 900.0)),
        Polynomial((3.0e4, 1.0e4)), 300.0, 1.0, 2.0, field_lag=0.02, voltage_range=(0.0, 1.0)))
    fit, other = (step_voltage_tests(device, amplitude=a, frequency=1.5, switch_period=0.23,
                                     samples_per_cycle=300, noise=0.01, seed=s)[0]
                  for a, s in ((0.01, 3), (0.007, 4)))
    a, b = write_csv(fit, tmp_path / "a.csv"), write_csv(other, tmp_path / "b.csv")
    out = tmp_path / "report"
    assert main(["diagnose", "--data", str(a), "--validate", str(b), "--model", "spencer",
                 "--out", str(out), "--json", "--quiet"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["model"] == "spencer" and doc["base_model"]["base"] == "spencer"
    assert doc["error_after"] <= 0.03 and doc["validation"]["error_after"] <= 0.04
    text = (out / "report.md").read_text()
    assert "spencer" in text and "Other recordings of the device" in text
