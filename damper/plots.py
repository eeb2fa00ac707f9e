"""Hysteresis-loop figures (PNG via the Agg backend), as in the seed paper's Fig. 1-3.

:func:`plot_loops` draws force-displacement and force-velocity loops of one or more tests
(:class:`~damper.data.DamperTest` or :class:`~damper.simulate.DamperResponse`), optionally with
the force minus an elastic part :math:`\\kappa_x x` (the seed's Fig. 3). Forces in kN.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.figures import save_figure
from damper.laboratory import periodic_test
from damper.loops import last_cycles, midline_slope, plastic_branch_fit

__all__ = ["plot_loops", "plot_virtual_calibration"]


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


def plot_virtual_calibration(path, device="virtual", voltages=(0.0, 0.25, 0.5, 0.75, 1.0)) -> dict:
    """Figure of the virtual damper's calibration figures (DOMAIN.md §3), measured from loops.

    Panels: (a) 0 V, ±0.4 m at 0.8 Hz force-displacement loop with the measured average
    inclination (seed Fig. 2); (b) its force-velocity loop and the force minus
    :math:`\\kappa_x x` (Fig. 1, 3); (c) the ±0.03 m, 1 Hz, 10 s test at 0 V (Fig. 6);
    (d) force-velocity loops over the voltage range with the dry-friction force read off each.
    Returns the measured figures (``kappa_x`` [N/m], ``reduced_force_at_max_velocity`` [N],
    ``small_test_peak`` [N], ``dry_friction`` {V: N}).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt


    big = last_cycles(periodic_test(device, 0.4, 0.8, 0.0, cycles=3, sample_rate=400))
    kappa_x = midline_slope(big)
    reduced = big.force - kappa_x * big.displacement
    small = periodic_test(device, 0.03, 1.0, 0.0, cycles=10, sample_rate=200)
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    ax = axes[0, 0]
    ax.plot(big.displacement, big.force / 1e3, lw=1.2)
    grid = np.array([-0.4, 0.4])
    ax.plot(grid, kappa_x * grid / 1e3, "k--", lw=1,
            label=f"average inclination {kappa_x / 1e3:.0f} kN/m ({kappa_x * 0.4 / 1e3:.1f} kN over 0.4 m)")
    ax.set(xlabel="Displacement (m)", ylabel="Force (kN)", title="(a) 0 V, ±0.4 m, 0.8 Hz")
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[0, 1]
    ax.plot(big.velocity, big.force / 1e3, "--", lw=1.2, label="force")
    ax.plot(big.velocity, reduced / 1e3, lw=1.2, label="force $-\\ \\kappa_x x$")
    ax.set(xlabel="Velocity (m/s)", ylabel="Force (kN)", title="(b) force-velocity, 0 V")
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[1, 0]
    ax.plot(small.time, small.force / 1e3, lw=1.0, label="force (kN)")
    ax2 = ax.twinx()
    ax2.plot(small.time, small.displacement, color="C1", lw=0.8)
    ax2.set_ylabel("Displacement (m)", color="C1")
    ax.set(xlabel="Time (s)", ylabel="Force (kN)", title="(c) 0 V, ±0.03 m, 1 Hz (seed Fig. 6)")
    friction = {}
    ax = axes[1, 1]
    for v in voltages:
        loop = last_cycles(periodic_test(device, 0.4, 0.8, v, cycles=3, sample_rate=200))
        friction[float(v)] = plastic_branch_fit(loop, kappa_x)[1]
        ax.plot(loop.velocity, (loop.force - kappa_x * loop.displacement) / 1e3, lw=1.0,
                label=f"{v:g} V: dry friction {friction[float(v)] / 1e3:.0f} kN")
    ax.set(xlabel="Velocity (m/s)", ylabel="Force $-\\ \\kappa_x x$ (kN)",
           title="(d) ±0.4 m, 0.8 Hz over the voltage range")
    ax.legend(fontsize=7, loc="upper left")
    for a in axes.ravel():
        a.grid(True, alpha=0.3)
    fig.suptitle("Virtual benchmark damper: calibration figures read off laboratory loops")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    return {"kappa_x": kappa_x,
            "reduced_force_at_max_velocity": float(reduced[np.argmax(big.velocity)]),
            "small_test_peak": float(np.abs(last_cycles(small, cycles=2).force).max()),
            "dry_friction": friction}
