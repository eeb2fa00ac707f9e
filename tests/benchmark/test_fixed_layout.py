"""benchmark.foundation.figures.fixed_layout: margins and gaps in inches, no tight_layout."""

from __future__ import annotations

import pytest
from matplotlib.figure import Figure

from benchmark.foundation.figures import fixed_layout


def test_margins_and_gaps_are_the_inches_asked_for():
    fig = Figure(figsize=(12, 10))
    axes = fig.subplots(3, 2)
    fixed_layout(fig, left=0.9, right=0.2, top=0.6, bottom=0.5, hgap=0.4, wgap=0.7)
    dpi = fig.dpi
    boxes = [[ax.get_position().transformed(fig.transFigure) for ax in row] for row in axes]
    inch = lambda pixels: pixels / dpi  # noqa: E731
    assert inch(boxes[0][0].x0) == pytest.approx(0.9)
    assert inch(fig.bbox.x1 - boxes[0][1].x1) == pytest.approx(0.2)
    assert inch(fig.bbox.y1 - boxes[0][0].y1) == pytest.approx(0.6)
    assert inch(boxes[2][0].y0) == pytest.approx(0.5)
    assert inch(boxes[0][0].y0 - boxes[1][0].y1) == pytest.approx(0.4)
    assert inch(boxes[0][1].x0 - boxes[0][0].x1) == pytest.approx(0.7)


def test_margins_that_leave_no_room_are_refused():
    fig = Figure(figsize=(4, 3))
    fig.subplots(2, 1)
    with pytest.raises(ValueError, match="no room"):
        fixed_layout(fig, left=1, right=1, top=1, bottom=1, hgap=1.5)


def test_save_figure_after_tight_layout_writes_the_same_file_without_the_extra_draw(tmp_path):
    """tight_layout leaves a placeholder layout engine, for which savefig draws the figure twice;
    save_figure drops it, and the file is byte for byte the one savefig writes with it."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from benchmark.foundation.figures import save_figure

    def figure():
        fig = Figure(figsize=(6, 4))
        FigureCanvasAgg(fig)
        ax = fig.subplots()
        ax.plot(np.sin(np.linspace(0, 9, 400)))
        ax.set_title("title")
        fig.tight_layout()
        return fig

    draws = []
    fig = figure()
    original = fig.draw
    fig.draw = lambda renderer: (draws.append(1), original(renderer))[1]
    save_figure(fig, tmp_path / "a.png")
    assert len(draws) == 1
    reference = figure()
    reference.savefig(tmp_path / "b.png", dpi=120, format="png", pil_kwargs={"compress_level": 1})
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    from matplotlib.image import imread
    assert np.array_equal(imread(tmp_path / "a.png"), imread(_default_png(figure(), tmp_path / "c.png")))


def _default_png(fig, path):
    fig.savefig(path, dpi=120, format="png")  # zlib's default level: the same pixels
    return path
