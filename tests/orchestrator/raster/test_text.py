"""Text of the run figures: DejaVu Sans found without matplotlib, measured by the font's own metrics, drawn inside its box."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from orchestrator.raster import text
from orchestrator.raster.text import Text, pixels, text_width

#: DejaVu Sans in font units (2048 per em): the advance of '0', the top of 'l', the bottom of 'p'
EM, ZERO, L_TOP, P_BOTTOM = 2048.0, 1303.0, 1556.0, 426.0
SIZE = 10.0
PX = pixels(SIZE)  # 15.28 px: 10 pt at 110 dpi


def _caches_clear():
    for cached in (text.font_file, text.font, text._metrics, text.text_width):
        cached.cache_clear()


def test_the_font_is_matplotlibs_dejavu_sans_found_without_importing_matplotlib():
    code = ("import sys\nfrom orchestrator.raster.text import font, font_file\n"
            "print('matplotlib' in sys.modules, font(10.0).getname()[0], font_file().name)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "DejaVu", "Sans", "DejaVuSans.ttf"]


def test_widths_are_the_advances_of_the_font():
    assert pixels(72.0) == 110.0 and PX == pytest.approx(15.2778, abs=1e-4)
    assert text_width("0", SIZE) == pytest.approx(ZERO / EM * PX, abs=0.5)  # 9.72 px, hinted to whole pixels
    assert text_width("0000", SIZE) == pytest.approx(4 * text_width("0", SIZE))


@pytest.mark.parametrize("ha, va, rotation", [("right", "top", 0), ("left", "baseline", 0), ("center", "center", 0),
                                              ("right", "center", 90)])
def test_a_text_box_reaches_from_the_top_of_l_to_the_bottom_of_p(ha, va, rotation):
    t = Text("0000", 100.0, 50.0, SIZE, ha=ha, va=va, rotation=rotation)
    x0, y0, x1, y1 = t.box
    width, height = (y1 - y0, x1 - x0) if rotation else (x1 - x0, y1 - y0)
    assert width == pytest.approx(4 * text_width("0", SIZE))
    assert height == pytest.approx((L_TOP + P_BOTTOM) / EM * PX, abs=1.0)  # 14.8 px
    anchor_x = {"left": x0, "center": 0.5 * (x0 + x1), "right": x1}[ha]
    anchor_y = {"top": y0, "center": 0.5 * (y0 + y1), "baseline": y0 + L_TOP / EM * PX}[va]
    # the baseline lies the top of l below the box's top (hinted to whole pixels: within a pixel)
    assert (anchor_x, anchor_y) == pytest.approx((100.0, 50.0), abs=0 if va != "baseline" else 1.0)


def test_lines_are_a_descent_and_1_2_ascents_apart():
    one = Text("a", 0.0, 0.0, SIZE).extent()[1]
    three = Text("a\nb\nc", 0.0, 0.0, SIZE).extent()[1]
    assert three - one == pytest.approx(2 * (P_BOTTOM + 1.2 * L_TOP) / EM * PX, abs=2.0)  # 2 x 17.1 px


@pytest.mark.parametrize("rotation", [0, 90])
def test_a_text_is_drawn_inside_its_box(rotation):
    from PIL import Image

    image = Image.new("RGB", (200, 200), (255, 255, 255))
    t = Text("force [kN] gp", 100.0, 100.0, SIZE, ha="center", va="center", rotation=rotation)
    t.draw(image)
    ink = np.argwhere(np.asarray(image.convert("L")) < 200)  # (row, column)
    x0, y0, x1, y1 = t.box
    assert ink.size
    assert x0 - 1 <= ink[:, 1].min() and ink[:, 1].max() <= x1 + 1
    assert y0 - 1 <= ink[:, 0].min() and ink[:, 0].max() <= y1 + 1
    if rotation:  # reads upwards: the first letter ('f') at the bottom
        assert ink[:, 0].max() > y1 - 0.2 * (y1 - y0) and ink[:, 0].min() < y0 + 0.2 * (y1 - y0)


def test_without_matplotlib_the_text_is_pillows_own_font(monkeypatch):
    _caches_clear()
    monkeypatch.setattr(text.importlib.util, "find_spec", lambda name: None)
    try:
        assert text.font_file() is None
        assert text.font(SIZE).getname()[0] != "DejaVu Sans"
        x0, y0, x1, y1 = Text("0000", 0.0, 0.0, SIZE, va="top").box
        assert x1 - x0 > 0.5 * 4 * ZERO / EM * PX and 0.5 * PX < y1 - y0 < 1.5 * PX
    finally:
        monkeypatch.undo()
        _caches_clear()
