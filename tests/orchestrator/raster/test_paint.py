"""Pixels of the run figures: colours, exact coverage of boxes, snapped lines, clipping and dashes by hand."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from orchestrator.raster import paint


@pytest.mark.parametrize("color, expected", [("C0", (31, 119, 180)), ("C3", (214, 39, 40)), ("tab:blue", (31, 119, 180)),
                                             ("0.93", (237, 237, 237)), ("#b0b0b0", (176, 176, 176)),
                                             ("k", (0, 0, 0)), ((1, 2, 3), (1, 2, 3))])
def test_colours_are_matplotlibs(color, expected):
    assert paint.rgb(color) == expected


@pytest.mark.parametrize("color, match", [("C", "not a colour"), ("1.5", "between 0 and 1"), ("violet", "not a colour")])
def test_an_unknown_colour_is_refused(color, match):
    with pytest.raises(ValueError, match=match):
        paint.rgb(color)


def test_a_box_covers_each_pixel_by_its_share():
    """Black over x 1.25-3.5 on white: pixel 1 three quarters covered, 2 whole, 3 half; rows 0-1 whole."""
    image = Image.new("RGB", (5, 2), (255, 255, 255))
    paint.fill_box(image, 1.25, 0.0, 3.5, 2.0, (0, 0, 0))
    row = np.asarray(image.convert("L"))[0]
    np.testing.assert_allclose(row, [255, 255 * 0.25, 0, 255 * 0.5, 255], atol=1.0)
    half = Image.new("RGB", (1, 1), (255, 255, 255))
    paint.fill_box(half, 0.0, 0.0, 1.0, 1.0, (0, 0, 0), alpha=0.25)
    assert np.asarray(half.convert("L"))[0, 0] == pytest.approx(255 * 0.75, abs=1.0)


@pytest.mark.parametrize("centre, width, snapped", [(10.3, 1.22, 10.5), (10.9, 0.46, 10.5), (10.6, 2.0, 11.0),
                                                    (10.4, 3.1, 10.5)])
def test_straight_lines_are_snapped_to_whole_pixels(centre, width, snapped):
    assert paint.snap(centre, width) == snapped


def test_polylines_are_cut_at_the_box():
    box = (0.0, 0.0, 2.0, 2.0)
    (part,) = paint.clip_polyline(np.array([-1.0, 3.0]), np.array([1.0, 1.0]), box)
    np.testing.assert_allclose(part, [[0.0, 1.0], [2.0, 1.0]])
    # out through the top and back: two parts; a NaN breaks the line; a line wholly outside is gone
    parts = paint.clip_polyline(np.array([0.5, 1.0, 1.5, 1.5, 1.8]), np.array([1.0, -1.0, 1.0, np.nan, 1.5]), box)
    assert len(parts) == 2
    np.testing.assert_allclose(parts[0], [[0.5, 1.0], [0.75, 0.0]])
    np.testing.assert_allclose(parts[1], [[1.25, 0.0], [1.5, 1.0]])
    assert paint.clip_polyline(np.array([3.0, 4.0]), np.array([0.0, 1.0]), box) == []


def test_dashes_are_cut_along_the_length():
    """A 10 px line, dashes of 3 with gaps of 2: 0-3, 5-8 (and the corner at 4 kept inside the second)."""
    pieces = paint.dash_pieces(np.array([[0.0, 0.0], [10.0, 0.0]]), 3.0, 2.0)
    assert pieces == [[0.0, 0.0, 3.0, 0.0], [5.0, 0.0, 8.0, 0.0]]
    (corner,) = paint.dash_pieces(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]), 4.0, 10.0)
    assert corner == [0.0, 0.0, 2.0, 0.0, 2.0, 2.0]


def test_a_curve_is_drawn_only_inside_its_box():
    """A wide red zigzag through a 40 x 40 box of a 100 x 100 canvas: red inside, none outside."""
    image = Image.new("RGB", (100, 100), (255, 255, 255))
    x = np.linspace(-50.0, 150.0, 41)
    y = np.where(np.arange(41) % 2, -80.0, 180.0)
    paint.stroke(image, x, y, (30.0, 30.0, 70.0, 70.0), 2.0, (255, 0, 0))
    red = np.asarray(image)[:, :, 1] < 128  # green channel gone: red
    rows, columns = np.nonzero(red)
    assert red[30:70, 30:70].any()
    assert rows.min() >= 30 and rows.max() < 70 and columns.min() >= 30 and columns.max() < 70
