"""Figures of a controller comparison (PNG, matplotlib Agg backend).

* ``J_by_record.png``: J1–J9 per record and orientation, one marker series per controller;
* ``J_summary.png``: mean (bar) and max (tick) of each J over records, per controller;
* ``histories_<record>_<orientation>.png``: base-displacement resultant (uncontrolled and
  every controller), total device-force resultant and mean device voltage over time.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from benchmark.foundation.figures import save_figure

__all__ = ["plot_all", "plot_J_by_record", "plot_J_summary", "plot_histories"]

J_NAMES = tuple(f"J{i}" for i in range(1, 10))


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    return save_figure(fig, path, dpi=110)


def plot_J_by_record(result: Any, path: Path) -> Path:
    plt = _pyplot()
    cases = result.cases
    labels = [f"{r}\n{o}" for r, o in cases]
    fig, axes = plt.subplots(3, 3, figsize=(15, 10), sharex=True)
    for ax, j in zip(axes.ravel(), J_NAMES):
        for k, name in enumerate(result.controllers):
            values = []
            for case in cases:
                run = next((r for r in result.runs if (r.record, r.orientation) == case and r.controller == name), None)
                v = None if run is None else run.J.get(j)
                values.append(np.nan if v is None else v)
            ax.plot(np.arange(len(cases)) + 0.06 * (k - len(result.controllers) / 2), values, "o-", ms=4,
                    lw=0.8, label=name)
        ax.axhline(1.0, color="k", lw=0.6, ls=":")
        ax.set_title(j)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xticks(np.arange(len(cases)))
        ax.set_xticklabels(labels, rotation=90, fontsize=7)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Evaluation criteria per record (ratio to the uncontrolled building; 1 = no change)")
    fig.tight_layout()
    return _save(fig, path)


def plot_J_summary(result: Any, path: Path) -> Path:
    plt = _pyplot()
    summary = result.summary()
    names = list(summary)
    fig, ax = plt.subplots(figsize=(12, 5))
    width = 0.8 / max(1, len(names))
    x = np.arange(len(J_NAMES))
    for k, name in enumerate(names):
        mean = [np.nan if summary[name][j]["mean"] is None else summary[name][j]["mean"] for j in J_NAMES]
        mx = [np.nan if summary[name][j]["max"] is None else summary[name][j]["max"] for j in J_NAMES]
        pos = x + (k - (len(names) - 1) / 2) * width
        ax.bar(pos, mean, width, label=name)
        ax.plot(pos, mx, "k_", ms=10)
    ax.axhline(1.0, color="k", lw=0.6, ls=":")
    ax.set_xticks(x)
    ax.set_xticklabels(J_NAMES)
    ax.set_ylabel("ratio to uncontrolled (bar: mean, tick: max over records)")
    ax.legend(fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    return _save(fig, path)


def plot_histories(result: Any, record: str, orientation: str, path: Path) -> Path:
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
            axes[1].plot(h["t"], np.hypot(*h["device_force_total"].T) / 1e3, lw=0.8, label=run.controller)
        if "voltage" in h:
            axes[2].plot(h["t"], h["voltage"].mean(axis=1), lw=0.8, label=run.controller)
    axes[0].set_ylabel("base displacement |u_b| [m]")
    axes[1].set_ylabel("total device force |F| [kN]")
    axes[2].set_ylabel("mean device voltage [V]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"{record} {orientation}")
    fig.tight_layout()
    return _save(fig, path)


def plot_all(result: Any, directory: Path) -> list[Path]:
    """All figures of the comparison into ``directory`` (created)."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = [plot_J_by_record(result, directory / "J_by_record.png"),
             plot_J_summary(result, directory / "J_summary.png")]
    for record, orientation in result.cases:
        paths.append(plot_histories(result, record, orientation,
                                    directory / f"histories_{record}_{orientation}.png"))
    return paths
