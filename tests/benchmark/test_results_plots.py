"""Figures of a run: files are written (PNG, atomically) and refuse runs they cannot draw."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from benchmark.simulator.isolation import bearing_step, bearing_total_force, get_isolation
from benchmark.simulator.plots import (plot_base_orbit, plot_bearing_hysteresis, plot_device_hysteresis,
                             plot_floor_envelopes, plot_run)

XY = np.column_stack([np.linspace(-17.0, 32.0, 92), np.linspace(-47.0, 30.0, 92)])
PNG = b"\x89PNG\r\n\x1a\n"


def run_with_real_bearing_loops(scale=1.0, n_devices=3, n=1200):
    """Decaying figure-eight base motion; bearing forces from the real kernels (friction-lrb)."""
    t = np.arange(n) * 0.01
    env = scale * 0.3 * np.exp(-t / 6.0)
    w = 2 * np.pi / 3.0
    ub = np.stack([env * np.sin(w * t), 0.5 * env * np.sin(2 * w * t), 1e-3 * env * np.sin(w * t)], axis=1)
    vb = np.gradient(ub, t, axis=0)
    packed = get_isolation("friction-lrb").pack()
    ubr = np.stack([ub[:, 0:1] - ub[:, 2:3] * XY[:, 1], ub[:, 1:2] + ub[:, 2:3] * XY[:, 0]], axis=2)
    vbr = np.stack([vb[:, 0:1] - vb[:, 2:3] * XY[:, 1], vb[:, 1:2] + vb[:, 2:3] * XY[:, 0]], axis=2)
    force = np.zeros((n, 92, 2))
    states = packed.states.copy()
    h, tot = np.zeros(2), np.zeros(2)
    for k in range(1, n):
        for i in range(92):
            a, b = ubr[k - 1, i], ubr[k, i]
            va, vb_ = vbr[k - 1, i], vbr[k, i]
            bearing_step(packed.type_ids[i], packed.params[i], states[i], a[0], a[1], b[0], b[1],
                         va[0], va[1], vb_[0], vb_[1], 0.01, h)
            bearing_total_force(packed.params[i], b[0], b[1], vb_[0], vb_[1], h, tot)
            force[k, i] = tot
    floors = np.stack([ub * 0.002 * (f + 1) for f in range(8)], axis=1)
    acc = np.stack([-w ** 2 * ub * (1 + 0.05 * f) for f in range(8)], axis=1)
    drift = floors[:, :, :2] / 4.0
    dx = ub[:, 0:1] * np.ones(n_devices)
    return SimpleNamespace(
        t=t, base_displacement=ub, base_acceleration_absolute=-w ** 2 * ub,
        floor_displacement=floors, floor_acceleration_absolute=acc, drift_ratio=drift,
        bearing_force=force, device_displacement=dx, device_velocity=np.gradient(dx, t, axis=0),
        device_force=1e5 * np.tanh(20 * np.gradient(dx, t, axis=0)), voltage=np.ones((n, n_devices)),
        info={"record": "synthetic", "orientation": "FN-x", "isolation": "friction-lrb",
              "controller": "passive-on" if n_devices else "none"})


@pytest.fixture(scope="module")
def runs():
    return run_with_real_bearing_loops(0.7), run_with_real_bearing_loops(1.0, n_devices=0)


def test_plot_run_writes_all_figures(tmp_path, runs):
    run, ref = runs
    paths = plot_run(run, tmp_path / "fig", reference=ref, bearing_xy=XY, corners=XY[[0, 91]])
    assert [p.name.split("_")[-1] for p in paths] == ["orbit.png", "envelopes.png", "bearings.png",
                                                       "devices.png"]
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == PNG and len(data) > 10_000
    assert sorted(x.name for x in (tmp_path / "fig").iterdir()) == sorted(p.name for p in paths)
    # a run without devices has no device figure
    assert len(plot_run(ref, tmp_path / "ref", bearing_xy=XY)) == 3


def test_plots_refuse_what_they_cannot_draw(tmp_path, runs):
    run, ref = runs
    with pytest.raises(InputError, match="no devices"):
        plot_device_hysteresis(ref, tmp_path / "d.png")
    with pytest.raises(InputError, match="bearing index 92"):
        plot_bearing_hysteresis(run, tmp_path / "b.png", bearings=[92], bearing_xy=XY)
    with pytest.raises(InputError, match="base_displacement"):
        plot_base_orbit(SimpleNamespace(), tmp_path / "o.png")
    assert not any(tmp_path.iterdir())


def test_individual_plots(tmp_path, runs):
    run, ref = runs
    assert plot_floor_envelopes(run, tmp_path / "e.pdf", ref).read_bytes()[:4] == b"%PDF"
    assert plot_base_orbit(run, tmp_path / "o.png").is_file()


def test_run_figures_use_display_units(tmp_path, runs, figures):
    """Issue #16 item 8: displacements in m, forces in kN, as in every other figure."""
    run, ref = runs
    plot_run(run, tmp_path / "fig", reference=ref, bearing_xy=XY, corners=XY[[0, 91]])
    figures.check()
    labels = [text for texts in figures.seen for _, text in texts]
    assert any("displacement" in t and t.endswith("[m]") for t in labels)
    assert not any("[cm]" in t for t in labels)


def test_device_commands_in_amperes_are_labelled_so(tmp_path, runs, figures):
    """A model identified on the coil current commands amperes: the devices' titles say A, not V
    (a probe's run of the UTFSM model had read 'max 1.00 V')."""
    from benchmark.applications.damper_choice import MIXED_COMMAND_UNITS, command_unit
    run, _ = runs
    plot_device_hysteresis(run, tmp_path / "dev.png", command_unit="A")
    titles = [text for texts in figures.seen for _, text in texts if text.startswith("device ")]
    assert titles and all(t.endswith(" A") for t in titles if "max" in t)
    volts, amps = {"input": {"unit": "V"}}, {"input": {"unit": "A"}}
    assert command_unit({"dampers": [amps, amps]}) == "A"
    assert command_unit({"dampers": [volts, amps]}) == MIXED_COMMAND_UNITS  # not "V" for all
    assert command_unit(None) == "V"
