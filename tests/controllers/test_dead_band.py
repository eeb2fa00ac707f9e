"""Switching before the earthquake (issue #16 item 12): the clipped-optimal law's dead band on the
desired force, and the duty-cycle view of the voltage panel."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import ParameterError
from controllers.compiled import LAW_CLIPPED_OPTIMAL, CompiledController, run_compiled


def _static(dead_band):
    Dc = np.zeros((2, 3))
    Dc[:, 0] = 1.0   # f_c = y[0]; the device forces are y[1], y[2]
    return CompiledController(name="t", n_meas=3, n_devices=2, control_step=0.01,
                              law_id=LAW_CLIPPED_OPTIMAL, law_params=dead_band, v_max=1.0, slew_rate=np.inf, Dc=Dc)


def test_dead_band_keeps_small_desired_forces_off():
    y = np.array([[50.0, 1.0, 1.0],      # |fc| 50 N < 100 N band: off although (fc - f) f > 0
                  [500.0, 1.0, 1.0],     # above the band: on
                  [-500.0, 1.0, 1.0]])   # above the band, wrong sign: off
    v, _, _ = run_compiled(_static([100.0, 100.0]), y)
    assert v[:, 0].tolist() == [0.0, 1.0, 0.0]
    v0, _, _ = run_compiled(_static(0.0), y)       # no band: Dyke's law as before
    assert v0[:, 0].tolist() == [1.0, 1.0, 0.0]
    with pytest.raises(ParameterError, match="dead band"):
        _static(-1.0)


def _quiet_then_strong(dt=0.005):
    """3 s of a 2e-3 m/s² ground motion (a record's quiet lead-in), then 3 s of 2 m/s²."""
    from records.record import Record

    t = np.arange(int(6.0 / dt)) * dt
    rng = np.random.default_rng(1)
    quiet = 2e-3 * np.sin(2 * np.pi * 1.3 * t) + 5e-4 * rng.standard_normal(t.size)
    strong = 2.0 * np.sin(2 * np.pi * 0.6 * t)
    acc = np.where(t < 3.0, quiet, strong)
    return Record(name="lead-in", dt=dt, acceleration=np.column_stack([acc, 0.3 * acc]), labels=("x", "y"),
                  source="synthetic: quiet lead-in, then a strong pulse train", synthetic=True, metadata={})


@pytest.fixture(scope="module")
def building():
    from benchmark.simulator.building import Building

    return Building.default(n_modes=12)


def test_clipped_optimal_is_quiet_before_the_earthquake(building):
    from benchmark.simulator.simulation import simulate
    from controllers.clipped_optimal import DEFAULT_DEAD_BAND, ClippedOptimal

    assert DEFAULT_DEAD_BAND > 0
    record = _quiet_then_strong()
    plain = simulate(building, record, ClippedOptimal(dead_band=0.0))
    banded = simulate(building, record, ClippedOptimal())
    t = np.asarray(plain.t)
    quiet, strong = t < 3.0, t >= 3.5
    # the sign-only law switches on a 2e-3 m/s² motion as if it were an earthquake ...
    assert plain.voltage[quiet].mean() > 0.2
    # ... the dead band keeps the devices off then, and still acts in the strong motion
    assert banded.voltage[quiet].mean() < 0.01
    assert banded.voltage[strong].mean() > 0.2


def test_dead_band_must_be_a_fraction():
    from controllers.clipped_optimal import ClippedOptimal

    with pytest.raises(ParameterError, match="dead_band"):
        ClippedOptimal(dead_band=1.5)


def test_voltage_panel_shows_a_readable_duty_cycle(tmp_path, monkeypatch):
    """Bang-bang voltages (0/1 V switching every few steps) are drawn as a 1 s moving mean."""
    from matplotlib.figure import Figure

    from benchmark.applications.comparison import ComparisonResult, ComparisonRun
    from benchmark.applications.comparison_plots import plot_histories

    t = np.arange(0.0, 20.0, 0.02)
    rng = np.random.default_rng(0)
    v = (rng.random((t.size, 4)) < 0.3).astype(float)       # 30 % duty cycle, switching constantly
    h = {"t": t, "base_displacement": np.zeros((t.size, 2)), "device_force_total": np.zeros((t.size, 2)),
         "voltage": v}
    result = ComparisonResult(runs=[ComparisonRun("kobe", "FN-x", "clipped-optimal", {}, {}, h)], references={})
    seen = {}
    original = Figure.savefig

    def savefig(self, *args, **kwargs):
        ax = self.axes[2]
        seen["ylabel"] = ax.get_ylabel()
        seen["y"] = ax.get_lines()[0].get_ydata()
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    plot_histories(result, "kobe", "FN-x", tmp_path / "h.png")
    y = np.asarray(seen["y"], dtype=float)
    assert "1 s" in seen["ylabel"] and "[V]" in seen["ylabel"]
    assert np.nanmean(y) == pytest.approx(v.mean(), abs=0.02)
    raw_variation = np.abs(np.diff(v.mean(axis=1))).sum()
    assert np.abs(np.diff(y[~np.isnan(y)])).sum() < 0.1 * raw_variation


def test_skyhook_is_quiet_before_the_earthquake(building):
    from benchmark.simulator.simulation import simulate
    from controllers.skyhook import Skyhook

    record = _quiet_then_strong()
    plain = simulate(building, record, Skyhook(dead_band=0.0))
    banded = simulate(building, record, Skyhook())
    quiet = np.asarray(plain.t) < 3.0
    assert plain.voltage[quiet].mean() > 0.05
    assert banded.voltage[quiet].mean() < 0.01 and banded.voltage[~quiet].mean() > 0.1
