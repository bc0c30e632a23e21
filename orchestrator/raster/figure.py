"""A run figure: a grid of axes in fixed margins, a title over it, laid out once, drawn once, written as PNG.

The margins (:class:`~orchestrator.figure_files.Margins`) are the least space around and
between the axes; the layout measures every text (it costs microseconds here) and widens a
margin where its text needs more: tick labels longer than planned, an offset text, a legend
beside the axes (the right margin takes the widest; a legend meant for the best place inside
goes there where every place inside would hide data). Axes sharing their x axis (``sharex``)
share its limits and show tick labels only on the bottom row.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..atomic_files import atomic_path
from ..figure_files import DPI, Margins, axes_size, write_png
from .axes import Axes
from .legend import Legend
from .text import Text

#: text of a figure's title (matplotlib's "large")
SUPTITLE_PT = 12.0
#: the top of the figure's title, as a share of the figure's height from its top
SUPTITLE_Y = 0.02
#: space kept between a margin's text and what is next to it [inches]
GAP = 0.03
#: a legend beside the axes is this much further from the figure's edge [inches]
LEGEND_ROOM = 0.05


class Figure:
    """``rows`` x ``columns`` axes (:attr:`axes`, a list of rows) on a ``width`` x ``height`` inch canvas."""

    def __init__(self, width: float, height: float, rows: int = 1, columns: int = 1, margins: Margins = Margins(),
                 sharex: str | None = None):
        if sharex not in (None, "col", "all"):
            raise ValueError(f"sharex is None, 'col' or 'all', not {sharex!r}")
        self.width, self.height = width, height
        self.rows, self.columns = rows, columns
        self.margins = margins
        self.sharex = sharex
        self.axes = [[Axes() for _ in range(columns)] for _ in range(rows)]
        if sharex:
            for row in self.axes[:-1]:
                for ax in row:
                    ax.x_tick_labels = False
        self.suptitle: Text | None = None
        self.used_margins = margins

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the canvas [pixels]."""
        return round(self.width * DPI), round(self.height * DPI)

    def axes_pixels(self) -> int:
        """Width of each axes at the figure's margins [pixels]: the resolution to draw curves at."""
        return max(int(axes_size(self.width, self.height, self.rows, self.columns, self.margins)[0] * DPI), 1)

    def set_suptitle(self, text: str, size_pt: float = SUPTITLE_PT) -> None:
        """A title over all the axes (lines split at ``\\n``), centred at the top."""
        self.suptitle = Text(text, 0.5 * self.size[0], SUPTITLE_Y * self.size[1], size_pt, ha="center", va="top",
                             role="suptitle")

    def flat(self) -> list[Axes]:
        return [ax for row in self.axes for ax in row]

    def texts(self) -> list[Text]:
        """Every text of the laid-out figure."""
        return [t for ax in self.flat() for t in ax.texts] + ([self.suptitle] if self.suptitle else [])

    def _share_limits(self) -> None:
        if not self.sharex:
            return
        groups = [[row[c] for row in self.axes] for c in range(self.columns)] if self.sharex == "col" \
            else [self.flat()]
        for group in groups:
            given = {ax.xlim for ax in group if ax.xlim is not None}
            if len(given) > 1:
                raise ValueError(f"axes sharing their x axis were given different limits: {sorted(given)}")
            limits = given.pop() if given else None
            if limits is None:  # the range of all their content
                probe = Axes()
                probe.lines = [line for ax in group for line in ax.lines]
                probe.spans = [s for ax in group for s in ax.spans]
                probe.bars = [b for ax in group for b in ax.bars]
                limits = probe.data_limits()[0]
            for ax in group:
                ax.xlim = limits

    def _boxes(self, margins: Margins) -> list[list[tuple[float, float, float, float]]]:
        axes_w, axes_h = axes_size(self.width, self.height, self.rows, self.columns, margins)
        boxes = []
        for r in range(self.rows):
            top = margins.top + r * (axes_h + margins.hspace)
            row = []
            for c in range(self.columns):
                left = margins.left + c * (axes_w + margins.wspace)
                row.append((left * DPI, top * DPI, (left + axes_w) * DPI, (top + axes_h) * DPI))
            boxes.append(row)
        return boxes

    def _needed(self) -> Margins:
        """The margins the laid-out text needs [inches] (at least the figure's own)."""
        outer = [[ax.outer_box() for ax in row] for row in self.axes]
        box = [[ax.box for ax in row] for row in self.axes]

        def most(values) -> float:
            return max(values) / DPI + GAP

        left = most(box[r][0][0] - outer[r][0][0] for r in range(self.rows))
        right = most(outer[r][-1][2] - box[r][-1][2] for r in range(self.rows))
        top = most(box[0][c][1] - outer[0][c][1] for c in range(self.columns))
        if self.suptitle is not None:
            top += self.suptitle.box[3] / DPI
        bottom = most(outer[-1][c][3] - box[-1][c][3] for c in range(self.columns))
        wspace = max([most(box[r][c][0] - outer[r][c][0] + outer[r][c - 1][2] - box[r][c - 1][2]
                           for r in range(self.rows)) for c in range(1, self.columns)], default=0.0)
        hspace = max([most(box[r][c][1] - outer[r][c][1] + outer[r - 1][c][3] - box[r - 1][c][3]
                           for c in range(self.columns)) for r in range(1, self.rows)], default=0.0)
        m = self.used_margins
        return replace(m, left=max(m.left, left), right=max(m.right, right), top=max(m.top, top),
                       bottom=max(m.bottom, bottom), wspace=max(m.wspace, wspace), hspace=max(m.hspace, hspace))

    def lay_out(self) -> None:
        """Place every axes, tick, text and legend; widen the margins where the text needs it.

        A legend to go at the best place inside its axes goes beside them where every place
        inside would hide some of the lines; the layout is then done again.
        """
        self._share_limits()
        for ax in self.flat():
            ax.legend_beside = bool(ax.legend_style) and ax.legend_style[0] == "beside"
        while True:
            self._lay_out_in(self._legend_room(self.margins))
            hiding = [ax for ax in self.flat() if ax.legend is not None and ax.legend.hidden]
            if not hiding:
                return
            for ax in hiding:
                ax.legend_beside = True

    def _legend_room(self, margins: Margins) -> Margins:
        """``margins`` with the right one widened to the widest legend beside the axes."""
        beside = [ax for ax in self.flat() if ax.legend_beside and ax.legend_entries()]
        if not beside:
            return margins
        widest = max(Legend(ax.legend_entries(), ax.legend_style[1]).extent()[0] for ax in beside)
        return replace(margins, right=margins.right + widest / DPI + LEGEND_ROOM)

    def _lay_out_in(self, margins: Margins) -> None:
        """Lay the axes out in ``margins``, widened (up to three times) where their text needs more."""
        self.used_margins = margins
        for attempt in range(4):  # a wider margin can change the ticks of the narrower axes: again
            for row, boxes in zip(self.axes, self._boxes(self.used_margins)):
                for ax, box in zip(row, boxes):
                    ax.lay_out(box)
            needed = self._needed()
            if needed == self.used_margins or attempt == 3:
                return
            self.used_margins = needed

    def render(self):
        """The laid-out figure drawn on an RGB ``PIL.Image``: axes content, then all text on top."""
        from PIL import Image

        self.lay_out()
        image = Image.new("RGB", self.size, (255, 255, 255))
        for ax in self.flat():
            ax.draw(image)
        for text in self.texts():
            text.draw(image)
        return image


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Lay out and draw ``fig`` and write it as a palette PNG (a temporary file, then renamed); returns the path."""
    path = Path(path)
    image = fig.render()
    with atomic_path(path) as tmp:
        write_png(image, tmp)
    return path
