"""Hysteresis-loop figures (PNG via the Agg backend), as in the seed paper's Fig. 1-3.

:func:`plot_loops` draws force-displacement and force-velocity loops of one or more tests
(:class:`~damper.io.data.DamperTest` or :class:`~damper.models.response.DamperResponse`), optionally with
the force minus an elastic part :math:`\\kappa_x x` (the seed's Fig. 3). Forces in kN.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.figures import save_figure

__all__ = ["plot_loops"]


def _series(item):
    if hasattr(item, "time"):  # DamperTest
        return item.displacement, item.velocity, item.force, item.name
    if hasattr(item, "t"):  # DamperResponse
        return item.displacement, item.velocity, item.force, item.model.name
    raise InputError(f"plot_loops: expected DamperTest or DamperResponse, got {type(item).__name__}")


def plot_loops(items, path, labels: Sequence[str] | None = None, title: str | None = None,
               kappa_x: float | None = None, styles: Sequence[str] | None = None) -> Path:
    """Save force-displacement and force-velocity loops to ``path`` (PNG/PDF), atomically.

    Parameters
    ----------
    items : DamperTest or DamperResponse, or a sequence of them
        Tests to draw (e.g. the last cycles of a periodic test).
    path : path-like
        Output file.
    labels : sequence of str, optional
        Legend labels (default: the tests' names).
    title : str, optional
        Figure title.
    kappa_x : float, optional
        Elastic coefficient [N/m]: adds a third panel with :math:`F - \\kappa_x x` against
        velocity (the seed's Fig. 3) and the mid-line :math:`\\kappa_x x` on the first panel.
    styles : sequence of str, optional
        Matplotlib line styles per item.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    if not isinstance(items, (list, tuple)):
        items = [items]
    if not items:
        raise InputError("plot_loops: nothing to plot")
    series = [_series(item) for item in items]
    labels = list(labels) if labels is not None else [s[3] for s in series]
    styles = list(styles) if styles is not None else ["-"] * len(series)
    n_panels = 3 if kappa_x is not None else 2
    fig, axes = plt.subplots(1, n_panels, figsize=(5.0 * n_panels, 4.2))
    for (x, xd, f, _), label, style in zip(series, labels, styles):
        axes[0].plot(x, f / 1e3, style, lw=1.2, label=label)
        axes[1].plot(xd, f / 1e3, style, lw=1.2, label=label)
        if kappa_x is not None:
            axes[2].plot(xd, (f - kappa_x * x) / 1e3, style, lw=1.2, label=label)
    if kappa_x is not None:
        x_all = np.concatenate([s[0] for s in series])
        grid = np.linspace(x_all.min(), x_all.max(), 2)
        axes[0].plot(grid, kappa_x * grid / 1e3, "k--", lw=0.8,
                     label=f"$\\kappa_x x$, {kappa_x / 1e3:.0f} kN/m")
        axes[2].set_xlabel("Velocity (m/s)")
        axes[2].set_ylabel("Force $-\\ \\kappa_x x$ (kN)")
        axes[2].set_title("Force minus elastic part")
    axes[0].set_xlabel("Displacement (m)")
    axes[0].set_ylabel("Force (kN)")
    axes[0].set_title("Force-displacement")
    axes[1].set_xlabel("Velocity (m/s)")
    axes[1].set_ylabel("Force (kN)")
    axes[1].set_title("Force-velocity")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.xaxis.set_major_locator(MaxNLocator(6))  # small strokes: long tick labels overlap
        ax.axhline(0.0, color="0.6", lw=0.5)
    axes[0].legend(fontsize=8, loc="upper left")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)

