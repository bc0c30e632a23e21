"""PNG plots of a run's analyses: contact-force spectra, load duration distributions, load events.

matplotlib's figure API on the Agg canvas (no display, no pyplot), each figure in a
fixed layout drawn once (:mod:`orchestrator.plotting`); the load duration distributions,
drawn by every run, by the run figures' own renderer (:mod:`orchestrator.raster`). Every function takes the
plain result objects of :mod:`components.analysis.fatigue` and
:mod:`components.analysis.spectrum` (or arrays) and a path, writes one PNG and returns the path.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from components.analysis.load_duration import LoadDurationDistribution
from components.analysis.spectrum import amplitude_spectrum

from ..figure_files import Margins
from ..plotting import axes_pixels, envelope, new_figure, save_figure, shade_inside_backlash
from ..raster.figure import Figure as RasterFigure
from ..raster.figure import save_figure as save_raster_figure

#: a title above and an x label below every panel
_PANEL_MARGINS = Margins(top=0.35, hspace=0.75)
#: panels sharing the time axis under one title
_STACK_MARGINS = Margins(top=0.4, hspace=0.15)


def plot_force_spectra(
    time_s: np.ndarray,
    series: Mapping[str, np.ndarray],
    path: str | Path,
    mesh_frequencies_hz: Mapping[str, float] | None = None,
    window: tuple[float, float] | None = None,
    max_frequency_hz: float | None = None,
) -> Path:
    """Amplitude spectra (Hann window) of contact forces, with the mesh frequencies marked.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Uniform sample times [s].
    series : mapping name -> ndarray, shape (N,)
        Contact forces [N] (one panel each).
    path : str or Path
    mesh_frequencies_hz : mapping label -> float, optional
        Vertical markers, e.g. ``{"stage3 mesh": 426.7}``.
    window : (float, float), optional
        Analysed window [s].
    max_frequency_hz : float, optional
        Upper frequency limit of the plot.
    """
    t = np.asarray(time_s, dtype=float)
    sel = np.ones(t.size, bool) if window is None else (t >= window[0]) & (t <= window[1])
    dt = float(np.median(np.diff(t[sel])))
    fig, axes = new_figure(len(series), height=2.6 * len(series) + 0.4, sharex=False, margins=_PANEL_MARGINS)
    for ax, (name, x) in zip(axes, series.items()):
        f, amp = amplitude_spectrum(np.asarray(x)[sel], dt)
        if max_frequency_hz:  # only the shown band, drawn as its envelope (every peak kept)
            band = f <= max_frequency_hz * 1.001
            f, amp = f[band], amp[band]
        ax.semilogy(*envelope(f[1:], np.maximum(amp[1:], 1e-12), axes_pixels(ax)), lw=0.8, color="black")
        for k, (label, fm) in enumerate((mesh_frequencies_hz or {}).items()):
            ax.axvline(fm, ls="--", lw=1.0, color=f"C{k % 10}", label=f"{label} {fm:.4g} Hz")
        ax.set_ylabel(f"|{name}| [N]")
        ax.set_xlim(0.0, max_frequency_hz or f[-1])
        ax.grid(True, which="both", alpha=0.25)
        if mesh_frequencies_hz:
            ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("frequency [Hz]")
    fig.suptitle(f"Contact-force amplitude spectra (Hann window, {t[sel][-1] - t[sel][0]:.3g} s, "
                 f"resolution {1.0 / (t[sel][-1] - t[sel][0]):.3g} Hz)", fontsize=10)
    return save_figure(fig, Path(path))


def plot_load_duration(ldds: Sequence[LoadDurationDistribution], path: str | Path) -> Path:
    """Load duration distributions (time per load bin, log scale), one panel per signal.

    Torques are drawn in kN m (forces in kN); the log time axis shows the rare extreme
    loads (e.g. of a load event) next to the hours-equivalent of normal operation. Drawn by
    the run figures' renderer (:mod:`orchestrator.raster`): every run draws it.
    """
    fig = RasterFigure(10.0, 2.5 * len(ldds) + 0.2, rows=len(ldds), margins=_PANEL_MARGINS)
    for (ax,), ld in zip(fig.axes, ldds):
        scale, unit = (1e-3, "kN m") if ld.unit in ("N.m", "N m") else (1e-3, "kN") if ld.unit == "N" else (1.0, ld.unit)
        edges = ld.edges * scale
        keep = ld.time_s > 0.0
        ax.yscale = "log"  # decades labelled as plain numbers, minor lines at 2 and 5
        if keep.any():  # one bar per non-empty bin, from the axis' bottom up
            time_s = ld.time_s[keep]
            low, high = float(time_s.min()), float(time_s.max())
            ax.bar(edges[:-1][keep], edges[1:][keep], time_s, color="tab:blue")
            ax.ylim = (10.0 ** np.floor(np.log10(low) - 0.05), high * 10.0 ** 0.1)
        ax.xlim = (float(edges[0]), float(edges[-1]))
        ax.xlabel = f"{ld.name} [{unit}]"
        ax.ylabel = "time in bin [s]"
        extra = f", {ld.time_outside_s:.3g} s outside the bins" if ld.time_outside_s > 0 else ""
        ax.set_title(f"{ld.name}: load duration distribution ({ld.analysed_time_s:.4g} s analysed, "
                     f"{edges.size - 1} bins of {np.diff(edges).mean():.3g} {unit}{extra})", size_pt=9.0)
        ax.grid(alpha=0.25, minor=True)
    return save_raster_figure(fig, Path(path))


def plot_event_response(
    time_s: np.ndarray,
    torques: Mapping[str, np.ndarray],
    forces: Mapping[str, np.ndarray],
    events: Sequence[tuple[str, float, float]],
    path: str | Path,
    threshold_n: float = 1.0,
    span: tuple[float, float] | None = None,
) -> Path:
    """Drivetrain response to generator load events: torques on top, one contact force per panel below.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Sample times [s].
    torques : mapping name -> ndarray, shape (N,)
        Torques [N m] drawn in the top panel (e.g. generator counter torque, shaft-3 torque).
    forces : mapping name -> ndarray, shape (N,)
        Contact forces [N], one panel each; the time inside the backlash
        (``|F| < threshold_n``) is shaded red.
    events : sequence of (label, start [s], end [s])
        Shaded in every panel (end may be inf).
    path : str or Path
    threshold_n : float
        Contact-loss threshold [N].
    span : (float, float), optional
        Time range shown [s]; default from 0.5 s before the first event to 2.5 s after the last end.
    """
    t = np.asarray(time_s, dtype=float)
    if span is None:
        first = min(e[1] for e in events)
        last = max(min(e[2], e[1] + 3.0) for e in events)
        span = (max(t[0], first - 0.5), min(t[-1], last + 2.5))
    sel = (t >= span[0]) & (t <= span[1])
    ts = t[sel]
    n = 1 + len(forces)
    fig, axes = new_figure(n, height=2.3 * n + 0.6, margins=_STACK_MARGINS)
    for ax in axes:
        for k, (label, a, b) in enumerate(events):
            ax.axvspan(a, min(b, span[1]), color="gold", alpha=0.25, lw=0, label=label if ax is axes[0] else None)
        ax.grid(True, alpha=0.3)
    for k, (name, y) in enumerate(torques.items()):
        axes[0].plot(ts, np.asarray(y)[sel] * 1e-3, lw=1.2, color=f"C{k % 10}", label=name)
    axes[0].axhline(0.0, color="black", lw=0.6)
    axes[0].set_ylabel("torque [kN m]")
    axes[0].legend(fontsize=7.5, loc="upper right", ncol=2)
    for ax, (name, y) in zip(axes[1:], forces.items()):
        f = np.asarray(y)[sel]
        ax.plot(ts, f * 1e-3, lw=1.0, color="black", label=name)
        ax.axhline(0.0, color="black", lw=0.6)
        shade_inside_backlash(ax, ts, f, threshold_n)
        ax.set_ylabel("force [kN]")
        ax.legend(fontsize=7.5, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_xlim(*span)
    fig.suptitle("Response to generator load events (torques and one contact force per stage)", fontsize=10)
    return save_figure(fig, Path(path))
