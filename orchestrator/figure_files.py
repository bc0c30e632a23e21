"""What every figure file dtcosim draws shares: 110 dpi, fixed margins, 8-bit palette PNG at fast zlib.

Both ways a figure is drawn use it: matplotlib's Agg canvas (:mod:`orchestrator.plotting`,
every study, report and analysis figure) and the run figures' own renderer
(:mod:`orchestrator.raster`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

#: resolution of every PNG [pixels per inch]
DPI = 110

#: zlib level of the PNG files: 1 costs about a third of the default 6's time; the palette keeps them small
PNG_COMPRESS_LEVEL = 1


@dataclass(frozen=True)
class Margins:
    """Fixed space around and between the axes of a figure [inches]: the layout of a figure drawn once.

    A layout engine (matplotlib's constrained layout) measures every label before the
    real drawing and so draws the text of a figure twice; the figures of every run know
    their labels and take fixed margins instead (:func:`orchestrator.plotting.new_figure`),
    wide enough for tick labels of up to seven characters (a common offset or power of ten
    leaves the labels), with matplotlib's axis labels at fixed distances from the axes
    (``xlabel_gap``, ``ylabel_gap``; placed automatically, every drawing measures the tick
    labels again). The run figures' renderer measures its text as it lays it out
    (:class:`orchestrator.raster.figure.Figure`): it places the axis labels beside the tick labels
    and takes these margins as the least space, widened where its text needs more.
    """

    left: float = 0.85
    right: float = 0.2
    bottom: float = 0.55
    top: float = 0.4
    hspace: float = 0.3
    wspace: float = 0.8
    xlabel_gap: float = 0.27
    ylabel_gap: float = 0.64


def axes_size(width: float, height: float, rows: int, columns: int, margins: Margins) -> tuple[float, float]:
    """(width, height) of each of ``rows`` x ``columns`` axes placed by ``margins`` in a figure [inches]."""
    axes_w = (width - margins.left - margins.right - (columns - 1) * margins.wspace) / columns
    axes_h = (height - margins.top - margins.bottom - (rows - 1) * margins.hspace) / rows
    if axes_w <= 0.0 or axes_h <= 0.0:
        raise ValueError(f"a {width:g} x {height:g} in figure has no room for {rows} x {columns} axes within {margins}")
    return axes_w, axes_h


def write_png(image, path: Path) -> None:
    """Write a drawn RGB or RGBA ``PIL.Image`` as an 8-bit palette PNG of :data:`DPI`.

    A plot has few colours (lines, shades and their anti-aliased edges): an adaptive
    palette of 256 (``FASTOCTREE``, straight from the pixels) holds them, and the file is
    about a third of the RGBA one, for about half its encoding time.
    """
    from PIL import Image

    image = image.quantize(256, method=Image.Quantize.FASTOCTREE)
    image.save(path, format="png", compress_level=PNG_COMPRESS_LEVEL, dpi=(DPI, DPI))
