"""Text of the run figures: DejaVu Sans through FreeType (Pillow), measured and placed by its box.

A text's box is what the layout keeps clear of other text: its advance width, and from the
top of an ``l`` to the bottom of a ``p`` (the same height whatever the letters, as
matplotlib's); lines are a descent and 1.2 ascents apart. Sizes are in points at :data:`~orchestrator.png_files.DPI`.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..figure_files import DPI

#: the font of every figure (matplotlib's default, so that the run figures read like the others)
FAMILY = "DejaVu Sans"
#: baseline to baseline of a text's lines: a descent and this many ascents
LINE_SPACING = 1.2


@lru_cache(maxsize=1)
def font_file() -> Path | None:
    """DejaVu Sans as matplotlib installs it, or None where it is not there.

    matplotlib ships DejaVu Sans as its default font in its package data
    (``mpl-data/fonts/ttf/DejaVuSans.ttf`` under the package, the folder
    ``matplotlib.get_data_path()`` documents): the file is looked up there without
    importing matplotlib (0.2 s), by the location the installed distribution documents, and
    :func:`font` uses it only if FreeType reads it as the family :data:`FAMILY`. This asks
    the installed package where its data is; it assumes nothing about matplotlib's modules.
    Without it the figures use Pillow's own font (:func:`font`).
    """
    try:
        spec = importlib.util.find_spec("matplotlib")
    except (ImportError, ValueError):
        return None
    for folder in (spec.submodule_search_locations or []) if spec is not None else []:
        path = Path(folder) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if path.is_file():
            return path
    return None


def pixels(points: float) -> float:
    """A length in points [1/72 in] on the canvas [pixels]."""
    return points * DPI / 72.0


@lru_cache(maxsize=None)
def font(size_pt: float):
    """The FreeType font of ``size_pt`` points: DejaVu Sans (:func:`font_file`), else Pillow's default font.

    Pillow's default (``ImageFont.load_default``) is a FreeType font too where Pillow has
    FreeType, so the figures keep their sizes and layout; only the letters' shapes differ.
    """
    from PIL import ImageFont

    path = font_file()
    if path is not None:
        try:
            face = ImageFont.truetype(str(path), pixels(size_pt), layout_engine=ImageFont.Layout.BASIC)
        except OSError:
            face = None
        if face is not None and face.getname()[0] == FAMILY:
            return face
    return ImageFont.load_default(pixels(size_pt))


@lru_cache(maxsize=None)
def _metrics(size_pt: float) -> tuple[float, float, float]:
    """(ascent, descent, line pitch) of the font of ``size_pt`` [pixels].

    A line's box reaches from the top of an ``l`` to the bottom of a ``p``; from one baseline
    to the next is a descent and :data:`LINE_SPACING` ascents (both as matplotlib's).
    """
    face = font(size_pt)
    if hasattr(face, "getmetrics"):
        _, top, _, bottom = face.getbbox("lp", anchor="ls")
        ascent, descent = float(-top), float(bottom)
    else:  # a bitmap font (Pillow without FreeType): no baseline known
        _, top, _, bottom = face.getbbox("lp")
        ascent, descent = float(bottom - top), 0.0
    return ascent, descent, descent + LINE_SPACING * ascent


@lru_cache(maxsize=4096)
def text_width(text: str, size_pt: float) -> float:
    """Advance width of one line of ``text`` [pixels] (tick labels repeat: remembered)."""
    return float(font(size_pt).getlength(text))


@dataclass
class Text:
    """A text placed on the canvas: its anchor ``(x, y)`` [pixels, y down] and how the box sits on it.

    ``ha`` is ``left``, ``center`` or ``right`` of the box; ``va`` is ``top``, ``center``,
    ``bottom`` of the box or ``baseline`` (of its first line); ``rotation`` 90 turns the text
    to read upwards about the box (a y label). ``role`` says what it is (``title``, ``ytick``, ...).
    """

    text: str
    x: float
    y: float
    size_pt: float
    ha: str = "left"
    va: str = "baseline"
    rotation: int = 0
    color: tuple[int, int, int] = (0, 0, 0)
    role: str = ""

    @property
    def lines(self) -> list[str]:
        return self.text.split("\n")

    def extent(self) -> tuple[float, float]:
        """(width, height) of the unrotated box [pixels]."""
        ascent, descent, pitch = _metrics(self.size_pt)
        width = max(text_width(line, self.size_pt) for line in self.lines)
        return width, ascent + descent + (len(self.lines) - 1) * pitch

    @property
    def box(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) of the text on the canvas [pixels, y down]."""
        width, height = self.extent()
        if self.rotation:
            width, height = height, width
        x0 = {"left": self.x, "center": self.x - 0.5 * width, "right": self.x - width}[self.ha]
        if self.va == "baseline":
            y0 = self.y - _metrics(self.size_pt)[0]
        else:
            y0 = {"top": self.y, "center": self.y - 0.5 * height, "bottom": self.y - height}[self.va]
        return x0, y0, x0 + width, y0 + height

    def draw(self, image) -> None:
        """Draw the text on ``image`` (an RGB ``PIL.Image``), anti-aliased."""
        from PIL import Image, ImageDraw

        x0, y0, x1, y1 = self.box
        face = font(self.size_pt)
        ascent, _, pitch = _metrics(self.size_pt)
        width = max(x1 - x0, y1 - y0) if self.rotation else x1 - x0
        if not self.rotation:
            draw = ImageDraw.Draw(image)
            for i, line in enumerate(self.lines):
                dx = {"left": 0.0, "center": 0.5, "right": 1.0}[self.ha] * (width - text_width(line, self.size_pt))
                draw.text((x0 + dx, y0 + ascent + i * pitch), line, fill=self.color, font=face, anchor="ls")
            return
        w_unrot, h_unrot = self.extent()
        slack = math.ceil(0.3 * pixels(self.size_pt))  # letters beyond the box's l and p (brackets, accents)
        mask = Image.new("L", (math.ceil(w_unrot) + 1, math.ceil(h_unrot) + 2 * slack), 0)
        ImageDraw.Draw(mask).text((0.0, slack + ascent), self.text, fill=255, font=face, anchor="ls")
        mask = mask.transpose(Image.Transpose.ROTATE_90)
        left, top = round(x0) - slack, round(y1 - mask.height)
        image.paste(self.color, (left, top, left + mask.width, top + mask.height), mask)
