"""Figures of records: time histories and response spectra (PNG/PDF, Agg canvas, never a window).

Synthetic records are marked "SYNTHETIC" in the title of every figure that shows them.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

from matplotlib.figure import Figure

from benchmark.foundation.errors import InputError
from benchmark.foundation.figures import save_figure
from records.record import STANDARD_GRAVITY, Record
from records.spectra import ResponseSpectrum, default_periods, response_spectrum

__all__ = ["plot_record", "plot_spectra_overview"]



def _title(record: Record) -> str:
    tag = "SYNTHETIC " if record.synthetic else ""
    event = record.metadata.get("event")
    orientation = record.metadata.get("orientation")
    extra = ", ".join(str(x) for x in (event, orientation) if x)
    return f"{tag}{record.name}" + (f" ({extra})" if extra else "")


def _legend(record: Record, c: int) -> str:
    if record.n_components == 2:
        return f"{'xy'[c]}: {record.labels[c]}"
    return record.labels[c]


def _save(fig: Figure, path: str | os.PathLike) -> Path:
    return save_figure(fig, path, dpi=120)


def plot_record(record: Record, path: str | os.PathLike, spectrum: ResponseSpectrum | None = None,
                damping: float = 0.05) -> Path:
    """Plot acceleration [g], velocity [cm/s] and displacement [cm] histories and the response spectrum.

    Parameters
    ----------
    record : Record
        The record (all components drawn, labelled).
    path : path-like
        Output file (.png, .pdf or .svg), written atomically.
    spectrum : ResponseSpectrum, optional
        Precomputed spectrum (default: 5 %-damped on :func:`records.spectra.default_periods`).
    damping : float
        Damping ratio if the spectrum is computed here.

    Returns
    -------
    Path
        The file written.
    """
    spec = spectrum if spectrum is not None else response_spectrum(record, periods=default_periods(), damping=damping)
    t = record.time
    histories = (
        (record.acceleration / STANDARD_GRAVITY, "acceleration [g]"),
        (100 * record.velocity(), "velocity [cm/s]"),
        (100 * record.displacement(), "displacement [cm]"),
    )
    fig = Figure(figsize=(11, 8))  # fixed margins: constrained layout costs more than the drawing
    grid = fig.add_gridspec(3, 2, width_ratios=(1.6, 1), left=0.07, right=0.98, bottom=0.07, top=0.93,
                            wspace=0.25, hspace=0.3)
    for row, (values, ylabel) in enumerate(histories):
        ax = fig.add_subplot(grid[row, 0])
        for c, label in enumerate(record.labels):
            ax.plot(t, values[:, c], lw=0.7, label=_legend(record, c), alpha=0.85)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.set_xlim(t[0], t[-1])
        if row == 0:
            ax.legend(loc="upper right", fontsize=8)
        if row == 2:
            ax.set_xlabel("time [s]")
    ax = fig.add_subplot(grid[0:2, 1])
    for c in range(record.n_components):
        ax.plot(spec.periods, spec.psa[:, c] / STANDARD_GRAVITY, label=_legend(record, c))
    ax.set_xscale("log")
    ax.set_xlabel("period [s]")
    ax.set_ylabel(f"pseudo-acceleration, {100 * spec.damping:g} % damping [g]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax = fig.add_subplot(grid[2, 1])
    for c in range(record.n_components):
        ax.plot(spec.periods, 100 * spec.sd[:, c], label=_legend(record, c))
    ax.set_xscale("log")
    ax.set_xlabel("period [s]")
    ax.set_ylabel("spectral displacement [cm]")
    ax.grid(alpha=0.3, which="both")
    pga = ", ".join(f"{p:.3f}" for p in record.pga_g)
    pgv = ", ".join(f"{100 * v:.1f}" for v in record.pgv)
    fig.suptitle(f"{_title(record)} — dt {record.dt:g} s, {record.duration:g} s, PGA {pga} g, PGV {pgv} cm/s",
                 fontsize=10)
    return _save(fig, path)


def plot_spectra_overview(records: Sequence[Record], path: str | os.PathLike, damping: float = 0.05,
                          title: str | None = None) -> Path:
    """One panel per component index (x, y): the pseudo-acceleration spectra of several records.

    Parameters
    ----------
    records : sequence of Record
        The records (synthetic ones are named so in the title).
    path : path-like
        Output file (.png, .pdf or .svg), written atomically.
    damping : float
        Damping ratio.
    title : str, optional
        Figure title (default says whether the records are synthetic).

    Returns
    -------
    Path
        The file written.
    """
    if not records:
        raise InputError("plot_spectra_overview: no records to plot")
    n_panels = max(r.n_components for r in records)
    periods = default_periods()
    fig = Figure(figsize=(5.5 * n_panels, 4.5))
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.12, top=0.88, wspace=0.25)
    axes = [fig.add_subplot(1, n_panels, i + 1) for i in range(n_panels)]
    for rec in records:
        spec = response_spectrum(rec, periods=periods, damping=damping)
        for c in range(rec.n_components):
            axes[c].plot(periods, spec.psa[:, c] / STANDARD_GRAVITY, label=rec.name, lw=1.0)
    for i, ax in enumerate(axes):
        ax.set_xscale("log")
        ax.set_xlabel("period [s]")
        ax.set_ylabel(f"pseudo-acceleration, {100 * damping:g} % damping [g]")
        ax.set_title(("component on x", "component on y")[i] if i < 2 else f"component {i + 1}")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    any_synthetic = any(r.synthetic for r in records)
    fig.suptitle(title or ("SYNTHETIC records" if all(r.synthetic for r in records)
                           else "records" + (" (some SYNTHETIC)" if any_synthetic else "")))
    return _save(fig, path)

