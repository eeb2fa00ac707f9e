"""The study's closed loop: laboratory campaign, building models of augmented models, the claim."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from benchmark.foundation.errors import InputError, ParameterError
from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.diagnosis.effects import Asymmetry, Inertia, RollOff, Stiffness, VoltageLag
from benchmark.applications.identification_campaign import laboratory_campaign
from damper.lab.protocols import random_voltage
from benchmark.applications.identification_closed_loop import (CLOSED_LOOP_EXTENDED, CLOSED_LOOP_NORMALIZED, ORIGINAL,
                                               PROPOSED, building_model, claim_object, claim_summary,
                                               closed_form_models)
from damper.models.series_dashpot import SeriesDashpotBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial, Tabulated

CHEAP_DEVICE = ExtendedBoucWen(kappa_x=2e5, kappa_xdot=Polynomial((1e5, 1e5)),
                               kappa_w=Polynomial((5e4, 9e5)), rho=120.0, sigma=0.9, n=1.4)


def test_campaign_runs_steps_switching_small_and_random_tests_through_the_laboratory():
    c = laboratory_campaign(CHEAP_DEVICE, scale=0.2)
    assert len(c.train) >= 3 and len(c.heldout) >= 2
    rows = c.describe()
    for t in c.train + c.heldout:
        assert np.ptp(t.voltage) > 0, t.name          # every test changes the voltage
        assert t.metadata["device"] == CHEAP_DEVICE.name  # run by damper.lab.laboratory
    strokes = [r["stroke_m"] for r in rows]
    assert min(strokes) < 0.1 * max(strokes)          # small amplitudes are in
    assert any("random" in r["name"] for r in rows if r["set"] == "train")
    assert any("random" in r["name"] for r in rows if r["set"] == "heldout")
    # held-out tests are other realizations, not copies of training tests
    train_x = {tuple(np.round(t.displacement[:50], 9)) for t in c.train}
    assert all(tuple(np.round(t.displacement[:50], 9)) not in train_x for t in c.heldout)
    for bad in ({"levels": (0.0,)}, {"levels": (0.0, 1.5)}, {"stroke": -0.1}, {"scale": 0.0}):
        with pytest.raises(InputError):
            laboratory_campaign(CHEAP_DEVICE, **bad)


def test_random_voltage_uses_only_the_levels_and_switches():
    t = np.arange(0.0, 10.0, 0.01)
    v = random_voltage(t, (0.0, 0.5, 1.0), (0.05, 0.3), np.random.default_rng(3))
    assert set(np.unique(v)) <= {0.0, 0.5, 1.0}
    assert np.count_nonzero(np.diff(v)) > 20


def _augmented():
    base = NormalizedBoucWen(kappa_xdot=Tabulated((0.0, 1.0), (1e5, 3e5)),
                             kappa_w=Tabulated((0.0, 1.0), (6e4, 9e5)), rho=100.0, sigma=1.2, n=1.5)
    return AugmentedModel(base, (Stiffness(2e5), RollOff(0.03), VoltageLag(0.03)))


def _switching(duration=4.0, rate=500.0):
    t = np.arange(0.0, duration, 1.0 / rate)
    x = 0.08 * np.sin(2 * np.pi * 0.7 * t)
    xd = 0.08 * 2 * np.pi * 0.7 * np.cos(2 * np.pi * 0.7 * t)
    v = np.where(np.mod(t, 0.4) < 0.2, 0.0, 1.0)
    return t, x, xd, v


def test_building_model_computes_what_the_augmented_model_computes():
    aug = _augmented()
    reg = building_model(aug)
    assert isinstance(reg, SeriesDashpotBoucWen)
    assert reg.kappa_x == pytest.approx(2e5) and reg.field_lag == pytest.approx(0.03)
    t, x, xd, v = _switching()
    f_aug = aug.simulate(t, x, xd, v=v).force
    f_reg = simulate(reg, t, x, xd, v).force
    # the two filter the held voltage slightly differently (exact per step vs piecewise linear)
    assert np.linalg.norm(f_reg - f_aug) / np.linalg.norm(f_aug) < 0.02
    # without the lag the field follows at once: clearly different, so the lag is really carried
    no_lag = building_model(AugmentedModel(aug.base, (Stiffness(2e5), RollOff(0.03))))
    assert np.linalg.norm(simulate(no_lag, t, x, xd, v).force - f_aug) / np.linalg.norm(f_aug) > 0.05
    # the building accepts it in its device slots
    from benchmark.simulator.building import Building
    b = Building.default()
    assert b.devices.with_model(reg) is not None


def test_building_model_names_what_no_kernel_carries():
    aug = _augmented()
    with pytest.raises(InputError, match="inertia"):
        building_model(aug.with_effect(Inertia(3.0)))
    # a factor runs as a force term around the series-dashpot model (damper.models.force_terms)
    assert building_model(aug.with_effect(Asymmetry(0.1))).terms["asymmetry"] == pytest.approx(0.1)
    with pytest.raises(InputError, match="voltage_lag"):
        building_model(AugmentedModel(aug.base, (VoltageLag(0.03),)))
    plain = building_model(AugmentedModel(aug.base, (Stiffness(1e5),)))
    assert isinstance(plain, ExtendedBoucWen) and plain.kappa_x == pytest.approx(1e5)
    assert building_model(AugmentedModel(aug.base)) is aug.base or isinstance(
        building_model(AugmentedModel(aug.base)), NormalizedBoucWen)


def test_series_dashpot_field_lag_is_checked():
    with pytest.raises(ParameterError, match="field_lag"):
        SeriesDashpotBoucWen(2e5, 1e5, 1e6, 100.0, 1.0, 1.5, roll_off_velocity=0.02, field_lag=-0.01)


def test_closed_form_models_are_the_seeds_unrefined_pair():
    from damper.identification.voltage_grid import TestProtocol, identify_voltage_grid
    grid = identify_voltage_grid(CHEAP_DEVICE, voltages=(0.0, 0.5, 1.0),
                                 protocol=TestProtocol(cycles=3, sample_rate=500.0))
    notes: list = []
    models = closed_form_models(grid, notes=notes)
    assert isinstance(models[ORIGINAL], NormalizedBoucWen)
    assert isinstance(models[PROPOSED], ExtendedBoucWen)
    kx = grid.kappa_x.value
    assert models[PROPOSED].coefficients(0.5)["kappa_x"] == pytest.approx(kx)
    for k, v in enumerate(grid.voltages):
        cf = grid.identifications["normalized"][k].closed_form.parameters()
        refined = grid.identifications["normalized"][k].parameters
        got = models[ORIGINAL].coefficients(float(v))
        # the closed form, not the refinement (they differ on this device)
        assert got["kappa_w"] == pytest.approx(cf["kappa_w"], rel=0.02)
        assert any(abs(cf[p] - refined[p]) > 1e-6 * abs(refined[p]) for p in ("rho", "sigma", "n"))


def test_claim_object_and_ratios():
    claim = claim_object()
    assert claim == {"original": ORIGINAL, "proposed": PROPOSED,
                     "closed_loop": {"normalized": CLOSED_LOOP_NORMALIZED, "extended": CLOSED_LOOP_EXTENDED}}

    def e(x):
        return {"rel_rms_error": x, "peak_error": x, "energy_error": x}
    val = {"errors": {"kobe": {"FN-x": {ORIGINAL: e(0.5), PROPOSED: e(0.6), CLOSED_LOOP_NORMALIZED: e(0.1),
                                        CLOSED_LOOP_EXTENDED: e(0.02)},
                               "FP-x": {ORIGINAL: e(0.4), PROPOSED: e(0.2), CLOSED_LOOP_NORMALIZED: e(0.1),
                                        CLOSED_LOOP_EXTENDED: e(0.05)}}}}
    s = claim_summary(val, claim)
    assert s["seed"]["ratio_by_run"]["kobe FN-x"] == pytest.approx(1.2)
    assert s["seed"]["below_one_every_run"] is False
    assert s["closed_loop"]["ratio_mean"] == pytest.approx(0.35)
    assert s["closed_loop"]["below_one_every_run"] is True
    assert s["closed_loop"]["mean_at_most_target"] is False


@pytest.mark.slow
def test_loop_finds_the_lag_and_roll_off_of_a_device_it_was_not_told_about():
    from benchmark.applications.identification_closed_loop import close_the_loop
    device = SeriesDashpotBoucWen(kappa_x=1.5e5, kappa_xdot=Polynomial((8e4, 1.5e5)),
                                  kappa_w=Polynomial((6e4, 8e5)), rho=110.0, sigma=1.0, n=1.5,
                                  roll_off_velocity=0.03, field_lag=0.04)
    result = close_the_loop(device, campaign_scale=0.3)
    found = set(result.models[CLOSED_LOOP_EXTENDED].effect_names)
    assert {"voltage_lag", "roll_off"} <= found
    lag = result.models[CLOSED_LOOP_EXTENDED].effect("voltage_lag").value
    assert lag == pytest.approx(0.04, rel=0.25)
    assert result.heldout_errors[CLOSED_LOOP_EXTENDED] < 0.5 * result.diagnoses["extended"].error_before
    assert not isinstance(result.building[CLOSED_LOOP_EXTENDED], str)


@pytest.mark.slow
def test_identify_study_writes_the_claim(records_dir, tmp_path):
    from benchmark.applications.identification_study import run_identify_study
    summary = run_identify_study(tmp_path, records=["kobe"], orientations=["FN-x"], progress=False,
                                 compare_free_kappa_x=False, ceiling=False, campaign_scale=0.3)
    val = json.loads((tmp_path / "validation.json").read_text())
    claim = val["claim"]
    names = [claim["original"], claim["proposed"], claim["closed_loop"]["normalized"],
             claim["closed_loop"]["extended"]]
    for name in names:
        assert name in val["summary"]
        assert set(val["errors"]["kobe"]["FN-x"][name]) == {"rel_rms_error", "peak_error", "energy_error"}
    assert claim["closed_loop"]["extended"] in val["J"]["kobe"]["FN-x"]  # re-run in the building
    assert "closed_loop" in val["claim_test"] and "seed" in val["claim_test"]
    assert (tmp_path / "closed_loop.json").is_file()
    figs = summary["files"]["figures"]
    assert any(p.endswith("fig11_seed_kobe_FN-x.png") for p in figs)
    for p in figs:
        assert Path(p).is_file(), p


def test_the_screen_sees_roll_off_on_a_base_with_voltage_laws():
    """With voltage-dependent data the base's shape has laws; roll_off needs one shape: the screen
    evaluates it where the joint refit starts instead of failing (and never trying it)."""
    from damper.diagnosis.dataset import DiagnosisData
    from damper.diagnosis.selection import screen_effects
    from damper.diagnosis.effects import EFFECT_NAMES, get_effect

    device = SeriesDashpotBoucWen(kappa_x=0.0, kappa_xdot=Polynomial((8e4, 1.5e5)),
                                  kappa_w=Polynomial((6e4, 8e5)), rho=110.0, sigma=1.0, n=1.5,
                                  roll_off_velocity=0.05)
    c = laboratory_campaign(device, scale=0.15, levels=(0.0, 1.0))
    data = DiagnosisData.from_tests(list(c.train), validate=list(c.heldout))
    nodes = data.nodes()
    base = NormalizedBoucWen(kappa_xdot=Tabulated(tuple(nodes), (8e4, 2.3e5)),
                             kappa_w=Tabulated(tuple(nodes), (6e4, 8.6e5)),
                             rho=Tabulated(tuple(nodes), (100.0, 120.0)), sigma=1.0, n=1.5)
    scales = {n: get_effect(n).scale(list(data.motions), data.force_rms("train")) for n in EFFECT_NAMES}
    s = screen_effects(AugmentedModel(base), data, ["roll_off"], scales, nodes=nodes)["roll_off"]
    assert "cannot be evaluated" not in s.reason
    from damper.diagnosis.selection import MIN_SCORE
    assert s.score > 10 * MIN_SCORE and s.estimate > 0  # it is refitted (tried) by the loop


def test_cli_identify_rejects_a_bad_campaign_scale(tmp_path, capsys):
    from benchmark.applications.cli import main
    assert main(["identify", "--campaign-scale", "0", "--out", str(tmp_path / "out")]) == 2
    assert "campaign_scale" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing written
