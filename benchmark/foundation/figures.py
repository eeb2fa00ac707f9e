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

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import InputError

__all__ = ["save_figure", "FIGURE_FORMATS"]

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
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix.lstrip("."))
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:  # release a pyplot-managed figure (a no-op for the others)
        pyplot.close(fig)
    return path
