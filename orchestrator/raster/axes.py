"""One axes of a run figure: what is drawn in it, its scales, ticks, labels, titles and legend.

The plot code adds content (:meth:`Axes.curve`, :meth:`Axes.span`, ...) and text; the
figure then lays the axes out in a box of the canvas (:meth:`Axes.lay_out`): limits
(given, or the data's range with 5 % margins), ticks (:mod:`.ticks`), every text with its
box (:attr:`Axes.texts`), the legend's place; and draws it (:meth:`Axes.draw`). The sizes
are matplotlib's defaults: tick labels and axis labels 10 pt, ticks 3.5 pt long outwards
(minor 2 pt), 3.5 pt from their labels, axis labels 4 pt beyond the tick labels, titles
6 pt above the axes; an offset or power of ten of the tick labels (:mod:`.ticks`) 3 pt above
the y axis' top, or right below the x axis' tick labels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import paint, ticks
from .legend import Entry, Legend
from .text import Text, pixels

TICK_PT = 10.0
LABEL_PT = 10.0
TITLE_PT = 12.0
MAJOR_TICK = (3.5, 0.8)  # length, width [pt]
MINOR_TICK = (2.0, 0.6)
TICK_PAD_PT = 3.5
LABEL_PAD_PT = 4.0
TITLE_PAD_PT = 6.0
OFFSET_PAD_PT = 3.0
SPINE_PT = 0.8
#: share of the data's range added on both sides where the limits are not given
MARGIN = 0.05


@dataclass
class Curve:
    """A line through data points (or a horizontal line across the axes where ``x`` is None)."""

    x: np.ndarray | None
    y: np.ndarray
    color: paint.RGB
    width_pt: float
    dashed: bool
    label: str | None


@dataclass
class Span:
    x0: float
    x1: float
    color: paint.RGB
    label: str | None


@dataclass
class Bars:
    """Bars from the axis' bottom to ``top``, from ``left`` to ``right`` (data units)."""

    left: np.ndarray
    right: np.ndarray
    top: np.ndarray
    color: paint.RGB


@dataclass
class Tick:
    value: float
    at: float  # canvas coordinate along the axis [pixels]
    label: str
    major: bool = True


class Axes:
    """Content and text of one axes; its layout once :meth:`lay_out` placed it."""

    def __init__(self) -> None:
        self.spans: list[Span] = []
        self.lines: list[Curve] = []
        self.bars: list[Bars] = []
        self.notes: list[Text] = []
        self.xlim: tuple[float, float] | None = None
        self.ylim: tuple[float, float] | None = None
        self.yscale = "linear"
        self.xlabel = ""
        self.ylabel = ""
        self.titles: dict[str, tuple[str, float]] = {}
        self.grid_style: tuple[float, paint.RGB, float, bool] | None = None
        self.legend_style: tuple[str, float] | None = None
        self.legend_beside = False  # where the figure puts it (set_legend, Figure.lay_out)
        self.x_tick_labels = True
        self._labelled: list[Curve | Span] = []  # in the order added: the legend's order
        # the layout (lay_out)
        self.box: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0)
        self.xticks: list[Tick] = []
        self.yticks: list[Tick] = []
        self.texts: list[Text] = []
        self.legend: Legend | None = None

    # -- content --------------------------------------------------------------------------------------------------
    def curve(self, x, y, color="C0", width_pt: float = 1.5, dashed: bool = False, label: str | None = None) -> None:
        """A line through ``(x, y)`` (data units; non-finite points break it), ``width_pt`` wide, solid or dashed."""
        self._add(self.lines, Curve(np.asarray(x, dtype=float), np.asarray(y, dtype=float), paint.rgb(color),
                                    width_pt, dashed, label))

    def hline(self, y: float, color="k", width_pt: float = 1.0, dashed: bool = False, label: str | None = None) -> None:
        """A horizontal line across the axes at ``y``."""
        self._add(self.lines, Curve(None, np.array([float(y)]), paint.rgb(color), width_pt, dashed, label))

    def span(self, x0: float, x1: float, color="0.93", label: str | None = None) -> None:
        """A shaded band over the axes' height from ``x0`` to ``x1`` (below the grid and the curves)."""
        self._add(self.spans, Span(float(x0), float(x1), paint.rgb(color), label))

    def _add(self, items: list, item: Curve | Span) -> None:
        items.append(item)
        if item.label:
            self._labelled.append(item)

    def bar(self, left, right, top, color="C0") -> None:
        """Bars from the axis' bottom up to ``top``, one per ``[left, right]``."""
        self.bars.append(Bars(np.asarray(left, float), np.asarray(right, float), np.asarray(top, float),
                              paint.rgb(color)))

    def note(self, text: str, fx: float, fy: float, size_pt: float = 7.0, color="0.35") -> None:
        """A small text whose baseline starts at ``(fx, fy)`` of the axes (fractions from its bottom left)."""
        self.notes.append(Text(text, fx, fy, size_pt, color=paint.rgb(color), role="note"))

    def set_title(self, text: str, loc: str = "center", size_pt: float = TITLE_PT) -> None:
        self.titles[loc] = (text, size_pt)

    def grid(self, width_pt: float = 0.8, color="#b0b0b0", alpha: float = 1.0, minor: bool = False) -> None:
        """Grid lines at the major ticks (and the minor ones of a log axis with ``minor``), below the curves."""
        self.grid_style = (width_pt, paint.rgb(color), alpha, minor)

    def set_legend(self, loc: str = "best", size_pt: float = 8.0) -> None:
        """A legend of the labelled content: ``beside`` the axes on the right, or inside at the ``best`` place.

        The best place is the corner (or edge, or centre) that hides least (:meth:`Legend.place_best`);
        where every place would hide some of the lines, the figure puts the legend beside the axes.
        """
        if loc not in ("best", "beside"):
            raise ValueError(f"a legend goes 'best' or 'beside', not {loc!r}")
        self.legend_style = (loc, size_pt)
        self.legend_beside = loc == "beside"

    def legend_entries(self) -> list[Entry]:
        """The labelled spans and lines, in the order added."""
        return [Entry(i.label, "patch", i.color) if isinstance(i, Span) else
                Entry(i.label, "line", i.color, i.width_pt, i.dashed) for i in self._labelled]

    # -- scales ---------------------------------------------------------------------------------------------------
    def data_limits(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(x limits, y limits): the given ones, else the content's range widened by :data:`MARGIN`."""
        return self.xlim or self._auto(self._x_values()), self.ylim or self._auto(self._y_values(), self.yscale == "log")

    def _x_values(self) -> list[np.ndarray]:
        values = [c.x for c in self.lines if c.x is not None]
        values += [np.array([s.x0, s.x1]) for s in self.spans]
        values += [np.concatenate([b.left, b.right]) for b in self.bars]
        return values

    def _y_values(self) -> list[np.ndarray]:
        values = [c.y for c in self.lines]
        values += [b.top if self.yscale == "log" else np.append(b.top, 0.0) for b in self.bars]
        return values

    def _auto(self, values: list[np.ndarray], log: bool = False) -> tuple[float, float]:
        """The range of ``values`` (positive ones on a log axis) widened by :data:`MARGIN` (of decades on a log axis)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            scaled = [np.log10(v) if log else v for v in values]
        finite = [v[np.isfinite(v)] for v in scaled]
        finite = [v for v in finite if v.size]
        if not finite:
            return (1.0, 10.0) if log else (0.0, 1.0)
        low, high = ticks.nonsingular(min(float(v.min()) for v in finite), max(float(v.max()) for v in finite))
        pad = MARGIN * (high - low)
        return (10.0 ** (low - pad), 10.0 ** (high + pad)) if log else (low - pad, high + pad)

    def _scale(self, v):
        return np.log10(v) if self.yscale == "log" else v

    def x_pixels(self, x) -> np.ndarray:
        """Canvas x [pixels] of data ``x``."""
        (lo, hi), (x0, _, x1, _) = self._xl, self.box
        return x0 + (np.asarray(x, dtype=float) - lo) * ((x1 - x0) / (hi - lo))

    def y_pixels(self, y) -> np.ndarray:
        """Canvas y [pixels, down] of data ``y`` (log axes: non-positive values are not finite)."""
        (lo, hi), (_, y0, _, y1) = self._yl, self.box
        with np.errstate(divide="ignore", invalid="ignore"):
            f = self._scale(np.asarray(y, dtype=float))
        return y1 - (f - lo) * ((y1 - y0) / (hi - lo))

    # -- layout ---------------------------------------------------------------------------------------------------
    def lay_out(self, box: tuple[float, float, float, float]) -> None:
        """Place the axes in ``box`` (x0, y0, x1, y1) [pixels]: limits, ticks, every text, the legend."""
        self.box = box
        (xa, xb), (ya, yb) = self.data_limits()
        if self.yscale == "log" and not (ya > 0.0 and yb > 0.0):
            raise ValueError(f"a log axis needs positive limits, not {ya:g}..{yb:g}")
        if xa == xb:
            xa, xb = ticks.nonsingular(xa, xb)
        if ya == yb:
            ya, yb = (ya / 1.25, ya * 1.25) if self.yscale == "log" else ticks.nonsingular(ya, yb)
        self._xl = (xa, xb)
        self._yl = tuple(float(v) for v in self._scale(np.array([ya, yb])))
        x0, y0, x1, y1 = box
        to_pt = 72.0 / pixels(72.0)
        self.xticks, x_offset = self._linear_ticks(xa, xb, ticks.tick_bins((x1 - x0) * to_pt, TICK_PT, True),
                                                   self.x_pixels)
        ybins = ticks.tick_bins((y1 - y0) * to_pt, TICK_PT, False)
        if self.yscale == "log":
            major, minor = ticks.log_ticks(ya, yb, ybins)
            self.yticks = self._visible(major, ticks.log_labels(major).labels, ya, yb, self.y_pixels)
            self.yticks += [Tick(t.value, t.at, "", False) for t in self._visible(minor, [""] * minor.size, ya, yb,
                                                                                 self.y_pixels)]
            y_offset = ""
        else:
            self.yticks, y_offset = self._linear_ticks(ya, yb, ybins, self.y_pixels)
        self.texts = []
        self._lay_out_ticks_and_labels(x_offset if self.x_tick_labels else "", y_offset)
        self._lay_out_titles()
        for n in self.notes:
            self.texts.append(Text(n.text, x0 + n.x * (x1 - x0), y1 - n.y * (y1 - y0), n.size_pt, color=n.color,
                                   role="note"))
        self._lay_out_legend()

    def _visible(self, values, labels, low, high, to_pixels) -> list[Tick]:
        low, high = sorted((low, high))
        slack = 1e-10 * (high - low)
        return [Tick(float(v), float(to_pixels(v)), text, True) for v, text in zip(values, labels)
                if low - slack <= v <= high + slack]

    def _linear_ticks(self, low, high, bins, to_pixels) -> tuple[list[Tick], str]:
        """The visible ticks of a linear axis and its offset text ('' if none)."""
        values = ticks.linear_ticks(low, high, bins)
        labels = ticks.linear_labels(values, low, high)
        return self._visible(values, labels.labels, low, high, to_pixels), labels.offset_text

    def _lay_out_ticks_and_labels(self, x_offset: str, y_offset: str) -> None:
        """Tick labels, the offset texts (x: right, below the tick labels; y: above the axes), axis labels."""
        x0, y0, x1, y1 = self.box
        reach = pixels(MAJOR_TICK[0] + TICK_PAD_PT)
        if self.x_tick_labels:
            self.texts += [Text(t.label, t.at, y1 + reach, TICK_PT, ha="center", va="top", role="xtick")
                           for t in self.xticks]
        self.texts += [Text(t.label, x0 - reach, t.at, TICK_PT, ha="right", va="center", role="ytick")
                       for t in self.yticks if t.label]
        below = max([t.box[3] for t in self.texts if t.role == "xtick"], default=y1 + pixels(MAJOR_TICK[0]))
        if x_offset:
            self.texts.append(Text(x_offset, x1, below + pixels(OFFSET_PAD_PT), TICK_PT, ha="right", va="top",
                                   role="offset"))
        if self.xlabel:
            label = Text(self.xlabel, 0.5 * (x0 + x1), below + pixels(LABEL_PAD_PT), LABEL_PT, ha="center", va="top",
                         role="xlabel")
            for o in [t.box for t in self.texts if t.role == "offset"]:  # below an x offset text it would cover
                if label.box[2] > o[0] and label.box[1] < o[3]:
                    label.y = o[3] + pixels(OFFSET_PAD_PT)
            self.texts.append(label)
        left = min([t.box[0] for t in self.texts if t.role == "ytick"], default=x0 - pixels(MAJOR_TICK[0]))
        if self.ylabel:
            self.texts.append(Text(self.ylabel, left - pixels(LABEL_PAD_PT), 0.5 * (y0 + y1), LABEL_PT, ha="right",
                                   va="center", rotation=90, role="ylabel"))
        if y_offset:
            self.texts.append(Text(y_offset, x0, y0 - pixels(OFFSET_PAD_PT), TICK_PT, ha="left", va="bottom",
                                   role="offset"))

    def _lay_out_titles(self) -> None:
        x0, y0, x1, _ = self.box
        offsets = [t.box for t in self.texts if t.role == "offset" and t.va == "bottom"]  # the y axis'
        for loc, (text, size) in self.titles.items():
            x, ha = {"left": (x0, "left"), "center": (0.5 * (x0 + x1), "center"), "right": (x1, "right")}[loc]
            title = Text(text, x, y0 - pixels(TITLE_PAD_PT), size, ha=ha, va="baseline", role="title")
            box = title.box
            for o in offsets:  # lifted above an offset text it would cover
                if box[0] < o[2] and o[0] < box[2] and box[3] > o[1]:
                    title.y -= box[3] - o[1] + pixels(1.0)
            self.texts.append(title)

    def _lay_out_legend(self) -> None:
        self.legend = None
        if self.legend_style is None or not self.legend_entries():
            return
        self.legend = Legend(self.legend_entries(), self.legend_style[1])
        if self.legend_beside:
            self.legend.place_beside(self.box)
        else:
            spans = [(*sorted(self.x_pixels([s.x0, s.x1])), self.box[1], self.box[3]) for s in self.spans]
            self.legend.place_best(self.box, self.drawn_points(), [(a, y0, b, y1) for a, b, y0, y1 in spans])
        self.texts += self.legend.texts

    def drawn_points(self) -> list[np.ndarray]:
        """The canvas points of every line drawn (each (n, 2), only its finite ones)."""
        points = []
        for c in self.lines:
            xs = np.array([self.box[0], self.box[2]]) if c.x is None else self.x_pixels(c.x)
            ys = np.full(2, self.y_pixels(c.y[0])) if c.x is None else self.y_pixels(c.y)
            keep = np.isfinite(xs) & np.isfinite(ys)
            points.append(np.column_stack([xs[keep], ys[keep]]))
        return points

    def outer_box(self) -> tuple[float, float, float, float]:
        """The axes with every text and tick of theirs and a legend beside them [pixels]."""
        boxes = [self.box] + [t.box for t in self.texts]
        if self.legend is not None:
            boxes.append(self.legend.box)
        reach = pixels(MAJOR_TICK[0])
        boxes.append((self.box[0] - reach, self.box[1], self.box[2], self.box[3] + reach))
        return (min(b[0] for b in boxes), min(b[1] for b in boxes), max(b[2] for b in boxes),
                max(b[3] for b in boxes))

    # -- drawing --------------------------------------------------------------------------------------------------
    def draw(self, image) -> None:
        """Spans, bars, grid, lines, spines, ticks and the legend's frame (the text is drawn by the figure)."""
        x0, y0, x1, y1 = self.box
        for s in self.spans:
            a, b = sorted(self.x_pixels([s.x0, s.x1]))
            paint.fill_box(image, max(a, x0), y0, min(b, x1), y1, s.color)
        for b in self.bars:
            mask = paint.Mask(self.box)
            lefts, rights, tops = self.x_pixels(b.left), self.x_pixels(b.right), self.y_pixels(b.top)
            for left, right, top in zip(lefts, rights, tops):
                if math.isfinite(top):
                    mask.rectangle(max(left, x0), max(top, y0), min(right, x1), y1)
            mask.blend(image, b.color)
        if self.grid_style is not None:
            width, color, alpha, minor = self.grid_style
            for t in self.xticks:
                paint.vline(image, t.at, y0, y1, pixels(width), color, alpha)
            for t in self.yticks:
                if t.major or minor:
                    paint.hline(image, t.at, x0, x1, pixels(width), color, alpha)
        for c in self.lines:
            xs = np.array([x0, x1]) if c.x is None else self.x_pixels(c.x)
            ys = np.full(2, paint.snap(float(self.y_pixels(c.y[0])), pixels(c.width_pt))) if c.x is None \
                else self.y_pixels(c.y)
            paint.stroke(image, xs, ys, self.box, pixels(c.width_pt), c.color, c.dashed)
        black = (0, 0, 0)
        spine = pixels(SPINE_PT)
        paint.hline(image, y0, x0 - 0.5 * spine, x1 + 0.5 * spine, spine, black)
        paint.hline(image, y1, x0 - 0.5 * spine, x1 + 0.5 * spine, spine, black)
        paint.vline(image, x0, y0, y1, spine, black)
        paint.vline(image, x1, y0, y1, spine, black)
        for t in self.xticks:
            length, width = MAJOR_TICK
            paint.vline(image, t.at, y1, y1 + pixels(length), pixels(width), black)
        for t in self.yticks:
            length, width = MAJOR_TICK if t.major else MINOR_TICK
            paint.hline(image, t.at, x0 - pixels(length), x0, pixels(width), black)
        if self.legend is not None:
            self.legend.draw(image)
