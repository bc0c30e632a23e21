"""A run figure laid out and drawn: data at the pixels its axes predict, the "best" legend, margins that fit the text."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from orchestrator.figure_files import Margins
from orchestrator.raster import paint
from orchestrator.raster.figure import Figure, save_figure
from orchestrator.raster.ticks import MINUS


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _inside(fig: Figure) -> None:
    width, height = fig.size
    for t in fig.texts():
        x0, y0, x1, y1 = t.box
        assert 0.0 <= x0 and x1 <= width and 0.0 <= y0 and y1 <= height, (t.text, t.box, fig.size)


def test_a_data_point_is_drawn_at_the_pixel_the_axes_predict(tmp_path):
    """4 x 3 in at 110 dpi, default margins: the axes span x 93.5-418 px and y 44-269.5 px (by hand).

    A red line at y = 2.5 of 0-10 lies at 269.5 - 0.25 x 225.5 = 213.125 px: row 213; a blue one at x = 7.5
    of 0-10 at 93.5 + 0.75 x 324.5 = 336.875 px: column 336.
    """
    fig = Figure(4.0, 3.0)
    (ax,) = fig.axes[0]
    ax.xlim, ax.ylim = (0.0, 10.0), (0.0, 10.0)
    ax.curve([0.0, 10.0], [2.5, 2.5], color="C3", width_pt=2.0)
    ax.curve([7.5, 7.5], [0.0, 10.0], color="C0", width_pt=2.0)
    path = save_figure(fig, tmp_path / "point.png")
    assert ax.box == pytest.approx((93.5, 44.0, 418.0, 269.5))
    assert float(ax.y_pixels(2.5)) == pytest.approx(213.125) and float(ax.x_pixels(7.5)) == pytest.approx(336.875)
    with Image.open(path) as png:
        pixels = np.asarray(png.convert("RGB")).astype(int)
    red, blue = np.array(paint.rgb("C3")), np.array(paint.rgb("C0"))
    assert np.abs(pixels[213, 200] - red).max() <= 8 and np.abs(pixels[213 + 4, 200] - 255).max() <= 8
    assert np.abs(pixels[150, 336] - blue).max() <= 8 and np.abs(pixels[150, 336 + 4] - 255).max() <= 8


@pytest.mark.parametrize("ys, span, place", [
    (np.full(50, 0.95), None, "lower left"),              # data across the top: the first free place below
    (np.linspace(0.0, 0.2, 50), None, "upper right"),     # data along the bottom: the first place
    (np.where(np.linspace(0, 1, 50) > 0.5, 0.95, 0.05), None, "upper left"),  # top right and bottom left taken
    (np.linspace(0.0, 0.2, 50), (0.5, 1.0), "upper left"),  # the right half shaded: kept clear where it can be
])
def test_the_best_legend_place_hides_the_fewest_points(ys, span, place):
    fig = Figure(6.0, 4.0)
    (ax,) = fig.axes[0]
    ax.xlim, ax.ylim = (0.0, 1.0), (0.0, 1.0)
    if span:
        ax.span(*span)
    ax.curve(np.linspace(0.0, 1.0, ys.size), ys, label="data")
    ax.set_legend("best")
    fig.lay_out()
    assert ax.legend.place == place
    points = ax.drawn_points()[0]
    x0, y0, x1, y1 = ax.legend.box
    assert not ((points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)).any()


def test_a_legend_that_would_hide_data_everywhere_inside_goes_beside_the_axes():
    """A fast sine fills the axes: every place inside hides some of it; the legend goes beside, the axes narrower."""
    fig = Figure(6.0, 4.0)
    (ax,) = fig.axes[0]
    x = np.linspace(0.0, 1.0, 2001)
    ax.curve(x, np.sin(2 * np.pi * 40 * x), label="40 cycles")
    ax.set_legend("best")
    fig.lay_out()
    assert ax.legend.place == "beside" and ax.legend.hidden == 0
    assert ax.legend.box[0] > ax.box[2] and ax.legend.box[2] <= fig.size[0]
    assert fig.used_margins.right == pytest.approx(0.2 + ax.legend.extent()[0] / 110.0 + 0.05)


def test_a_legend_beside_the_axes_widens_the_right_margin_to_its_width():
    fig = Figure(8.0, 3.0, margins=Margins())
    (ax,) = fig.axes[0]
    ax.curve([0.0, 1.0], [0.0, 1.0], label="a rather long legend entry [kN]")
    ax.set_legend("beside", 7.0)
    fig.lay_out()
    width = ax.legend.extent()[0]
    assert fig.used_margins.right == pytest.approx(0.2 + width / 110.0 + 0.05)
    assert ax.legend.box[0] > ax.box[2] and ax.legend.box[2] <= fig.size[0] - 0.05 * 110.0 + 0.5
    _inside(fig)


def test_margins_too_small_for_the_text_are_widened():
    """Tick labels of 7 characters ('−1499.5'), a y label, an offset text and titles in margins of a tenth of an inch."""
    fig = Figure(6.0, 4.0, rows=2, margins=Margins(left=0.1, right=0.1, top=0.1, bottom=0.1, hspace=0.05))
    top, bottom = fig.axes[0][0], fig.axes[1][0]
    top.curve([0.0, 1.0], [-1499.8, -1498.2])
    top.ylim = (-1499.9, -1498.1)  # 4 intervals fit: steps of 0.5, no offset (it would save 3 digits)
    top.ylabel, top.xlabel = "torque [kN m]", "time [s]"
    top.set_title("shaft 1: whole run", "left", 10.0)
    bottom.curve([0.0, 1.0], [100000.1, 100001.9])  # labels 0.0 ... 2.0 with '+1e5' above the axis
    bottom.ylabel, bottom.xlabel = "speed [rpm]", "time [s]"
    bottom.set_title("shaft 2: whole run", "left", 10.0)
    fig.lay_out()
    assert [t.text for t in top.texts if t.role == "ytick"] == [f"{MINUS}1499.5", f"{MINUS}1499.0", f"{MINUS}1498.5"]
    (offset,) = [t for t in bottom.texts if t.role == "offset"]
    assert offset.text == "+1e5"
    m = fig.used_margins
    assert m.left > 0.1 and m.top > 0.1 and m.bottom > 0.1 and m.hspace > 0.05
    _inside(fig)
    texts = fig.texts()
    for i, a in enumerate(texts):
        for b in texts[i + 1:]:
            assert not _overlap(a.box, b.box), (a.text, b.text)
    for ax in (top, bottom):
        (ylabel,) = [t.box for t in ax.texts if t.role == "ylabel"]
        assert all(ylabel[2] <= t.box[0] for t in ax.texts if t.role == "ytick")


def test_an_x_offset_text_goes_right_below_the_tick_labels_and_the_x_label_clears_it():
    """Times 100000.1-100001.9 s: labels 0.0 ... 2.0 (not 100000.0 ...), '+1e5' at the right, the long x label below it."""
    fig = Figure(6.0, 3.0)
    (ax,) = fig.axes[0]
    ax.curve([100000.1, 100001.9], [0.0, 1.0])
    ax.xlim = (100000.1, 100001.9)
    ax.xlabel = "time since the start of the measurement campaign on the test bench [s]"
    ax.ylabel = "force [kN]"
    fig.lay_out()
    labels = [t.text for t in ax.texts if t.role == "xtick"]
    assert labels[0] in ("0.2", "0.5") and labels[-1] in ("1.5", "1.8")
    (offset,) = [t for t in ax.texts if t.role == "offset"]
    (xlabel,) = [t for t in ax.texts if t.role == "xlabel"]
    ticks_bottom = max(t.box[3] for t in ax.texts if t.role == "xtick")
    assert offset.text == "+1e5" and offset.box[2] == pytest.approx(ax.box[2]) and offset.box[1] > ticks_bottom
    assert xlabel.box[2] > offset.box[0] and xlabel.box[1] >= offset.box[3]  # as wide as to reach it: below it
    _inside(fig)


def test_shared_x_axes_share_their_limits_and_only_the_bottom_row_is_labelled():
    fig = Figure(6.0, 4.0, rows=2, sharex="all")
    (top,), (bottom,) = fig.axes
    top.curve([0.0, 3.0], [0.0, 1.0])
    bottom.curve([0.0, 3.0], [0.0, 1.0])
    bottom.xlim = (0.0, 2.0)
    fig.lay_out()
    assert top.xlim == bottom.xlim == (0.0, 2.0)
    assert not [t for t in top.texts if t.role == "xtick"] and [t for t in bottom.texts if t.role == "xtick"]
    top.xlim = (0.0, 1.0)
    with pytest.raises(ValueError, match="different limits"):
        fig.lay_out()


@pytest.mark.parametrize("build, match", [
    (lambda ax: setattr(ax, "yscale", "log") or setattr(ax, "ylim", (0.0, 1.0)), "log axis needs positive limits"),
    (lambda ax: ax.set_legend("upper left"), "'best' or 'beside'"),
])
def test_what_a_figure_cannot_draw_is_refused(build, match):
    fig = Figure(4.0, 3.0)
    (ax,) = fig.axes[0]
    ax.curve([0.0, 1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match=match):
        build(ax)
        fig.lay_out()


def test_a_figure_without_room_for_its_axes_is_refused():
    with pytest.raises(ValueError, match="no room"):
        Figure(1.0, 1.0, rows=3).lay_out()
