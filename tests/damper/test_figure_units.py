"""Units in figures (issue #16 item 8): every axis shows each kind of quantity in the unit
:mod:`benchmark.foundation.display_units` picks (force kN, displacement m, velocity m/s, ...)."""

from __future__ import annotations

import pytest


def _check(figures) -> None:
    figures.check()

def _diagnosis(input_name: str):
    from damper.diagnosis.augmented import AugmentedModel
    from damper.models.bouc_wen import NormalizedBoucWen
    from damper.diagnosis import diagnose
    from damper.diagnosis.synthetic import sinusoidal_tests
    from damper.diagnosis.effects import Stiffness

    device = AugmentedModel(NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5), (Stiffness(5.0e4),))
    tests = sinusoidal_tests(device, cycles=3, samples_per_cycle=100, input_name=input_name)
    return diagnose(tests, model="normalized", max_effects=1)


@pytest.mark.parametrize("input_name", ["voltage", "current"])
def test_diagnosis_figures_use_display_units(tmp_path, figures, input_name):
    from damper.diagnosis.report import write_report

    write_report(_diagnosis(input_name), tmp_path)
    _check(figures)
    labels = [text for texts in figures.seen for _, text in texts]
    assert any("force" in t.lower() and "[kN]" in t for t in labels)
    assert not any("[mm" in t or "[N]" in t for t in labels), labels
    # the coil-input panel names what it shows: current in A, voltage in V
    unit = "A" if input_name == "current" else "V"
    titles = [text for texts in figures.seen for where, text in texts if where == "title"]
    coil = [t for t in titles if t.startswith(("voltage", "current", "coil"))]
    assert coil and all(t.startswith(input_name) for t in coil if "rate" not in t), coil
    xlabels = [text for texts in figures.seen for where, text in texts if where == "xlabel"]
    assert f"{input_name} [{unit}]" in xlabels, xlabels


def test_identify_data_figures_have_units(tmp_path, figures):
    from damper.io.data import write_csv
    from damper.identification.measured import identify_files
    from damper.lab.laboratory import periodic_test

    path = tmp_path / "t.csv"
    write_csv(periodic_test("virtual", 0.02, 1.0, 0.0, cycles=3, sample_rate=100.0), path)
    identify_files([path], models=("extended",), n_bootstrap=0, out=tmp_path / "figs")
    _check(figures)
    titles = [text for texts in figures.seen for where, text in texts if where == "title"]
    for symbol, unit in (("kappa_x", "kN/m"), ("kappa_w", "kN"), ("rho", "1/m")):
        assert any(symbol in t and f"[{unit}]" in t for t in titles), titles
    labels = [text for texts in figures.seen for _, text in texts]
    assert not any("(N)" in t or "(mm" in t for t in labels), labels
