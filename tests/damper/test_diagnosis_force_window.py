"""The report's force window (issue 24: "measured and predicted force over a window, the residual
trace"): a few displacement reversals of the held-out part, readable on the report page."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from damper.diagnosis.report import force_window, plot_force_window


def test_window_spans_the_asked_reversals_of_a_sine():
    t = np.linspace(0.0, 10.0, 10001)            # 1 kHz, 10 cycles of 1 Hz
    x = 0.01 * np.sin(2 * np.pi * t)
    scored = t >= 5.0
    start, stop = force_window(x, scored, reversals=6)
    assert start == np.flatnonzero(scored)[0]
    # six reversals after t = 5 s: the peaks at 5.25, 5.75, ..., 7.75 s (plus the band's return)
    assert 7.75 < t[stop - 1] < 8.0, t[stop - 1]


def test_noise_does_not_end_the_window_early():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 10.0, 10001)
    x = 0.01 * np.sin(2 * np.pi * t) + 2e-4 * rng.standard_normal(t.size)   # 2 % noise: many tiny reversals
    start, stop = force_window(x, np.ones(t.size, bool), reversals=4)
    assert 1.7 < t[stop - 1] < 2.1, t[stop - 1]


def test_window_is_capped_and_empty_mask_gives_none():
    t = np.linspace(0.0, 100.0, 100001)
    x = 0.01 * np.sin(2 * np.pi * 0.05 * t)       # slow: six reversals take 60 s
    start, stop = force_window(x, np.ones(t.size, bool), reversals=6, max_samples=5000)
    assert (start, stop) == (0, 5000)
    assert force_window(x, np.zeros(t.size, bool)) is None


def test_window_figure_is_page_wide_and_marks_unscored_samples(tmp_path):
    from matplotlib.image import imread

    t = np.linspace(0.0, 8.0, 1601)
    motions = [SimpleNamespace(t=t, x=0.01 * np.sin(2 * np.pi * t), xdot=0.02 * np.pi * np.cos(2 * np.pi * t),
                               name=f"test{i}") for i in range(3)]
    force = lambda m: 1e3 * np.tanh(m.xdot / 0.01)  # noqa: E731
    held = [t > 6.0 for _ in motions]
    held[1] = held[1] & ~((t > 6.5) & (t < 6.7))   # screened-out samples inside the held-out part
    data = SimpleNamespace(motions=motions, heldout=held, forces=[force(m) * 1.05 for m in motions])
    model = SimpleNamespace(force=force)
    diagnosis = SimpleNamespace(data=data, base_model=model, final_model=model, model_kind="spencer",
                                effects=["inertia"], errors_by_test={m.name: (0.05, 0.04) for m in motions})
    path = plot_force_window(diagnosis, tmp_path / "window.png")
    height, width = imread(path).shape[:2]
    assert 900 <= width <= 1000, width
    one = SimpleNamespace(**{**vars(diagnosis), "data": SimpleNamespace(
        motions=motions[:1], heldout=held[:1], forces=data.forces[:1])})
    height1, width1 = imread(plot_force_window(one, tmp_path / "one.png")).shape[:2]
    assert width1 == width and height1 < height
