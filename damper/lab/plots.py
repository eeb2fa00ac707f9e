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

__all__ = ["plot_loops", "draw_loops"]


def draw_loops(axes, x, xdot, curves, x_labels: tuple[str, str] = ("Displacement (m)", "Velocity (m/s)"),
               force_label: str = "Force (kN)") -> None:
    """Draw force against displacement (``axes[0]``) and against velocity (``axes[1]``).

    The one loop drawing of the project: :func:`plot_loops` (tests and responses), the
    identification's Fig. 1 (:func:`damper.identification.plots.plot_identified_loops`) and the
    residual loop's held-out loops (:func:`damper.diagnosis.report.plot_heldout_loops`) all draw
    through it, each in its own units.

    Parameters
    ----------
    axes : pair of matplotlib Axes
        Force-displacement and force-velocity panels.
    x : ndarray
        Displacement, in the unit of ``x_labels[0]``.
    xdot : ndarray
        Velocity, in the unit of ``x_labels[1]``.
    curves : sequence of (ndarray, str, dict)
        ``(force, legend label, matplotlib line keywords)`` per curve, force in the unit of
        ``force_label``.
    x_labels : tuple of str, optional
        Axis labels of the two panels.
    force_label : str, optional
        Label of the force axis.
    """
    for ax, z, label in zip(axes, (x, xdot), x_labels):
        for force, name, style in curves:
            ax.plot(z, force, label=name, **style)
        ax.set_xlabel(label)
        ax.set_ylabel(force_label)
        ax.grid(True, alpha=0.3)


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
        draw_loops(axes[:2], x, xd, [(f / 1e3, label, {"ls": style, "lw": 1.2})])
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
    axes[0].set_title("Force-displacement")
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

