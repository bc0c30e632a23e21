"""Plot helpers shared by every PNG dtcosim writes (matplotlib Agg canvas, no pyplot global state).

Figures, envelopes of long curves (every extreme kept), backlash shading and the
labels of the declared mesh kinds; the plots themselves live with their owners
(:mod:`orchestrator.run.plots`, :mod:`orchestrator.run.analysis_plots`,
:mod:`orchestrator.reports`, :mod:`orchestrator.study.plots`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .atomic_files import atomic_path

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)


#: above this many samples a curve is drawn as its min/max envelope over this many bins
ENVELOPE_BINS = 2000


#: a contact force's declared mesh kind (its ``mesh`` detail) -> its label and line style in plots
MESH_KIND_STYLES = {"sun_planet": ("sun-planet", "-"), "ring_planet": ("ring-planet", "--"), "parallel": ("mesh", "-")}


def envelope(t: np.ndarray, y: np.ndarray, bins: int = ENVELOPE_BINS) -> tuple[np.ndarray, np.ndarray]:
    """A curve reduced to the minimum and maximum of each of ``bins`` time bins, in time order.

    Drawing 2 x ``bins`` points instead of every sample is much faster and looks the
    same at screen resolution: every extreme is kept. Curves with fewer than
    4 x ``bins`` samples are returned unchanged.
    """
    n = t.size
    if n < 4 * bins:
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
    """``ax.plot`` of a long curve as its :func:`envelope` (every extreme kept)."""
    ax.plot(*envelope(t, y), **kwargs)


def shade_inside_backlash(ax, t: np.ndarray, force: np.ndarray, threshold_n: float, label: str | None = None) -> None:
    """Shade the full height of ``ax`` wherever ``|force| < threshold_n`` (teeth inside the backlash).

    ``t`` [s] and ``force`` [N] at full resolution; ``label`` (default ``inside the
    backlash (|F| < ... N)``) goes into the legend only if something is shaded.
    """
    inside = np.abs(force) < threshold_n
    if inside.any():
        ax.fill_between(t, 0, 1, where=inside, transform=ax.get_xaxis_transform(), color="tab:red", alpha=0.35,
                        lw=0, label=label or f"inside the backlash (|F| < {threshold_n:g} N)")


def new_figure(rows: int = 1, height: float = 4.0, sharex: bool = True, width: float = 10.0):
    """A headless figure of ``rows`` stacked axes, ``width`` x ``height`` inches: (figure, axes array)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 1, sharex=sharex, squeeze=False)[:, 0]
    return fig, axes


def new_grid(rows: int, columns: int, height: float, width: float, sharex: str | bool = "col"):
    """A headless figure of ``rows`` x ``columns`` axes: (figure, 2-D axes array)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.subplots(rows, columns, sharex=sharex, squeeze=False)


def save_figure(fig, path: Path) -> Path:
    """Write the figure as PNG (temporary file and rename); returns ``path``."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
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
