"""Plot helpers: matplotlib figures on the Agg canvas (no pyplot global state) and what every plot shares.

Figures in fixed margins, backlash shading and the PNG writing of the matplotlib figures
(studies, reports, spectra, load events); envelopes of long curves (every extreme kept),
the labels of the declared mesh kinds and speed units for every plot, also the run figures
drawn by :mod:`orchestrator.raster`. The plots themselves live with their owners
(:mod:`orchestrator.run.plots`, :mod:`orchestrator.run.analysis_plots`,
:mod:`orchestrator.reports`, :mod:`orchestrator.study.plots`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from .atomic_files import atomic_path
from .figure_files import DPI, Margins, axes_size, write_png

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)


#: bins of a curve's min/max envelope where the axes it goes into are not known
ENVELOPE_BINS = 2000


#: a contact force's declared mesh kind (its ``mesh`` detail) -> its label and line style in plots
MESH_KIND_STYLES = {"sun_planet": ("sun-planet", "-"), "ring_planet": ("ring-planet", "--"), "parallel": ("mesh", "-")}


def envelope(t: np.ndarray, y: np.ndarray, bins: int = ENVELOPE_BINS) -> tuple[np.ndarray, np.ndarray]:
    """A curve reduced to the minimum and maximum of each of ``bins`` time bins, in time order.

    With ``bins`` the width of the axes in pixels (:func:`plot_envelope`), drawing
    2 x ``bins`` points instead of every sample looks the same and is faster: every
    extreme is kept. Curves of at most 2 x ``bins`` samples are returned unchanged.
    """
    n = t.size
    if n <= 2 * bins:
        return t, y
    per = n // bins
    m = per * bins
    tb = t[:m].reshape(bins, per)
    yb = y[:m].reshape(bins, per)
    i_min = np.argmin(yb, axis=1)
    i_max = np.argmax(yb, axis=1)
    first = np.minimum(i_min, i_max)
    second = np.maximum(i_min, i_max)
    rows = np.arange(bins)
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    if m < n:
        tt = np.append(tt, t[m:])
        yy = np.append(yy, y[m:])
    return tt, yy


def plot_envelope(ax, t, y, **kwargs) -> None:
    """``ax.plot`` of a curve as its :func:`envelope` at the resolution of ``ax`` (every extreme kept)."""
    ax.plot(*envelope(t, y, axes_pixels(ax)), **kwargs)


def shade_inside_backlash(ax, t: np.ndarray, force: np.ndarray, threshold_n: float, label: str | None = None) -> None:
    """Shade the full height of ``ax`` wherever ``|force| < threshold_n`` (teeth inside the backlash).

    ``t`` [s] and ``force`` [N] at full resolution; ``label`` (default ``inside the
    backlash (|F| < ... N)``) goes into the legend only if something is shaded.
    """
    inside = np.abs(force) < threshold_n
    if inside.any():
        ax.fill_between(t, 0, 1, where=inside, transform=ax.get_xaxis_transform(), color="tab:red", alpha=0.35,
                        lw=0, label=label or f"inside the backlash (|F| < {threshold_n:g} N)")


def _grid(width: float, height: float, rows: int, columns: int, margins: Margins) -> dict[str, float]:
    """The grid parameters (figure fractions) that place ``rows`` x ``columns`` axes by ``margins``."""
    axes_w, axes_h = axes_size(width, height, rows, columns, margins)
    return {"left": margins.left / width, "right": 1.0 - margins.right / width, "bottom": margins.bottom / height,
            "top": 1.0 - margins.top / height, "hspace": margins.hspace / axes_h, "wspace": margins.wspace / axes_w}


def _subplots(fig, rows: int, columns: int, sharex, margins: Margins | None):
    """``fig.subplots`` with the grid placed by ``margins`` (None: constrained layout decides)."""
    if margins is None:
        fig.set_layout_engine("constrained")
        return fig.subplots(rows, columns, sharex=sharex, squeeze=False)
    from matplotlib import rc_context
    from matplotlib.transforms import offset_copy

    grid = _grid(*fig.get_size_inches(), rows, columns, margins)
    # titles right above the axes: placed automatically, each draw measures the axes' tick labels to lift it
    with rc_context({"axes.titley": 1.0}):
        axes = fig.subplots(rows, columns, sharex=sharex, squeeze=False, gridspec_kw=grid)
    for ax in axes.flat:
        ax.xaxis.set_label_coords(0.5, 0.0, offset_copy(ax.transAxes, fig, y=-margins.xlabel_gap, units="inches"))
        ax.yaxis.set_label_coords(0.0, 0.5, offset_copy(ax.transAxes, fig, x=-margins.ylabel_gap, units="inches"))
    return axes


def _no_property_table(artist) -> str:
    return ""


def import_matplotlib() -> None:
    """Import matplotlib's figure and Agg canvas, without the property tables of its docstrings.

    Every artist class matplotlib defines builds, as it is defined, the docstring of its
    ``set`` method: a table of all its properties (``matplotlib.artist.kwdoc``), a fifth of
    the import's ~0.3 s. Nothing here reads a docstring, so while this imports matplotlib the
    tables are left empty; the classes, their signatures and everything they draw are the
    same. Where matplotlib is imported already (or ``kwdoc`` is gone) it is imported as it is.
    """
    import sys

    if "matplotlib.figure" in sys.modules and "matplotlib.backends.backend_agg" in sys.modules:
        return
    import matplotlib.artist as artist

    kwdoc = getattr(artist, "kwdoc", None)
    if kwdoc is not None:
        artist.kwdoc = _no_property_table
    try:
        import matplotlib.backends.backend_agg  # noqa: F401
        import matplotlib.figure  # noqa: F401
    finally:
        if kwdoc is not None:
            artist.kwdoc = kwdoc


def _figure(width: float, height: float):
    """A figure on its own Agg canvas (no pyplot: no global state, nothing to close)."""
    import_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def new_figure(rows: int = 1, height: float = 4.0, sharex: bool = True, width: float = 10.0,
               margins: Margins | None = None):
    """A headless figure of ``rows`` stacked axes, ``width`` x ``height`` inches: (figure, axes array).

    ``margins`` fixes the layout (see :class:`~orchestrator.figure_files.Margins`); without, matplotlib's constrained
    layout places the axes (for figures whose labels and legends vary).
    """
    fig = _figure(width, height)
    return fig, _subplots(fig, rows, 1, sharex, margins)[:, 0]


def axes_pixels(ax) -> int:
    """Width of ``ax`` on the canvas [pixels]: the resolution at which its curves are drawn."""
    fig = ax.get_figure(root=True)
    return max(int(ax.get_position().width * fig.get_figwidth() * fig.dpi), 1)


#: how text is rendered: FreeType's outlines unhinted (matplotlib's default auto-hints every glyph: the
#: text then costs about a fifth more for no better reading at 110 dpi)
TEXT_RENDERING = {"text.hinting": "no_hinting"}


def encode_png(canvas, path: Path) -> None:
    """Write a drawn Agg canvas as an 8-bit palette PNG (:func:`orchestrator.figure_files.write_png`)."""
    from PIL import Image

    width, height = canvas.get_width_height(physical=True)
    write_png(Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(), "raw", "RGBA", 0, 1), path)


def save_figure(fig, path: Path) -> Path:
    """Draw the figure once (text as :data:`TEXT_RENDERING`) and write it as PNG (temporary file and rename)."""
    from matplotlib import rc_context

    with rc_context(TEXT_RENDERING):
        fig.canvas.draw()
    with atomic_path(path) as tmp:
        encode_png(fig.canvas, tmp)
    return path


def close_figure(fig, path: str | Path) -> Path:
    """Write a pyplot figure as PNG (tight bounding box, 120 dpi), close it and return ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    import matplotlib.pyplot as plt

    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=120, bbox_inches="tight")
    finally:
        plt.close(fig)
    return path
