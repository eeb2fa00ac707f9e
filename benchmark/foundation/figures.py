"""Saving figures: one place for the project's rule that a plot file is written atomically.

Every plotting module (building, records, dampers, identification, diagnosis, controllers,
benchmarks) draws with matplotlib and hands the figure to :func:`save_figure`, which picks the
format from the extension, writes to a temporary file renamed on success
(:func:`benchmark.foundation.atomic.atomic_path`) and releases the figure. Library code never calls
``plt.show()``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import InputError

__all__ = ["save_figure", "FIGURE_FORMATS", "display_envelope", "ENVELOPE_BINS", "fixed_layout"]

#: Extensions a figure may be written to.
FIGURE_FORMATS = (".png", ".pdf", ".svg")


def save_figure(fig, path: str | os.PathLike, dpi: int = 120) -> Path:
    """Write ``fig`` to ``path`` atomically (format from the extension) and release it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure made with pyplot or directly with ``Figure()`` (an Agg canvas is attached if it
        has none).
    path : path-like
        Destination (``.png``, ``.pdf`` or ``.svg``); the parent directory is created.
    dpi : int
        Resolution of raster output.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        For an extension matplotlib should not be asked to guess.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FIGURE_FORMATS:
        raise InputError(f"plot file {path}: unsupported extension {path.suffix!r}; "
                         f"expected {', '.join(FIGURE_FORMATS)}")
    if fig.canvas is None or type(fig.canvas).__name__ == "FigureCanvasBase":
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    # tight_layout leaves a placeholder layout engine behind (matplotlib 3.6+), and savefig then
    # draws the whole figure once more before drawing it for the file: with no engine the file is
    # byte for byte the same and written 15 % faster (1 CPU-s of the main job's figures)
    engine = fig.get_layout_engine()
    if engine is not None and type(engine).__name__ == "PlaceHolderLayoutEngine":
        fig.set_layout_engine(None)
    # zlib's fastest level: a PNG 7 % larger, encoded in two thirds of the time (42 -> 28 ms for a
    # 1440 x 1200 history, measured 2026-11-26); the pixels are the same
    extra = {"pil_kwargs": {"compress_level": 1}} if suffix == ".png" else {}
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix.lstrip("."), **extra)
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:  # release a pyplot-managed figure (a no-op for the others)
        pyplot.close(fig)
    return path


#: Columns of :func:`display_envelope`: more than the pixels of the widest axes the project draws
#: (a 10-inch figure at 120 dpi is 1200 pixels wide).
ENVELOPE_BINS = 1500


def display_envelope(t, y, bins: int = ENVELOPE_BINS) -> tuple[np.ndarray, np.ndarray]:
    """The samples of a long history that a line plot of it shows: per column, its lowest and
    its highest sample, in time order (with the first and the last sample).

    A line through these samples covers the same pixels as the whole history at a resolution of
    ``bins`` columns or fewer, so a plot looks the same and is drawn 2-3 times faster: an
    earthquake's damper force or a switching voltage is 6 000 samples or more in 1 100 pixels,
    and matplotlib lays out and rasterizes every sample (``tight_layout`` draws the figure once
    more). Peaks are kept exactly; this is only for display, never for a computed value.
    Histories of at most ``2 * bins`` samples (nothing to gain), or with a NaN (a gap the line
    should show), are returned unchanged.

    Parameters
    ----------
    t : array_like (n,)
        Abscissa (time), in plotting order.
    y : array_like (n,)
        Ordinate.
    bins : int
        Columns of the envelope.

    Returns
    -------
    t, y : ndarray
        The kept samples.
    """
    t = np.asarray(t)
    y = np.asarray(y)
    n = y.size
    k = n // bins
    if n <= 2 * bins or t.shape != y.shape or y.ndim != 1 or not np.all(np.isfinite(y)):
        return t, y
    m = n // k * k
    chunks = y[:m].reshape(-1, k)
    start = np.arange(0, m, k)
    keep = np.concatenate(([0], start + np.argmin(chunks, axis=1), start + np.argmax(chunks, axis=1),
                           np.arange(m, n), [n - 1]))
    keep = np.unique(keep)  # sorted: the line follows time
    return t[keep], y[keep]


def fixed_layout(fig, left: float, right: float, top: float, bottom: float, hgap: float = 0.0,
                 wgap: float = 0.0) -> None:
    """Place a figure's grid of axes with margins and gaps given in inches (no ``tight_layout``).

    ``tight_layout`` measures every tick label and title to place the axes, which costs a third
    of drawing a large figure (0.1 s of a three-panel history, 0.25 s of the nine-panel criteria
    figure, measured 2026-11-26). Figures drawn many times with the same labels (one per record
    and orientation) use fixed margins instead, sized for their longest labels.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure whose axes come from one ``subplots`` grid.
    left, right, top, bottom : float
        Margins [in] between the figure's edge and the grid (room for tick labels, axis labels,
        the suptitle).
    hgap, wgap : float
        Gaps [in] between rows and between columns of axes (room for titles and tick labels).
    """
    gs = fig.axes[0].get_subplotspec().get_gridspec()
    nrows, ncols = gs.get_geometry()
    width, height = fig.get_size_inches()
    axes_h = (height - top - bottom - (nrows - 1) * hgap) / nrows
    axes_w = (width - left - right - (ncols - 1) * wgap) / ncols
    if not (axes_h > 0 and axes_w > 0):
        raise ValueError(f"fixed_layout: margins and gaps leave no room for the axes in a "
                         f"{width:g} x {height:g} in figure")
    fig.subplots_adjust(left=left / width, right=1.0 - right / width, top=1.0 - top / height,
                        bottom=bottom / height, hspace=hgap / axes_h, wspace=wgap / axes_w)

