"""Figures of a controller comparison (PNG, matplotlib Agg backend).

* ``J_by_record.png``: J1–J9 per record and orientation, one marker series per controller;
* ``J_summary.png``: mean (bar) and max (tick) of each J over records, per controller;

Both carry the key of the J's (name, normalisation, formula, source) from
:mod:`benchmark.simulator.criteria`; only the ratios to the uncontrolled run (J1–J5, J7, J8) are labelled
and marked (dotted line at 1) as such: J6 and J9 are fractions of the controlled run's own base
shear and input energy.
* ``histories_<record>_<orientation>.png``: base-displacement resultant (uncontrolled and
  every controller), total device-force resultant and the device voltage over time, as a 1 s
  moving mean over the devices (a bang-bang law switches tens of times per second: the moving
  mean is the maximum voltage times the fraction of time on, the duty cycle).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from benchmark.foundation.figures import fixed_layout, save_figure

__all__ = ["plot_all", "plot_J_by_record", "plot_J_summary", "plot_histories"]

from benchmark.simulator.criteria import J_NAMES, axis_label, is_ratio, key_lines
from benchmark.foundation.display_units import axis_label as unit_label
from benchmark.foundation.display_units import to_display
from benchmark.applications.damper_choice import command_unit


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: window [s] of the voltage panel's moving mean (duty-cycle view of bang-bang voltages)
VOLTAGE_WINDOW = 1.0


def moving_mean(t: np.ndarray, values: np.ndarray, window: float) -> np.ndarray:
    """Centred moving mean of ``values`` over ``window`` seconds (``t`` uniformly sampled);
    the ends use the samples there are."""
    values = np.asarray(values, dtype=float)
    if values.size < 2:
        return values.copy()
    n = max(1, int(round(window / float(t[1] - t[0]))))
    kernel = np.ones(n)
    total = np.convolve(values, kernel, mode="same")
    count = np.convolve(np.ones_like(values), kernel, mode="same")
    return total / count


def _key(fig, fontsize: float = 9.0) -> None:
    """The key of the J's under the axes (the caller leaves room at the bottom)."""
    fig.text(0.01, 0.005, "\n".join(key_lines(formulas=False)), ha="left", va="bottom", fontsize=fontsize,
             family="monospace")


def _save(fig, path: Path) -> Path:
    return save_figure(fig, path, dpi=110)


def plot_J_by_record(result: Any, path: Path) -> Path:
    """One panel per criterion J1–J9: its value for every record and orientation, bars by controller.

    Parameters
    ----------
    result : ComparisonResult
        The comparison's result.
    path : Path
        Image file to write (format from the suffix).
    """
    plt = _pyplot()
    cases = result.cases
    labels = [f"{r}\n{o}" for r, o in cases]
    fig, axes = plt.subplots(3, 3, figsize=(15, 12.5), sharex=True)
    for ax, j in zip(axes.ravel(), J_NAMES):
        for k, name in enumerate(result.controllers):
            values = []
            for case in cases:
                run = next((r for r in result.runs if (r.record, r.orientation) == case and r.controller == name), None)
                v = None if run is None else run.J.get(j)
                values.append(np.nan if v is None else v)
            ax.plot(np.arange(len(cases)) + 0.06 * (k - len(result.controllers) / 2), values, "o-", ms=4,
                    lw=0.8, label=name)
        if is_ratio(j):
            ax.axhline(1.0, color="k", lw=0.6, ls=":")
        ax.set_title(j)
        ax.set_ylabel(axis_label(j), fontsize=9)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xticks(np.arange(len(cases)))
        ax.set_xticklabels(labels, rotation=90, fontsize=9)
    axes[0, 0].legend(fontsize=9)
    fig.suptitle("Evaluation criteria per record (key below)")
    # fixed margins (tight_layout took a third of this figure's cost); the key's 2 in at the bottom
    fixed_layout(fig, left=0.8, right=0.15, top=0.8, bottom=2.0 + 0.85, hgap=0.4, wgap=0.85)
    _key(fig)
    return _save(fig, path)


def plot_J_summary(result: Any, path: Path) -> Path:
    """Every criterion by controller: mean over the records (bar) and maximum (tick).

    Parameters
    ----------
    result : ComparisonResult
        The comparison's result.
    path : Path
        Image file to write (format from the suffix).
    """
    plt = _pyplot()
    summary = result.summary()
    names = list(summary)
    fig, ax = plt.subplots(figsize=(12, 7.5))
    width = 0.8 / max(1, len(names))
    x = np.arange(len(J_NAMES))
    for k, name in enumerate(names):
        mean = [np.nan if summary[name][j]["mean"] is None else summary[name][j]["mean"] for j in J_NAMES]
        mx = [np.nan if summary[name][j]["max"] is None else summary[name][j]["max"] for j in J_NAMES]
        pos = x + (k - (len(names) - 1) / 2) * width
        bars = ax.bar(pos, mean, width, label=name)
        for bar, j in zip(bars, J_NAMES):
            if not is_ratio(j):   # J6, J9: fractions of the controlled run itself
                bar.set_hatch("//")
        ax.plot(pos, mx, "k_", ms=10)
    # the dotted "no change" line belongs to the ratios only
    ratio_x = [k for k, j in enumerate(J_NAMES) if is_ratio(j)]
    for k in ratio_x:
        ax.plot([k - 0.45, k + 0.45], [1.0, 1.0], color="k", lw=0.6, ls=":")
    ax.set_xticks(x)
    ax.set_xticklabels(J_NAMES)
    ax.set_ylabel("value of the criterion (bar: mean, tick: max over records)")
    ax.set_title("J1–J5, J7, J8: ratio to uncontrolled (dotted: 1 = no change); "
                 "J6, J9 (hatched): fractions of the controlled run", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout(rect=(0, 0.23, 1, 1))
    _key(fig)
    return _save(fig, path)


def plot_histories(result: Any, record: str, orientation: str, path: Path) -> Path:
    """Base displacement, total device force and mean voltage against time, one line per controller.

    Parameters
    ----------
    result : ComparisonResult
        The comparison's result (with down-sampled histories).
    record : str
        Record name.
    orientation : str
        ``FN-x`` or ``FP-x``.
    path : Path
        Image file to write (format from the suffix).
    """
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(12, 10), sharex=True)
    ref = result.reference_histories.get((record, orientation))
    if ref:
        axes[0].plot(ref["t"], np.hypot(*ref["base_displacement"].T), color="0.6", lw=1.0, label="uncontrolled")
    for run in result.runs:
        if (run.record, run.orientation) != (record, orientation):
            continue
        h = run.histories
        axes[0].plot(h["t"], np.hypot(*h["base_displacement"].T), lw=0.8, label=run.controller)
        if "device_force_total" in h:
            axes[1].plot(h["t"], to_display(np.hypot(*h["device_force_total"].T), "force"), lw=0.8,
                         label=run.controller)
        if "voltage" in h:
            axes[2].plot(h["t"], moving_mean(h["t"], h["voltage"].mean(axis=1), VOLTAGE_WINDOW), lw=1.0,
                         label=run.controller)
    axes[0].set_ylabel(unit_label("base displacement |u_b|", "displacement"))
    axes[1].set_ylabel(unit_label("total device force |F|", "force"))
    unit = command_unit(result.settings.get("damper"))
    axes[2].set_ylabel(f"device command, {VOLTAGE_WINDOW:g} s moving mean [{unit}]")
    axes[2].set_title("bang-bang laws switch tens of times per second: the moving mean is "
                      "V_max × the fraction of time on (duty cycle), mean over devices", fontsize=8)
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"{record} {orientation}")
    fixed_layout(fig, left=0.95, right=0.15, top=0.55, bottom=0.6, hgap=0.45)  # one per record: no tight_layout
    return _save(fig, path)


def plot_all(result: Any, directory: Path, part: tuple[int, int] = (0, 1)) -> list[Path]:
    """All figures of the comparison into ``directory`` (created).

    ``part = (i, n)`` draws only the i-th of n interleaved shares of the figures (the summaries
    belong to share 0), so that n processes can draw them side by side.

    Parameters
    ----------
    result : Any
        The comparison's result (:class:`benchmark.applications.comparison.ComparisonResult`).
    directory : Path
        Directory to draw into (created).
    part : tuple[int, int], optional
        ``(index, count)``: draw only this share of the per-record figures (for parallel drawing); ``(0, 1)``:
        all.
    """
    i, n = part
    directory.mkdir(parents=True, exist_ok=True)
    paths = [plot_J_by_record(result, directory / "J_by_record.png"),
             plot_J_summary(result, directory / "J_summary.png")] if i == 0 else []
    for k, (record, orientation) in enumerate(result.cases):
        if k % n == (n - 1 - i):  # share 0, which has the summaries, takes the smaller share
            paths.append(plot_histories(result, record, orientation,
                                        directory / f"histories_{record}_{orientation}.png"))
    return paths
