"""``sbib diagnose`` prints the parameters the JSON holds (the final model's, after the last joint
refit), with their units, and names the coil input as the tests give it (a current is a current)."""

from __future__ import annotations

import argparse
from types import SimpleNamespace

from benchmark.applications import cli_diagnose
from damper.diagnosis.report import format_parameters, input_word


def test_parameters_carry_their_units():
    assert format_parameters("roll_off", {"velocity": 0.011744}) == "velocity = 0.01174 m/s"
    assert format_parameters("stiffness", {"kappa_x": 2.08e5}) == "kappa_x = 2.08e+05 N/m"
    assert input_word("voltage_rate", "current") == "current_rate"
    assert input_word("voltage", "voltage") == "voltage"


def test_printed_values_are_the_final_ones(monkeypatch, capsys):
    step = SimpleNamespace(name="roll_off", parameters={"velocity": 0.011744}, error_before=0.2,
                           error_after=0.1)
    final = SimpleNamespace(effects=[SimpleNamespace(name="roll_off", parameters={"velocity": 0.011827})],
                            base=SimpleNamespace(sigma=50.0))
    result = SimpleNamespace(model_kind="normalized", error_before=0.2, error_after=0.1,
                             base_at_bounds={"sigma": "upper 50"},
                             selection=SimpleNamespace(steps=[step]), final_model=final, unexplained=True,
                             unexplained_in=[("voltage_rate", 0.4, 0.02)],
                             data=SimpleNamespace(input_name="current", input_varies_within_tests=False), validation=None, settings={},
                             to_json=lambda: {})
    monkeypatch.setattr(cli_diagnose, "read_usable", lambda paths, keep=False: [(str(f), f) for f in paths])
    monkeypatch.setattr(cli_diagnose, "unique_names", lambda pairs: pairs)
    monkeypatch.setattr(cli_diagnose, "screening_summary", lambda tests, keep=False: {})
    monkeypatch.setattr(cli_diagnose, "screening_lines", lambda tests, keep=False: [])
    monkeypatch.setattr(cli_diagnose, "diagnose", lambda *a, **k: result)
    args = argparse.Namespace(data=["x"], validate=None, quiet=True, holdout=None, coarse_samples=None,
                              model="normalized", effects=None, out=None, json=False, keep_flagged=False,
                              time_budget=None)
    assert cli_diagnose.run(args) == 0
    out = capsys.readouterr().out
    assert "velocity = 0.01183 m/s" in out and "0.01174" not in out
    assert "current_rate" in out and "voltage" not in out
    assert "base sigma = 50: at the search's upper bound 50, not identified by the data" in out


def test_loop_figure_fits_the_report_page(tmp_path):
    """Six tests: three per row (about 970 px wide at the saved dpi), not six side by side (1944 px)."""
    import numpy as np
    from matplotlib.image import imread

    from damper.diagnosis.report import plot_heldout_loops

    t = np.linspace(0, 2, 400)
    motions = [SimpleNamespace(x=0.01 * np.sin(3 * t) + 1e-14, xdot=0.03 * np.cos(3 * t), name=f"test{i}")
               for i in range(6)]
    force = lambda m: 1e3 * np.tanh(m.xdot / 0.01)  # noqa: E731
    data = SimpleNamespace(motions=motions, heldout=[t > 1 for _ in motions],
                           forces=[force(m) for m in motions])
    model = SimpleNamespace(force=force)
    diagnosis = SimpleNamespace(data=data, base_model=model, final_model=model, model_kind="normalized")
    path = plot_heldout_loops(diagnosis, tmp_path / "loops.png")
    height, width = imread(path).shape[:2]
    assert width <= 1000 and height > width / 2, (width, height)
