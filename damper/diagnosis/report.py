"""Markdown report and plots of a residual-loop run (:class:`~damper.diagnosis.loop.Diagnosis`).

:func:`write_report` writes into a directory

* ``report.md`` -- held-out errors before and after, the effects added (parameters, error after
  each), what was tried in each round and why it did or did not pay, the residual trace before and
  after, whiteness figures, errors per test and per coil-input level, the verdict;
* ``residual_trace.png`` -- the held-out residual against each variable, before (grey) and after
  (colour), with its binned partial dependence;
* ``force_histories.png`` -- measured force and the two models over each test's held-out part;
* ``force_window.png`` -- measured force and the two models over a readable window of each test's
  held-out part (a few displacement reversals), with the residual of both below (the seed
  paper's force and force-error histories, its Figs. 6 and 11);
* ``loops.png`` -- force-displacement and force-velocity loops over the same window;
* ``diagnosis.json`` -- :meth:`Diagnosis.to_json`.

Every file is written atomically; plots use the Agg backend.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from benchmark.foundation.atomic import atomic_write_text
from benchmark.foundation.figures import fixed_layout, save_figure
from benchmark.foundation.display_units import axis_label, to_display
from damper.diagnosis.trace import TRACE_VARIABLES
from damper.diagnosis.effects import EFFECTS
from damper.diagnosis.interference import interference_lines
from damper.diagnosis.coverage import coverage_lines
from damper.diagnosis.levels import level_lines
from damper.diagnosis.loop import force_zero_text, tare_matters
from damper.io.screening import screening_lines, screening_summary
from damper.lab.plots import draw_loops

__all__ = ["residual_not_white", "write_report", "report_markdown", "plot_residual_trace", "plot_force_histories",
           "plot_force_window", "plot_validation_window", "force_window", "plot_heldout_loops"]

#: trace variable -> (axis text, quantity kind of benchmark.foundation.display_units); the coil input's
#: kind ("voltage" or "current") is the tests' own
_LABELS = {"displacement": ("displacement", "displacement"), "velocity": ("velocity", "velocity"),
           "acceleration": ("acceleration", "acceleration"), "time": ("time since test start", "time"),
           "sign": ("sign of velocity", None), "loop": ("displacement on each branch", "displacement")}
_MAX_POINTS = 4000


def _trace_axis(var: str, input_name: str) -> tuple[str, str, str | None]:
    """(panel name, axis label, display kind) of trace variable ``var``; the coil input is named
    for what the tests give (``voltage`` [V] or ``current`` [A])."""
    if var == "voltage":
        return input_name, axis_label(input_name, input_name), input_name
    if var == "voltage_rate":
        unit = axis_label("", input_name).strip()[1:-1]
        return f"{input_name} rate", f"{input_name} rate [{unit}/s]", None
    text, kind = _LABELS[var]
    return var, (axis_label(text, kind) if kind else text), kind


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path: Path, dpi: int = 90) -> Path:
    return save_figure(fig, path, dpi=dpi)


def model_forces(diagnosis) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The base and the final model's force histories [N] over every test of ``diagnosis``.

    Each plot below needs both. The loop keeps the histories it computed its errors from
    (:attr:`damper.diagnosis.loop.Diagnosis.forces_before`); a diagnosis without them has them
    simulated here (by each figure). On a 67 000-sample recording (``ranran_50``, the normalized
    base's final model, one core, 2026-11-28) :func:`write_report` took 4.7 s of CPU when each
    of the four figures simulated both models, 1.7-2.6 s with the loop's own histories.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose` (or anything with ``data``,
        ``base_model`` and ``final_model``).
    """
    data = diagnosis.data
    kept_before = getattr(diagnosis, "forces_before", ())
    kept_after = getattr(diagnosis, "forces_after", ())
    if len(kept_before) == len(data.motions) and len(kept_after) == len(data.motions):
        return list(kept_before), list(kept_after)
    before = [diagnosis.base_model.force(m) for m in data.motions]
    after = [diagnosis.final_model.force(m) for m in data.motions]
    return before, after


def plot_residual_trace(diagnosis, path, max_points: int = _MAX_POINTS, dpi: int = 90) -> Path:
    """Residual against each traced variable, before and after (held-out samples; at most
    ``max_points`` random samples are drawn as dots, the binned means use all).

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    path
        Image file to write (format from the suffix).
    max_points : int, optional
        At most this many random samples are drawn as dots.
    dpi : int, optional
        Resolution of the image [dots per inch].
    """
    plt = _pyplot()
    data = diagnosis.data
    before, after = model_forces(diagnosis)
    measured = data.measured("heldout")
    r_before = measured - data.concat(before, "heldout")
    r_after = measured - data.concat(after, "heldout")
    signals = data.signals("heldout")
    signals["sign"] = np.where(signals["velocity"] > 0, 1.0, -1.0)
    signals["loop"] = signals["displacement"]
    n = r_before.size
    pick = np.arange(n) if n <= max_points else np.random.default_rng(0).choice(n, max_points, replace=False)
    fig, axes = plt.subplots(2, 4, figsize=(16, 7.5))
    input_name = "current" if data.input_unit == "A" else "voltage"
    r_before, r_after = to_display(r_before, "force"), to_display(r_after, "force")
    for ax, var in zip(axes.ravel(), TRACE_VARIABLES):
        name, label, kind = _trace_axis(var, input_name)
        z = to_display(signals[var], kind) if kind else signals[var]
        if diagnosis.trace_before.profiles[var].constant:
            # constant in these tests: its rounding noise (a current rate of 1e-14 A/s) is no axis
            z = np.full(z.shape, float(np.median(z)))
        ax.plot(z[pick], r_before[pick], ".", color="0.6", ms=2, alpha=0.5, label="before")
        ax.plot(z[pick], r_after[pick], ".", color="tab:blue", ms=2, alpha=0.5, label="after")
        for trace, color in ((diagnosis.trace_before, "k"), (diagnosis.trace_after, "tab:red")):
            prof = trace.profiles[var]
            if prof.constant:
                continue
            c = to_display(prof.centers, kind) if kind else prof.centers
            means = to_display(prof.means, "force")
            if var == "loop":
                for b, ls in ((1.0, "-"), (-1.0, "--")):
                    sel = prof.branch == b
                    ax.plot(c[sel], means[sel], ls, color=color, lw=1.6)
            else:
                style = {"sign": "-o", "time": "o"}.get(var, "-")  # time: one point per cycle
                ax.plot(c, means, style, color=color, lw=1.6, ms=4)
        ax.set_xlabel(label)
        ax.set_title(f"{name}: share {diagnosis.trace_before.shares[var]:.2f} → "
                     f"{diagnosis.trace_after.shares[var]:.2f}", fontsize=10)
        if diagnosis.trace_before.profiles[var].constant:
            ax.text(0.5, 0.9, "constant in these tests", transform=ax.transAxes, ha="center")
        ax.grid(True, alpha=0.3)
    axes[0, 0].set_ylabel(axis_label("residual F − F̂", "force"))
    axes[1, 0].set_ylabel(axis_label("residual F − F̂", "force"))
    axes[0, 0].legend(loc="lower right", markerscale=4, fontsize=8)
    effects = ", ".join(diagnosis.effects) or "none"
    fig.suptitle(f"Held-out residual: {diagnosis.model_kind} model (grey, black line = binned mean) "
                 f"and after adding {effects} (blue, red line)", fontsize=11)
    # fixed margins: tight_layout measured the eight panels' labels for a third of the figure's cost
    fixed_layout(fig, left=0.75, right=0.2, top=0.65, bottom=0.55, hgap=0.85, wgap=0.6)
    return _save(fig, Path(path), dpi)


def _grid(n: int):
    cols = min(n, 3)
    rows = int(math.ceil(n / cols))
    return rows, cols


def plot_force_histories(diagnosis, path, max_tests: int = 6) -> Path:
    """Measured force and both models over the held-out part of each test.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    path
        Image file to write (format from the suffix).
    max_tests : int, optional
        At most this many tests are drawn (the first ones).
    """
    plt = _pyplot()
    data = diagnosis.data
    before, after = model_forces(diagnosis)
    idx = [i for i, k in enumerate(data.heldout) if k.any()][:max_tests]
    rows, cols = _grid(len(idx))
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 3.4 * rows), squeeze=False)
    for ax, i in zip(axes.ravel(), idx):
        m, k = data.motions[i], data.heldout[i]
        sel = np.flatnonzero(k)
        t = m.t[sel]
        ax.plot(t, to_display(data.forces[i][sel], "force"), color="k", lw=1.2, label="measured")
        ax.plot(t, to_display(before[i][sel], "force"), color="0.55", lw=1.0, ls="--", label=diagnosis.model_kind)
        ax.plot(t, to_display(after[i][sel], "force"), color="tab:red", lw=1.0, label=diagnosis.final_model.name)
        eb, ea = diagnosis.errors_by_test[m.name]
        ax.set_title(f"{m.name}: error {eb:.3f} → {ea:.3f}", fontsize=10)
        ax.set_xlabel(axis_label("time", "time"))
        ax.set_ylabel(axis_label("force", "force"))
        ax.grid(True, alpha=0.3)
    for ax in axes.ravel()[len(idx):]:
        ax.axis("off")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Held-out force histories", fontsize=11)
    fixed_layout(fig, left=0.8, right=0.2, top=0.7, bottom=0.55, hgap=0.85, wgap=0.8)
    return _save(fig, Path(path))


def force_window(x: np.ndarray, scored: np.ndarray, reversals: int = 6,
                 hysteresis: float = 0.1, max_samples: int = 6000) -> tuple[int, int] | None:
    """A readable window ``[start, stop)`` of the scored samples: from the first scored sample to
    the ``reversals``-th displacement reversal after it, and at most ``max_samples`` long.

    A reversal counts when the displacement comes back from its running extreme by more than
    ``hysteresis`` times its range over the scored span, so that noise and small wiggles of a
    random motion do not end the window early: a sinusoidal test shows ``reversals / 2`` cycles,
    a random one its same number of large strokes.

    Parameters
    ----------
    x : np.ndarray
        Displacement of the test [m].
    scored : np.ndarray
        Boolean mask of the samples to show (e.g. the held-out samples that count in the error).
    reversals : int, optional
        Reversals the window spans.
    hysteresis : float, optional
        Return, as a fraction of the displacement range, that makes a reversal.
    max_samples : int, optional
        Longest window [samples].

    Returns
    -------
    tuple of int or None
        ``(start, stop)`` sample indices, or None when no sample is scored.
    """
    idx = np.flatnonzero(scored)
    if idx.size == 0:
        return None
    start, last = int(idx[0]), int(idx[-1])
    seg = np.asarray(x, dtype=float)[start:last + 1]
    band = hysteresis * float(np.ptp(seg))
    stop = last + 1
    count, direction = 0, 0
    high = low = seg[0]  # running extremes; one of them is the current stroke's once moving
    for i, value in enumerate(seg):
        high, low = max(high, value), min(low, value)
        if direction >= 0 and high - value > band:  # falling back from a maximum
            count += direction > 0
            direction, low = -1, value
        elif direction <= 0 and value - low > band:  # rising back from a minimum
            count += direction < 0
            direction, high = 1, value
        if count >= reversals:
            stop = start + i + 1
            break
    return start, min(stop, start + max_samples)


def plot_force_window(diagnosis, path, max_tests: int = 6, reversals: int = 6, dpi: int = 90) -> Path:
    """Measured force and both models over a readable window of each test's held-out part
    (:func:`force_window`), and below it the residual of each model in the same window.

    Samples the error does not count (screened out, or the warm-up) are left blank in the
    measured force; the models are drawn through them.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    path
        Image file to write (format from the suffix).
    max_tests : int, optional
        At most this many tests are drawn (the first ones).
    reversals : int, optional
        Displacement reversals each window spans.
    dpi : int, optional
        Resolution of the image [dots per inch].
    """
    data = diagnosis.data
    before, after = model_forces(diagnosis)
    panels = []
    for i in [i for i, k in enumerate(data.heldout) if k.any()][:max_tests]:
        m = data.motions[i]
        eb, ea = diagnosis.errors_by_test[m.name]
        panels.append((m, data.forces[i], data.heldout[i], before[i], after[i],
                       f"{m.name}: held-out error {eb:.3f} → {ea:.3f}"))
    return _window_figure(diagnosis, panels, path, reversals, dpi,
                          "Held-out force (top) and residual F − F̂ (bottom) over a window of a few strokes")


def plot_validation_window(diagnosis, path, max_tests: int = 4, reversals: int = 6, dpi: int = 90) -> Path:
    """:func:`plot_force_window` for the other recordings of ``sbib diagnose --validate``: the
    base and the final model, fitted on the tests, predicting a recording they never saw.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose` with ``cross_validate`` recordings.
    path
        Image file to write (format from the suffix).
    max_tests : int, optional
        At most this many recordings are drawn (the first ones).
    reversals : int, optional
        Displacement reversals each window spans.
    dpi : int, optional
        Resolution of the image [dots per inch].
    """
    by_test = (diagnosis.validation or {}).get("errors_by_test", {})
    panels = []
    for h in diagnosis.validation_histories[:max_tests]:
        errs = by_test.get(h.motion.name, {})
        panels.append((h.motion, h.force, h.scored, h.before, h.after,
                       f"{h.motion.name} (never fitted): error {errs.get('before', np.nan):.3f} → "
                       f"{errs.get('after', np.nan):.3f}"))
    return _window_figure(diagnosis, panels, path, reversals, dpi,
                          "Other recordings of the device: force (top) and residual F − F̂ (bottom) "
                          "over a few strokes")


def _window_figure(diagnosis, panels, path, reversals: int, dpi: int, title: str) -> Path:
    """Force and residual windows, one cell per ``(motion, force, scored, before, after, title)``."""
    plt = _pyplot()
    n_cols = 1 if len(panels) <= 1 else 2  # about 990 px wide at 90 dpi: legible on the report page
    n_rows = max(1, -(-len(panels) // n_cols))
    # heights in inches: a header (title, legend) and a footer of fixed size, 4 in per row of tests
    header, footer, row = 0.85, 0.5, 4.0
    height = header + footer + row * n_rows
    fig = plt.figure(figsize=(11.0, height))
    outer = fig.add_gridspec(n_rows, n_cols, hspace=0.38, wspace=0.22, left=0.08, right=0.98,
                             top=1.0 - header / height, bottom=footer / height)
    base_label, final_label = f"{diagnosis.model_kind} (base)", "augmented"
    if diagnosis.effects:
        final_label += " (+ " + ", ".join(diagnosis.effects) + ")"
    handles, labels, shaded = [], [], False
    for j, (m, force, k, before, after, panel_title) in enumerate(panels):
        start, stop = force_window(m.x, k, reversals) or (0, 0)
        cell = outer[j // n_cols, j % n_cols].subgridspec(2, 1, height_ratios=(2.2, 1.2), hspace=0.08)
        ax_f = fig.add_subplot(cell[0])
        ax_r = fig.add_subplot(cell[1], sharex=ax_f)
        sl = slice(start, stop)
        t = m.t[sl]
        shown = k[sl]
        measured = np.where(shown, force[sl], np.nan)
        f_m = to_display(measured, "force")
        ax_f.plot(t, f_m, color="k", lw=1.3, label="measured")
        ax_f.plot(t, to_display(before[sl], "force"), color="0.5", lw=1.0, ls="--", label=base_label)
        ax_f.plot(t, to_display(after[sl], "force"), color="tab:red", lw=1.0, label=final_label)
        for model, color, ls in ((before, "0.5", "--"), (after, "tab:red", "-")):
            ax_r.plot(t, to_display(measured - model[sl], "force"), color=color, lw=0.9, ls=ls)
        ax_r.axhline(0.0, color="k", lw=0.6)
        if not shown.all():  # where the error does not count: shaded
            shaded = True
            for a, b in _spans(~shown):
                for ax in (ax_f, ax_r):
                    ax.axvspan(t[a], t[min(b, t.size - 1)], color="tab:orange", alpha=0.15, lw=0)
        ax_f.set_title(panel_title, fontsize=9.5)
        ax_f.set_ylabel(axis_label("force", "force"))
        ax_r.set_ylabel(axis_label("F − F̂", "force"))
        ax_r.set_xlabel(axis_label("time", "time"))
        ax_f.tick_params(labelbottom=False)
        for ax in (ax_f, ax_r):
            ax.grid(True, alpha=0.3)
        if j == 0:
            handles, labels = ax_f.get_legend_handles_labels()
    if panels:
        fig.legend(handles, labels, loc="upper center", ncol=3, fontsize=9, frameon=False,
                   bbox_to_anchor=(0.5, 1.0 - 0.3 / height))
    # short enough for the 11-in figure at 11 pt (about 125 characters)
    fig.suptitle(title + ("; shaded: not scored" if shaded else ""), fontsize=11,
                 y=1.0 - 0.08 / height, va="top")
    return _save(fig, Path(path), dpi)


def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` index of each run of True in ``mask``."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


def plot_heldout_loops(diagnosis, path, max_tests: int = 6, dpi: int = 90, reversals: int = 6) -> Path:
    """Force-displacement and force-velocity loops of each test over the window of its held-out
    part that :func:`plot_force_window` shows (:func:`force_window`).

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    path
        Image file to write (format from the suffix).
    max_tests : int, optional
        At most this many tests are drawn (the first ones).
    dpi : int, optional
        Resolution of the image [dots per inch].
    reversals : int, optional
        Displacement reversals each window spans.
    """
    plt = _pyplot()
    data = diagnosis.data
    before, after = model_forces(diagnosis)
    idx = [i for i, k in enumerate(data.heldout) if k.any()][:max_tests]
    # At most three tests side by side (two rows each: displacement, velocity), so that the
    # figure is about 970 px wide and its labels legible on the report page at 100 % zoom.
    n_cols = min(3, max(1, len(idx)))
    n_rows = 2 * -(-len(idx) // n_cols) if idx else 2
    fig, grid = plt.subplots(n_rows, n_cols, figsize=(3.6 * n_cols, 3.2 * n_rows), squeeze=False)
    for ax in grid.flat:  # shown again below where a test is drawn
        ax.set_visible(False)
    for j, i in enumerate(idx):
        m, k = data.motions[i], data.heldout[i]
        # the window of the force plot: a long random held-out part drawn whole is a scribble
        start, stop = force_window(m.x, k, reversals) or (0, 0)
        k = k.copy()
        k[:start], k[stop:] = False, False
        r0, col = 2 * (j // n_cols), j % n_cols
        pair = (grid[r0, col], grid[r0 + 1, col])
        curves = [(to_display(data.forces[i][k], "force"), "measured", {"color": "k", "lw": 1.0}),
                  (to_display(before[i][k], "force"), diagnosis.model_kind, {"color": "0.55", "lw": 0.9, "ls": "--"}),
                  (to_display(after[i][k], "force"), "augmented", {"color": "tab:red", "lw": 0.9})]
        draw_loops(pair, to_display(m.x, "displacement")[k], to_display(m.xdot, "velocity")[k], curves,
                   (axis_label("displacement", "displacement"), axis_label("velocity", "velocity")),
                   axis_label("force", "force"))
        for ax in pair:
            ax.set_visible(True)
            ax.ticklabel_format(useOffset=False)  # plain tick values, no "1e-14" offset text
            ax.locator_params(axis="x", nbins=4)  # four ticks: long values ("-0.0075") do not collide
            if col != 0:
                ax.set_ylabel("")
        grid[r0, col].set_title(m.name, fontsize=10)
    grid[0, 0].legend(fontsize=9)
    fig.tight_layout()
    return _save(fig, Path(path), dpi)


def format_parameters(effect: str, params: dict) -> str:
    """``name = value unit`` for each parameter of the library effect ``effect`` (SI units)."""
    unit = getattr(EFFECTS.get(effect), "unit", None)
    suffix = "" if unit in (None, "-", "1") else f" {unit}"
    return ", ".join(f"{k} = {v:.4g}{suffix}" for k, v in params.items())


def input_word(variable: str, input_name: str) -> str:
    """A trace variable named for the coil input the tests give (``voltage`` -> ``current``); the
    entry of structure no variable locates (:data:`damper.diagnosis.loop.UNLOCATED`) in words."""
    if variable == "unlocated":
        return "no trace variable (a residual that is not white)"
    return variable.replace("voltage", input_name) if input_name != "voltage" else variable


def _fmt_params(params: dict, effect: str = "") -> str:
    return format_parameters(effect, params)


def report_markdown(diagnosis, plots: dict | None = None) -> str:
    """The Markdown text of the report.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    plots : dict | None, optional
        Plot paths by kind to link (:func:`write_report`); None: no plots.
    """
    d = diagnosis
    data = d.data
    unit = data.input_unit
    lines = ["# Residual loop: diagnosis of the damper model", ""]
    split = (f"last {100 * data.holdout:g} % of each test held out" if data.holdout is not None
             else "separate validation tests held out")
    lines += [f"- Tests: {', '.join(data.names)} ({split}; the samples before each test's first "
              "reversal are not scored).",
              (f"- Coil input: {data.input_name} [{unit}]." if data.input_recorded else
               "- Coil input: **none in the files**, taken as 0 V (a passive test, or a column left "
               "out: the model's voltage laws hold for 0 V only)."),
              f"- Base model: **{d.model_kind}**" + (" (Spencer et al. 1997, field lag inside)"
                                                     if d.model_kind == "spencer" else " Bouc-Wen")
              + ("" if d.settings.get("nodes") is None else
                 f", parameters as PCHIP laws on {data.input_name} nodes {d.settings['nodes']}") + ".",
              f"- Held-out relative RMS force error: **{d.error_before:.4f} → {d.error_after:.4f}**"
              f" ({d.final_model.name}).", ""]
    if d.base_at_bounds:
        lines[-1:-1] = ["- **Base shape at a bound of the search**: "
                        + ", ".join(f"{name} = {getattr(d.final_model.base, name):.4g} ({where})"
                                    for name, where in d.base_at_bounds.items())
                        + ". The data did not identify it: the fit would have moved it further."]
    if getattr(d, "validation", None):
        v = d.validation
        lines[-1:-1] = [f"- Other recordings of the device ({', '.join(v['tests'])}, never fitted): "
                        f"relative RMS force error **{v['error_before']:.4f} → {v['error_after']:.4f}**"
                        + (f"; with each recording's force zero re-estimated on it (a load cell's tare, not the "
                           f"device's: " + force_zero_text(v)
                           + f") {v['error_before_force_zero']:.4f} → {v['error_after_force_zero']:.4f}"
                           if tare_matters(v) else "") + "."]
        if len(v["tests"]) > 1:  # a pooled figure hides which recording the model misses
            lines[-1:-1] = ["  - " + ", ".join(f"{name} {e['before']:.4f} → {e['after']:.4f}"
                                                for name, e in v["errors_by_test"].items()) + "."]
        lines[-1:-1] = [f"- {name}: {c['samples']} samples of its {d.data.input_name} lie outside the fitted "
                        f"tests' range (by up to {c['largest_excess']:.3g}); the models saw them held at its edge."
                        for name, c in (v.get("input_clipped") or {}).items()]
        unit = d.data.input_unit
        lines[-1:-1] = [f"- {name}: {c['samples']} scored samples ({100 * c['share']:.0f} %) of its {d.data.input_name} "
                        f"lie outside the fitted levels ({c['levels'][0]:.4g}–{c['levels'][1]:.4g} {unit}): "
                        "there the voltage laws extrapolate."
                        for name, c in (v.get("input_beyond_levels") or {}).items()]
        lines[-1:-1] = [f"- **{text}**." if finding else f"- {text}."  # each starts with a recording's name
                        for text, finding in coverage_lines(v.get("coverage"))]
    al = getattr(d, "alignment", None)
    if al is not None:
        if al["finding"]:
            lines[-1:-1] = [f"- **The measured force is {1e3 * al['shift_s']:+.3g} ms ({al['shift_samples']:+.1f} samples) "
                            f"off the final model**: shifted by that much the error over the usable samples falls "
                            f"{al['error_unshifted']:.4f} → {al['error_shifted']:.4f}. A skew between the force "
                            "and motion channels (or a lag the model lacks): check the rig's timing; nothing "
                            "was shifted."]
        elif not al.get("identifiable", True):
            freqs = al.get("frequencies") or []
            span = (f"{min(freqs):.3g} Hz" if len(freqs) == 1 or max(freqs) < 1.05 * min(freqs)
                    else f"{min(freqs):.3g}-{max(freqs):.3g} Hz")
            lines[-1:-1] = [f"- Force channel against the final model: best alignment at {1e3 * al['shift_s']:+.3g} ms; "
                            f"every test moves as one sinusoid at {span}, where a skew between the force and motion "
                            "channels reads as the model's phase: these tests cannot tell them apart (tests at "
                            "other frequencies, or a broadband test, can)."]
        else:
            lines[-1:-1] = [f"- Force channel against the final model: best alignment at {1e3 * al['shift_s']:+.3g} ms "
                            f"({al['shift_samples']:+.2f} samples, searched ±{1e3 * al['searched_s']:.3g} ms): "
                            "no skew between force and motion channels."]
    lines[-1:-1] = [f"- **{text[0].upper()}{text[1:]}**." if finding else f"- {text[0].upper()}{text[1:]}."
                    for text, finding in level_lines(getattr(d, "force_levels", None))]
    found = getattr(d, "interference", None)
    lines[-1:-1] = [f"- **{text[0].upper()}{text[1:]}**." if finding else f"- {text[0].upper()}{text[1:]}."
                    for text, finding in interference_lines(found)]
    if found is not None and not found["lines"]:
        lines[-1:-1] = [f"- Mains lines (50 or 60 Hz and harmonics) in the final residual: none in the "
                        f"{len(found['searched'])} of {found['tests']} test(s) long and uniform enough to search."]
    if d.settings.get("dropped_at_full_rate"):
        lines[-1:-1] = [f"- Left out: {', '.join(d.settings['dropped_at_full_rate'])}, chosen on the coarse pass "
                        "but without a lower held-out error over every sample."]
    if d.settings.get("coarse_windows"):
        lines[-1:-1] = [f"- The base fit and the effect selection ran on {d.settings['coarse_windows']} windows of "
                        f"the tests (one sample in {d.settings.get('decimation')}, each window simulated from "
                        "rest a quarter second before its first scored sample): the tests are long and their "
                        "motion broadband. Every error here is over every sample of the whole tests."]
    if d.settings.get("stopped_by_budget"):
        lines[-1:-1] = [f"- The time budget ({d.settings['time_budget']:g} s) ended the effect "
                        "selection: the model so far is reported."]
    lines += ["## Effects added", ""]
    if d.selection.steps:
        lines += ["| step | effect | parameters at that step (SI) | held-out error before | after | BIC change | N_eff |",
                  "|---|---|---|---|---|---|---|"]
        for i, s in enumerate(d.selection.steps, 1):
            lines.append(f"| {i} | `{s.name}` | {_fmt_params(s.parameters, s.name)} | {s.error_before:.4f} | "
                         f"{s.error_after:.4f} | {s.bic_delta:+.1f} | {s.effective_samples:.0f} |")
        final = {e.name: e.parameters for e in d.final_model.effects}
        lines += ["", "Parameters after the last joint refit: "
                  + "; ".join(f"`{k}`: {_fmt_params(v, k)}" for k, v in final.items()) + "."]
    else:
        lines.append("None paid on the held-out data.")
    lines += ["", "## Rounds", "",
              f"Each round screens every remaining effect (share of the training residual it can "
              f"remove, orthogonally to the model's own parameters), refits the best "
              f"{d.settings.get('trials')} jointly, and adds the one with the lowest held-out BIC "
              f"if it also lowers the held-out error by at least {100 * d.settings.get('min_gain', 0):g} %.", ""]
    for r, (screens, trials) in enumerate(d.selection.rounds, 1):
        lines.append(f"**Round {r}.** Screening: " + ", ".join(
            f"`{s.name}` {s.score:.3f}" + (f" ({s.reason})" if s.reason else "")
            for s in sorted(screens.values(), key=lambda s: -s.score)) + ".")
        dropped = set(d.settings.get("dropped_at_full_rate") or ())
        for t in trials:
            verdict = ("added on the coarse pass, left out (no lower held-out error over every sample)"
                       if t.accepted and t.name in dropped else "**added**" if t.accepted else "not added")
            lines.append(f"- `{t.name}`: held-out error {t.error:.4f}, BIC change {t.bic_delta:+.1f}, "
                         f"{_fmt_params(t.parameters, t.name)} — {verdict}" + (f" ({t.note})" if t.note else ""))
        lines.append("")
    lines += ["## Residual trace (held-out)", "",
              "Share of the residual variance explained by each variable (binned partial dependence, "
              "bias-adjusted correlation ratio); `mean` is the constant part of the mean square.", "",
              "| variable | before | after |", "|---|---|---|"]
    for var in (*TRACE_VARIABLES, "mean"):
        b = d.trace_before.mean_share if var == "mean" else d.trace_before.shares[var]
        a = d.trace_after.mean_share if var == "mean" else d.trace_after.shares[var]
        lines.append(f"| {var} | {b:.3f} | {a:.3f} |")
    tb, ta = d.trace_before, d.trace_after
    lines += ["", f"Whiteness (Ljung-Box, {ta.lags} lags): Q = {tb.ljung_box:.4g} → {ta.ljung_box:.4g}, "
              f"p = {tb.ljung_box_p:.3g} → {ta.ljung_box_p:.3g}; lag-1 autocorrelation "
              f"{tb.lag1:.3f} → {ta.lag1:.3f}; effective samples {tb.effective_samples:.0f} → "
              f"{ta.effective_samples:.0f}; white-noise share of the variance {tb.noise_fraction:.3f} → "
              f"{ta.noise_fraction:.3f}.", ""]
    lines += ["## Verdict", ""]
    if d.unexplained:
        lines.append("**Unexplained structure remains** (no library term paid for it). It lives in: "
                     + ", ".join(f"`{v}` (share {s:.2f}, {100 * lv:.1f} % of the force RMS)"
                                 if v != "unlocated" else
                                 f"no variable of the trace: the residual is not white (structured share "
                                 f"{s:.2f}, {100 * lv:.1f} % of the force RMS; lag-1 autocorrelation "
                                 f"{ta.lag1:.3f}), as a channel skew, a lag, a dead zone after reversals or "
                                 "a change of the device between tests leave it"
                                 for v, s, lv in d.unexplained_in) + ".")
    else:
        lines.append(f"No residual structure above {100 * d.settings.get('structure_level', 0):g} % of "
                     f"the force RMS is left (threshold share {d.settings.get('structure_share')})"
                     + (f"{residual_not_white(d)}." if residual_not_white(d) else "."))
    lines += ["", "## Errors per test (held-out)", "", "| test | before | after |", "|---|---|---|"]
    for name, (b, a) in d.errors_by_test.items():
        lines.append(f"| {name} | {b:.4f} | {a:.4f} |")
    if len(d.errors_by_input) > 1:
        lines += ["", f"| {data.input_name} [{unit}] | before | after |", "|---|---|---|"]
        for lvl, (b, a) in d.errors_by_input.items():
            lines.append(f"| {lvl:g} | {b:.4f} | {a:.4f} |")
    if plots:
        lines += ["", "## Plots", ""]
        for title, p in plots.items():
            lines.append(f"![{title}]({Path(p).name})")
    lines.append("")
    return "\n".join(lines)


def residual_not_white(d) -> str:
    """``", but the residual is not white (...)"`` when the held-out residual is mostly structured
    (white-noise share below a half) while no trace variable explains it, else ``""``: a verdict
    of nothing left must not hide a residual the trace cannot see (a channel skew, a lag, a
    change of the device between tests).

    Parameters
    ----------
    d : Diagnosis
        The loop's result (its ``unexplained`` verdict and held-out ``trace_after``).
    """
    ta = getattr(d, "trace_after", None)
    if ta is None or d.unexplained or not ta.noise_fraction < 0.5:
        return ""
    return (f", but the residual is not white (white-noise share {ta.noise_fraction:.3f}, lag-1 autocorrelation "
            f"{ta.lag1:.3f}): what is left is structured in a way none of the trace's variables shows "
            "(a channel skew, a lag, a change of the device between tests)")


def write_report(diagnosis, out_dir, tests=None, keep_flagged: bool = False) -> dict[str, Path]:
    """Write the report, plots and JSON into ``out_dir`` (created); return the paths by kind.

    Parameters
    ----------
    diagnosis
        Result of :func:`damper.diagnosis.loop.diagnose`.
    out_dir
        Directory to write into (created).
    tests : sequence of DamperTest, optional
        The tests as read (fitted and ``--validate`` ones): their screening
        (:func:`damper.io.screening.screening_summary`) goes into ``report.md`` ("Screening of
        the data") and under ``screening`` in ``diagnosis.json``.
    keep_flagged : bool
        The flagged samples were kept in fit and error (``--keep-flagged``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plots = {"residual trace": plot_residual_trace(diagnosis, out / "residual_trace.png"),
             "force window": plot_force_window(diagnosis, out / "force_window.png"),
             "force histories": plot_force_histories(diagnosis, out / "force_histories.png"),
             "loops": plot_heldout_loops(diagnosis, out / "loops.png")}
    if getattr(diagnosis, "validation_histories", ()):
        plots["validation window"] = plot_validation_window(diagnosis, out / "validation_window.png")
    text = report_markdown(diagnosis, plots)
    doc = diagnosis.to_json()
    if tests is not None:
        doc["screening"] = screening_summary(tests, keep_flagged)
        text += ("\n## Screening of the data\n\n"
                 + "\n".join(f"- {line}" for line in screening_lines(tests, keep_flagged)) + "\n")
    md = atomic_write_text(out / "report.md", text)
    js = atomic_write_text(out / "diagnosis.json", json.dumps(doc, indent=2) + "\n")
    return {"report": md, "json": js, **{k.replace(" ", "_"): v for k, v in plots.items()}}
