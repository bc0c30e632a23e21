"""Legends of the run figures: entries, their box, where it goes (the "best" corner or beside the axes).

The sizes are matplotlib's defaults in font sizes (:data:`SPACING`), so a legend reads as in
the other figures: a rounded white frame (80 % opaque, a light grey edge), a line or patch
sample per entry, its text beside it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import paint
from .text import Text, pixels

#: space in the legend's font size: around the entries, between rows, the sample's length and height,
#: between sample and text, and between the legend and the axes' edges
SPACING = {"border": 0.4, "rows": 0.5, "handle": 2.0, "handle_height": 0.7, "handle_text": 0.8, "axes": 0.5}
#: the places a "best" legend may take, in the order tried (matplotlib's ``loc`` codes 1-10):
#: (horizontal, vertical) as fractions of the free room inside the axes
PLACES = {"upper right": (1.0, 0.0), "upper left": (0.0, 0.0), "lower left": (0.0, 1.0), "lower right": (1.0, 1.0),
          "right": (1.0, 0.5), "center left": (0.0, 0.5), "center right": (1.0, 0.5), "lower center": (0.5, 1.0),
          "upper center": (0.5, 0.0), "center": (0.5, 0.5)}
FRAME_EDGE = 0.8  # grey level of the frame's edge
FRAME_ALPHA = 0.8
FRAME_WIDTH_PT = 0.8


@dataclass
class Entry:
    """One legend row: a line sample (``kind="line"``: colour, width, dashed) or a filled patch, and its text."""

    label: str
    kind: str
    color: paint.RGB
    width_pt: float = 1.0
    dashed: bool = False


@dataclass
class Legend:
    """The entries of one axes' legend in ``size_pt`` text; ``box`` (x0, y0, x1, y1) once placed."""

    entries: list[Entry]
    size_pt: float
    box: tuple[float, float, float, float] | None = None
    place: str = ""
    #: drawn points inside the box plus lines crossing it (:meth:`place_best`)
    hidden: int = 0
    texts: list[Text] = field(default_factory=list)

    def _unit(self, key: str) -> float:
        return SPACING[key] * pixels(self.size_pt)

    def _row_height(self) -> float:
        return Text("", 0.0, 0.0, self.size_pt).extent()[1]

    def extent(self) -> tuple[float, float]:
        """(width, height) of the legend's box [pixels]."""
        widest = max(Text(e.label, 0.0, 0.0, self.size_pt).extent()[0] for e in self.entries)
        n = len(self.entries)
        width = 2 * self._unit("border") + self._unit("handle") + self._unit("handle_text") + widest
        height = 2 * self._unit("border") + n * self._row_height() + (n - 1) * self._unit("rows")
        return width, height

    def candidates(self, axes_box) -> dict[str, tuple[float, float, float, float]]:
        """Each place of :data:`PLACES` as a box inside ``axes_box``, kept off its edges by the axes pad."""
        width, height = self.extent()
        x0, y0, x1, y1 = axes_box
        pad = self._unit("axes")
        boxes = {}
        for name, (fx, fy) in PLACES.items():
            left = x0 + pad + fx * (x1 - x0 - 2 * pad - width)
            top = y0 + pad + fy * (y1 - y0 - 2 * pad - height)
            boxes[name] = (left, top, left + width, top + height)
        return boxes

    def place_best(self, axes_box, lines: list[np.ndarray], patches=()) -> None:
        """Put the legend where it hides least of ``lines`` (canvas points, each (n, 2)), as matplotlib's "best".

        A place's cost is the number of drawn points inside it, plus one for every line that
        crosses it and for every one of ``patches`` (boxes: shaded spans) it overlaps; the first
        place of :data:`PLACES` with the least cost wins (the first with none at once).
        """
        best = None
        for name, box in self.candidates(axes_box).items():
            hidden = 0
            for pts in lines:
                inside = ((pts[:, 0] >= box[0]) & (pts[:, 0] <= box[2]) & (pts[:, 1] >= box[1]) & (pts[:, 1] <= box[3]))
                hidden += int(np.count_nonzero(inside)) + (1 if paint.clip_polyline(pts[:, 0], pts[:, 1], box) else 0)
            cost = hidden + sum(1 for p in patches if p[0] < box[2] and box[0] < p[2] and p[1] < box[3] and box[1] < p[3])
            if best is None or cost < best[0]:
                best = (cost, name, box, hidden)
            if cost == 0:
                break
        _, self.place, self.box, self.hidden = best
        self._lay_out_texts()

    def place_beside(self, axes_box) -> None:
        """Put the legend beside the axes, its top left at their top right (half a percent of their width off)."""
        width, height = self.extent()
        left = axes_box[2] + 0.005 * (axes_box[2] - axes_box[0])
        self.box, self.place, self.hidden = (left, axes_box[1], left + width, axes_box[1] + height), "beside", 0
        self._lay_out_texts()

    def _rows(self):
        """(entry, vertical centre of its row) [pixels]."""
        top = self.box[1] + self._unit("border")
        row = self._row_height()
        for i, entry in enumerate(self.entries):
            yield entry, top + i * (row + self._unit("rows")) + 0.5 * row

    def _lay_out_texts(self) -> None:
        x = self.box[0] + self._unit("border") + self._unit("handle") + self._unit("handle_text")
        self.texts = [Text(e.label, x, yc, self.size_pt, ha="left", va="center", role="legend") for e, yc in self._rows()]

    def draw(self, image) -> None:
        """Frame and samples (the texts are drawn with the figure's other text)."""
        x0, y0, x1, y1 = self.box
        radius = 0.2 * pixels(self.size_pt)
        frame = paint.Mask(self.box)
        frame.rounded(x0, y0, x1, y1, radius)
        frame.blend(image, (255, 255, 255), FRAME_ALPHA)
        edge = paint.Mask((x0 - 1, y0 - 1, x1 + 1, y1 + 1))
        edge.rounded(x0, y0, x1, y1, radius, outline=pixels(FRAME_WIDTH_PT))
        edge.blend(image, paint.rgb(str(FRAME_EDGE)))
        left = x0 + self._unit("border")
        length = self._unit("handle")
        for entry, yc in self._rows():
            if entry.kind == "line":
                width = pixels(entry.width_pt)
                y = paint.snap(yc, width)  # a straight line on whole pixels, as the axes' horizontal lines
                paint.stroke(image, np.array([left, left + length]), np.array([y, y]), self.box, width, entry.color,
                             entry.dashed)
            else:
                half = 0.5 * self._unit("handle_height")
                paint.fill_box(image, left, yc - half, left + length, yc + half, entry.color)
