"""Pixels of the run figures: colours, axis-aligned boxes and lines, anti-aliased curves and bars.

Everything is painted onto an RGB ``PIL.Image`` in canvas pixels (x right, y down; pixel
``(i, j)`` covers ``[i, i + 1) x [j, j + 1)``). An axis-aligned box (a span, a grid line, a
tick, a spine) covers each pixel by the exact share of its area inside it; grid lines, ticks
and spines are first snapped to the pixel grid so that they stay crisp. Curves and bars are
drawn :data:`SUPERSAMPLE` times finer into a coverage mask of their axes and reduced by
averaging, so their edges get 17 shades (16 sub-pixels); the mask then blends their colour
into the image. Curves are clipped to their axes exactly (segment by segment), dashed along
their length.
"""

from __future__ import annotations

import math

import numpy as np

#: matplotlib's default colour cycle ("tab10"): ``C0`` ... ``C9``
TAB10 = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
         "#17becf")
_NAMED = {"black": "#000000", "k": "#000000", "white": "#ffffff", "w": "#ffffff",
          **{f"tab:{name}": TAB10[i] for i, name in enumerate(
              ("blue", "orange", "green", "red", "purple", "brown", "pink", "gray", "olive", "cyan"))}}
#: sub-pixels per pixel (each way) of curves and bars
SUPERSAMPLE = 4
#: a dashed line's dash and gap, in its line widths (matplotlib's ``--``)
DASHES = (3.7, 1.6)

RGB = tuple[int, int, int]


def rgb(color) -> RGB:
    """An RGB triple of 0-255 from ``"C3"``, ``"tab:red"``, ``"#d62728"``, a grey ``"0.93"`` or a triple."""
    if isinstance(color, tuple):
        return tuple(int(c) for c in color)  # type: ignore[return-value]
    text = str(color)
    if len(text) == 2 and text[0] == "C" and text[1].isdigit():
        text = TAB10[int(text[1])]
    text = _NAMED.get(text, text)
    if text.startswith("#") and len(text) == 7:
        return int(text[1:3], 16), int(text[3:5], 16), int(text[5:7], 16)
    try:
        grey = float(text)
    except ValueError:
        raise ValueError(f"not a colour: {color!r}") from None
    if not 0.0 <= grey <= 1.0:
        raise ValueError(f"a grey level is between 0 and 1, not {color!r}")
    level = round(255 * grey)
    return level, level, level


def _shares(lo: float, hi: float) -> list[tuple[int, int, float]]:
    """The pixels from ``lo`` to ``hi`` covers along one axis: (first, end, share) of the first, inner and last."""
    first, last = math.floor(lo), math.ceil(hi)
    if last - first == 1:
        return [(first, last, hi - lo)]
    runs = [(first, first + 1, first + 1 - lo), (first + 1, last - 1, 1.0), (last - 1, last, hi - last + 1)]
    return [(a, b, share) for a, b, share in runs if b > a and share > 0.0]


def fill_box(image, x0: float, y0: float, x1: float, y1: float, color: RGB, alpha: float = 1.0) -> None:
    """Blend ``color`` over the rectangle ``[x0, x1] x [y0, y1]``, edge pixels by the share covered."""
    from PIL import ImageDraw

    width, height = image.size
    x0, x1 = max(min(x0, x1), 0.0), min(max(x0, x1), float(width))
    y0, y1 = max(min(y0, y1), 0.0), min(max(y0, y1), float(height))
    if x1 <= x0 or y1 <= y0:
        return
    draw = None
    for xa, xb, cx in _shares(x0, x1):
        for ya, yb, cy in _shares(y0, y1):
            level = round(255.0 * alpha * cx * cy)
            if level >= 255:
                image.paste(color, (xa, ya, xb, yb))
            elif level > 0:
                draw = draw or ImageDraw.Draw(image, "RGBA")  # blends the colour in by its alpha
                draw.rectangle((xa, ya, xb - 1, yb - 1), fill=(*color, level))


def snap(centre: float, width: float) -> float:
    """A line's centre moved onto the pixel grid so that it covers whole pixels where it can.

    Odd widths (in whole pixels; anything under 1.5) are centred on a pixel, even ones on
    the edge between two.
    """
    return math.floor(centre) + 0.5 if round(width) % 2 == 1 or width < 1.5 else float(round(centre))


def vline(image, x: float, y0: float, y1: float, width: float, color: RGB, alpha: float = 1.0) -> None:
    """A vertical line of ``width`` pixels from ``y0`` to ``y1``, snapped (a grid line, an x tick, a spine)."""
    x = snap(x, width)
    half = 0.5 * max(width, 1.0)
    fill_box(image, x - half, y0, x + half, y1, color, alpha * min(width, 1.0))


def hline(image, y: float, x0: float, x1: float, width: float, color: RGB, alpha: float = 1.0) -> None:
    """A horizontal line of ``width`` pixels from ``x0`` to ``x1``, snapped."""
    y = snap(y, width)
    half = 0.5 * max(width, 1.0)
    fill_box(image, x0, y - half, x1, y + half, color, alpha * min(width, 1.0))


def clip_polyline(x: np.ndarray, y: np.ndarray, box: tuple[float, float, float, float]) -> list[np.ndarray]:
    """The parts of the polyline through ``(x, y)`` inside ``box`` (x0, y0, x1, y1): arrays of points, shape (n, 2).

    Each segment is cut to the box (Liang-Barsky); a segment with a non-finite end is left
    out. Consecutive segments that stay inside form one part.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.size < 2:
        return []
    xa, ya, dx, dy = x[:-1], y[:-1], np.diff(x), np.diff(y)
    visible = np.isfinite(xa) & np.isfinite(ya) & np.isfinite(dx) & np.isfinite(dy)
    t_in = np.zeros(dx.size)
    t_out = np.ones(dx.size)
    bx0, by0, bx1, by1 = box
    with np.errstate(divide="ignore", invalid="ignore"):
        for p, q in ((-dx, xa - bx0), (dx, bx1 - xa), (-dy, ya - by0), (dy, by1 - ya)):
            ratio = q / p
            visible &= ~((p == 0.0) & (q < 0.0))
            t_in = np.where(p < 0.0, np.maximum(t_in, ratio), t_in)
            t_out = np.where(p > 0.0, np.minimum(t_out, ratio), t_out)
    visible &= t_in <= t_out
    index = np.nonzero(visible)[0]
    if index.size == 0:
        return []
    start = np.column_stack([xa[index] + t_in[index] * dx[index], ya[index] + t_in[index] * dy[index]])
    end = np.column_stack([xa[index] + t_out[index] * dx[index], ya[index] + t_out[index] * dy[index]])
    joined = np.zeros(index.size, bool)  # segment k continues segment k - 1
    joined[1:] = (np.diff(index) == 1) & (t_out[index[:-1]] >= 1.0) & (t_in[index[1:]] <= 0.0)
    firsts = np.nonzero(~joined)[0]
    ends = np.append(firsts[1:], index.size)
    return [np.vstack([start[a:a + 1], end[a:b]]) for a, b in zip(firsts, ends)]


def dash_pieces(points: np.ndarray, on: float, off: float) -> list[list[float]]:
    """The dashes of a polyline: pieces ``on`` long, ``off`` apart along its length from its start, as flat lists.

    Each piece is ``[x0, y0, x1, y1, ...]``: its start and end interpolated on the polyline,
    the points between them kept (a dash over a peak keeps the peak).
    """
    steps = np.hypot(*np.diff(points, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(steps)])
    begin = np.arange(0.0, s[-1], on + off)
    finish = np.minimum(begin + on, s[-1])
    first, last = np.searchsorted(s, begin, "right"), np.searchsorted(s, finish, "left")
    heads = np.column_stack([np.interp(begin, s, points[:, 0]), np.interp(begin, s, points[:, 1])]).tolist()
    tails = np.column_stack([np.interp(finish, s, points[:, 0]), np.interp(finish, s, points[:, 1])]).tolist()
    flat = points.ravel().tolist()
    return [head + flat[2 * a:2 * b] + tail for head, tail, a, b in zip(heads, tails, first.tolist(), last.tolist())]


#: a vertex where a curve turns by more than this [rad] gets a round joint (smaller turns leave no visible notch)
ROUND_TURN = math.radians(15.0)


class Mask:
    """A coverage mask over a rectangle of whole pixels, drawn :data:`SUPERSAMPLE` times finer."""

    def __init__(self, box: tuple[float, float, float, float]):
        from PIL import Image, ImageDraw

        self.left, self.top = math.floor(box[0]), math.floor(box[1])
        self.width = max(math.ceil(box[2]) - self.left, 1)
        self.height = max(math.ceil(box[3]) - self.top, 1)
        self.image = Image.new("L", (self.width * SUPERSAMPLE, self.height * SUPERSAMPLE), 0)
        self.draw = ImageDraw.Draw(self.image)

    def fine(self, points: np.ndarray) -> np.ndarray:
        """Canvas points (n, 2) as the fine mask's pixel coordinates (a pixel's centre is its integer index)."""
        return (points - (self.left, self.top)) * SUPERSAMPLE - 0.5

    def polyline(self, fine: np.ndarray, width: float, round_joints: bool = True) -> None:
        """Cover the stroke of ``width`` pixels along ``fine`` points (n, 2), with round joints where it turns.

        A joint gets a disc of the stroke's width where the polyline turns by more than
        :data:`ROUND_TURN` (and the stroke is wider than a pixel); elsewhere the segments meet
        closely enough.
        """
        thick = max(round(width * SUPERSAMPLE), 1)
        self.draw.line(fine.ravel().tolist(), fill=255, width=thick)
        if not round_joints or thick <= SUPERSAMPLE or len(fine) < 3:
            return
        d = np.diff(fine, axis=0)
        turn = np.abs(np.angle((d[1:, 0] + 1j * d[1:, 1]) * (d[:-1, 0] - 1j * d[:-1, 1])))
        r = 0.5 * (thick - 1)
        for x, y in fine[1:-1][turn > ROUND_TURN].tolist():
            self.draw.ellipse((x - r, y - r, x + r, y + r), fill=255)

    def line(self, flat: list[float], width: float) -> None:
        """Cover a short stroke (a dash) of ``width`` pixels along fine points ``[x0, y0, x1, y1, ...]``."""
        self.draw.line(flat, fill=255, width=max(round(width * SUPERSAMPLE), 1))

    def rectangle(self, x0: float, y0: float, x1: float, y1: float) -> None:
        """Cover the rectangle ``[x0, x1] x [y0, y1]`` (to a sub-pixel)."""
        a = (np.array([[x0, y0], [x1, y1]]) - (self.left, self.top)) * SUPERSAMPLE
        (fx0, fy0), (fx1, fy1) = np.rint(a)
        if fx1 > fx0 and fy1 > fy0:
            self.draw.rectangle((fx0, fy0, fx1 - 1, fy1 - 1), fill=255)

    def rounded(self, x0: float, y0: float, x1: float, y1: float, radius: float, outline: float = 0.0) -> None:
        """Cover a rectangle with corners of ``radius`` pixels (only its border of ``outline`` pixels if > 0)."""
        a = (np.array([x0, y0, x1, y1]) - (self.left, self.top, self.left, self.top)) * SUPERSAMPLE
        width = max(round(outline * SUPERSAMPLE), 1) if outline else 0
        self.draw.rounded_rectangle(np.rint(a).tolist(), radius=radius * SUPERSAMPLE, fill=None if width else 255,
                                    outline=255 if width else None, width=width)

    def blend(self, image, color: RGB, alpha: float = 1.0) -> None:
        """Blend ``color`` into ``image`` by the mask's coverage (times ``alpha``)."""
        coverage = self.image.reduce(SUPERSAMPLE)
        if alpha < 1.0:
            coverage = coverage.point([round(v * alpha) for v in range(256)])
        image.paste(color, (self.left, self.top, self.left + self.width, self.top + self.height), coverage)


def stroke(image, x: np.ndarray, y: np.ndarray, box: tuple[float, float, float, float], width: float, color: RGB,
           dashed: bool = False) -> None:
    """Draw the polyline through canvas points ``(x, y)`` clipped to ``box``, ``width`` pixels wide, anti-aliased."""
    parts = clip_polyline(x, y, box)
    if not parts:
        return
    lows = np.min([p.min(axis=0) for p in parts], axis=0) - width
    highs = np.max([p.max(axis=0) for p in parts], axis=0) + width
    mask = Mask((max(lows[0], box[0]), max(lows[1], box[1]), min(highs[0], box[2]), min(highs[1], box[3])))
    if dashed:
        for part in parts:
            for dash in dash_pieces(mask.fine(part), DASHES[0] * width * SUPERSAMPLE, DASHES[1] * width * SUPERSAMPLE):
                mask.line(dash, width)
    else:
        for part in parts:
            mask.polyline(mask.fine(part), width)
    mask.blend(image, color)
