"""Plots of a study's measures over its grid: heat maps (two axes) and line plots (one axis).

A heat map shows one measure over two axes of the grid (Fig. 12 and 13 of the
paper: I_max,acc and CPU time over R1 x lambda), every cell annotated with its
value; the colour bar carries the measure's unit. Where several points fall in
one cell (seeds, explicit points, further axes) the cell shows their mean (for a
damage-equivalent load ``del<m>`` the damage-consistent ``(mean DEL^m)^(1/m)``)
and says so. Cells of failed points are hatched grey and marked "failed"; cells not
run yet are blank. With one axis, a line plot shows every point and the mean.

Each ``[[plots]]`` entry of the study gives one PNG; without any, every measure
is plotted over the first two axes (or the only one).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from components.validation import is_number

from ..atomic_files import atomic_path
from ..inputs.measures import wohler_exponent_of
from ..inputs.study import PlotSpec

_UNIT_TEXT = {"rad/s2": "rad/s²", "N.m": "N m", "1": "-", "kg.m2": "kg m²"}


def unit_text(unit: str) -> str:
    """A unit as printed on plots (``rad/s2`` -> ``rad/s²``)."""
    return _UNIT_TEXT.get(unit, unit)


def compact(value: float) -> str:
    """A value in at most ~6 characters for a heat-map cell (3 significant digits)."""
    if value is None or not math.isfinite(value):
        return "-"
    a = abs(value)
    if a != 0 and (a >= 1e4 or a < 1e-2):
        mant, exp = f"{value:.2e}".split("e")
        return f"{mant}e{int(exp)}"
    return f"{value:.3g}"


def _tick(value) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def plot_specs(study) -> list[PlotSpec]:
    """The study's ``[[plots]]``, or one plot per measure if it gives none (needs an axis)."""
    if study.plots:
        return list(study.plots)
    if not study.axes:
        return []
    return [PlotSpec(measure=m.name) for m in study.measures]


def cell_exponent(measure: str) -> float:
    """Power of the per-cell mean: ``m`` for a damage-equivalent load ``...:del<m>``, else 1.

    Runs of equal length add damage, so the DEL of a cell of n runs is
    ``(sum DEL_i^m / n)^(1/m)``, not the arithmetic mean of the DELs.
    """
    return wohler_exponent_of(measure.rpartition(":")[2]) or 1.0


def grid(prepared, recs, measure: str, x: int, y: int | None):
    """Cell means of a measure over axes x (and y).

    Returns
    -------
    mean : ndarray, shape (ny, nx)
        Mean of the ``ok`` points of each cell (NaN: none); for a ``del<m>``
        measure the damage-equivalent mean ``(mean DEL^m)^(1/m)`` (:func:`cell_exponent`).
    count : ndarray of int, shape (ny, nx)
        Number of ``ok`` points per cell.
    failed : ndarray of int, shape (ny, nx)
        Number of failed (or errored) points per cell.
    """
    study = prepared.study
    p = cell_exponent(measure)
    nx = len(study.axes[x].values)
    ny = 1 if y is None else len(study.axes[y].values)
    total = np.zeros((ny, nx))
    count = np.zeros((ny, nx), dtype=int)
    failed = np.zeros((ny, nx), dtype=int)
    for point, rec in zip(prepared.points, recs):
        if rec is None:
            continue
        i = point.coords[1 + x]
        j = 0 if y is None else point.coords[1 + y]
        value = (rec.get("measures") or {}).get(measure)
        if rec["status"] == "ok" and value is not None and math.isfinite(value):
            total[j, i] += value if p == 1.0 else abs(value) ** p
            count[j, i] += 1
        elif rec["status"] != "ok":
            failed[j, i] += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    if p != 1.0:
        mean = mean ** (1.0 / p)
    return mean, count, failed


def _title(text: str, per_cell: int, width_in: float, measure: str = "") -> str:
    """A plot title wrapped to the figure width, noting the runs averaged per cell."""
    import textwrap

    if per_cell > 1:
        p = cell_exponent(measure)
        text += (f" (mean of {per_cell} runs per cell)" if p == 1.0 else
                 f" ({per_cell} runs per cell combined as (mean DEL^{p:g})^(1/{p:g}))")
    return "\n".join(textwrap.wrap(text, width=max(30, int(width_in * 11))))


def _per_cell(study, x: int, y: int | None) -> int:
    """Points that share one cell of the plot."""
    n = study.n_points // len(study.axes[x].values)
    return n if y is None else n // len(study.axes[y].values)


def heatmap(prepared, recs, spec: PlotSpec, path: Path) -> Path:
    """One heat map (see the module docstring); returns ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, Normalize
    from matplotlib.ticker import ScalarFormatter

    study = prepared.study
    m = study.measure(spec.measure)
    ax_x, ax_y = study.axes[spec.x], study.axes[spec.y]
    mean, count, failed = grid(prepared, recs, m.name, spec.x, spec.y)
    ny, nx = mean.shape
    width = max(5.5, 0.95 * nx + 2.6)
    fig, ax = plt.subplots(figsize=(width, max(3.6, 0.5 * ny + 1.9)), constrained_layout=True)
    finite = mean[np.isfinite(mean)]
    lo = spec.vmin if spec.vmin is not None else (float(finite.min()) if finite.size else 0.0)
    hi = spec.vmax if spec.vmax is not None else (float(finite.max()) if finite.size else 1.0)
    if not hi > lo:  # one value (or none): a band around it
        span = 0.05 * abs(lo) or 1.0
        lo, hi = (lo - span if spec.vmin is None else lo), (hi + span if spec.vmax is None else hi)
    if spec.log and lo > 0:
        norm = LogNorm(vmin=lo, vmax=hi)
    else:
        norm = Normalize(vmin=lo, vmax=hi)
    cmap = plt.get_cmap("viridis").with_extremes(bad="#f2f2f2")
    im = ax.imshow(np.ma.masked_invalid(mean), origin="lower", aspect="auto", cmap=cmap, norm=norm,
                   interpolation="nearest")
    for j in range(ny):
        for i in range(nx):
            if count[j, i]:
                r, g, b, _ = cmap(float(np.clip(norm(mean[j, i]), 0.0, 1.0)))
                colour = "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.55 else "white"
                ax.text(i, j, compact(mean[j, i]), ha="center", va="center", fontsize=8.5, color=colour)
            elif failed[j, i]:
                ax.add_patch(plt.Rectangle((i - 0.5, j - 0.5), 1, 1, facecolor="#bdbdbd", hatch="//",
                                           edgecolor="#7f7f7f", linewidth=0))
                ax.text(i, j, "failed", ha="center", va="center", fontsize=8, color="#b00020")
            else:
                ax.text(i, j, "not run", ha="center", va="center", fontsize=7.5, color="#9e9e9e")
    ax.set_xticks(range(nx), [_tick(ax_x.display(v)) for v in ax_x.values])
    ax.set_yticks(range(ny), [_tick(ax_y.display(v)) for v in ax_y.values])
    ax.set_xlabel(ax_x.axis_label)
    ax.set_ylabel(ax_y.axis_label)
    bar = fig.colorbar(im, ax=ax, pad=0.02)
    bar.set_label(f"{m.name} [{unit_text(m.unit)}]")
    if not spec.log:
        bar.formatter = ScalarFormatter(useOffset=False)
        bar.formatter.set_powerlimits((-3, 4))
        bar.update_ticks()
    ax.set_title(_title(spec.title or f"{study.name}: {m.description}", _per_cell(study, spec.x, spec.y), width, m.name),
                 fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=130)
    plt.close(fig)
    return path


def line_plot(prepared, recs, spec: PlotSpec, path: Path) -> Path:
    """A measure over one axis: every ok point and the mean per axis value; returns ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    study = prepared.study
    m = study.measure(spec.measure)
    axis = study.axes[spec.x]
    xs = [axis.display(v) for v in axis.values]
    numeric = all(is_number(v) for v in xs)
    pos = xs if numeric else list(range(len(xs)))
    fig, ax = plt.subplots(figsize=(6.4, 4.2), constrained_layout=True)
    px, py, fx = [], [], []
    for point, rec in zip(prepared.points, recs):
        if rec is None:
            continue
        k = point.coords[1 + spec.x]
        value = (rec.get("measures") or {}).get(m.name)
        if rec["status"] == "ok" and value is not None:
            px.append(pos[k])
            py.append(value)
        elif rec["status"] != "ok":
            fx.append(pos[k])
    mean, count, failed = grid(prepared, recs, m.name, spec.x, None)
    ax.plot(px, py, "o", color="#1f77b4", alpha=0.5, label="runs")
    ok = count[0] > 0
    ax.plot(np.asarray(pos)[ok], mean[0][ok], "-", color="#1f77b4",
            label="mean" if cell_exponent(m.name) == 1.0 else "damage-equivalent mean")
    if fx:
        ax.plot(fx, [ax.get_ylim()[0]] * len(fx), "x", color="#b00020", label="failed")
    if not numeric:
        ax.set_xticks(pos, [str(v) for v in xs])
    if spec.log:
        ax.set_yscale("log")
    if spec.vmin is not None or spec.vmax is not None:
        ax.set_ylim(spec.vmin, spec.vmax)
    ax.set_xlabel(axis.axis_label)
    ax.set_ylabel(f"{m.name} [{unit_text(m.unit)}]")
    ax.set_title(_title(spec.title or f"{study.name}: {m.description}", _per_cell(study, spec.x, None), 6.4, m.name),
                 fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=130)
    plt.close(fig)
    return path


def plot_study(prepared, recs, out_dir: str | Path) -> list[Path]:
    """Write every plot of the study into ``out_dir``; returns the PNG files."""
    out = Path(out_dir)
    study = prepared.study
    files = []
    for spec in plot_specs(study):
        two = len(study.axes) >= 2
        name = spec.file or f"{'heatmap' if two else 'plot'}_{spec.measure.replace(':', '_').replace('.', '_')}.png"
        name = name.replace("[", "").replace("]", "")
        path = out / name
        files.append(heatmap(prepared, recs, spec, path) if two else line_plot(prepared, recs, spec, path))
    return files
