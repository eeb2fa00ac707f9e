"""The Record type: validation, derived histories, peaks, copies."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.errors import InputError
from records import STANDARD_GRAVITY, Record


def _sine_record(amplitude=2.0, freq=1.0, dt=0.001, duration=4.0):
    t = np.arange(int(round(duration / dt))) * dt
    return Record("sine", dt, amplitude * np.sin(2 * np.pi * freq * t), labels=("x",))


def test_shape_time_and_duration():
    rec = Record("r", 0.005, np.zeros((6000, 2)) + 0.1)
    assert rec.n_samples == 6000 and rec.n_components == 2
    assert rec.duration == pytest.approx(30.0)           # n * dt, as the benchmark counts it
    assert rec.time[-1] == pytest.approx(29.995)
    assert rec.labels == ("component 1", "component 2")
    one = Record("r", 0.01, np.ones(10))
    assert one.acceleration.shape == (10, 1)


def test_peaks_match_the_analytic_sine():
    a, f = 2.0, 1.0
    rec = _sine_record(a, f)
    w = 2 * np.pi * f
    assert rec.pga[0] == pytest.approx(a, rel=1e-6)
    assert rec.pga_g[0] == pytest.approx(a / STANDARD_GRAVITY, rel=1e-6)
    # v = a/w (1 - cos wt): peak 2a/w; d = a/w (t - sin(wt)/w): grows linearly
    assert rec.pgv[0] == pytest.approx(2 * a / w, rel=1e-5)
    t = rec.time
    assert np.allclose(rec.displacement()[:, 0], a / w * (t - np.sin(w * t) / w), atol=1e-6)


def test_acceleration_is_a_read_only_copy():
    raw = np.ones((5, 2))
    rec = Record("r", 0.1, raw)
    raw[0, 0] = 99.0
    assert rec.acceleration[0, 0] == 1.0
    with pytest.raises(ValueError):
        rec.acceleration[0, 0] = 2.0


@pytest.mark.parametrize("kwargs, match", [
    (dict(dt=0.0), "dt"),
    (dict(dt=-0.01), "dt"),
    (dict(dt=float("nan")), "dt"),
    (dict(acceleration=np.array([1.0, np.nan, 2.0])), "non-finite acceleration nan at sample 1"),
    (dict(acceleration=np.array([1.0, np.inf])), "non-finite"),
    (dict(acceleration=np.ones((1, 2))), "n_samples >= 2"),
    (dict(acceleration=np.ones((2, 2, 2))), "expected \\(n_samples"),
    (dict(labels=("x",)), "1 labels for 2 components"),
])
def test_invalid_records_are_rejected(kwargs, match):
    args = dict(name="bad", dt=0.01, acceleration=np.ones((10, 2)), labels=("x", "y"))
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        Record(**args)


def test_scaled_select_replace_and_summary():
    rec = Record("r", 0.01, np.column_stack([np.linspace(0, 1, 50), -np.linspace(0, 2, 50)]), labels=("a", "b"))
    s = rec.scaled(3.0).scaled(0.5)
    assert np.allclose(s.acceleration, 1.5 * rec.acceleration)
    assert s.metadata["scale_factor"] == pytest.approx(1.5)
    sw = rec.select([1, 0])
    assert sw.labels == ("b", "a") and np.array_equal(sw.acceleration[:, 0], rec.acceleration[:, 1])
    with pytest.raises(InputError, match="component 2 does not exist"):
        rec.select([2])
    with pytest.raises(InputError, match="dt"):
        rec.replace(dt=-1.0)
    summary = rec.summary()
    assert summary["pga_g"][1] == pytest.approx(2 / STANDARD_GRAVITY)
    assert summary["n_samples"] == 50 and summary["labels"] == ["a", "b"]
    assert "pga_g" in repr(rec)


def test_importing_records_does_not_import_the_simulator():
    import subprocess
    import sys

    code = ("import sys, records; bad = [m for m in sys.modules if m.startswith(('benchmark.', 'damper', "
            "'controllers')) and m not in ('benchmark.errors', 'benchmark.paths', 'benchmark.atomic', "
            "'benchmark.textfile')]; "
            "print(bad); raise SystemExit(1 if bad else 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
