"""PNG plots of a drivetrain run, drawn by the run figures' own renderer (:mod:`orchestrator.raster`).

* ``rotor_speed.png`` - rotor speed over time, the wind description (paper Fig. 15);
* ``generator_speed.png`` - generator speed against the ideal gearbox, ratio x rotor
  speed, with their relative difference below (Fig. 16);
* ``contact_forces.png`` - every contact force, one row per stage: the whole run
  and the analysis window alone; identical planet meshes drawn once (Fig. 17).

The variables come from the components' declared roles and signals
(:mod:`orchestrator.cosim.roles`); a plot whose signals are not declared or not
recorded is skipped and :func:`plot_run` says why. The analysis window is shaded.
Curves are drawn as their min/max envelope at the axes' resolution (every extreme kept).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..cosim.outcome import RunOutcome
from ..cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE, ComponentRole
from ..cosim.resolved import ResolvedSystem
from ..figure_files import Margins
from ..plotting import MESH_KIND_STYLES, RPM_PER_RAD_S, envelope
from ..raster.axes import Axes
from ..raster.figure import Figure, save_figure
from .derived import Skipped, generator_vs_ideal, single_role
from .memory import release_between_phases


#: the least space around the axes of the figures (see :class:`~orchestrator.figure_files.Margins`)
_SPEED_MARGINS = Margins()
#: contact forces: a title above every row, the window's axes with their own tick labels
_FORCE_MARGINS = Margins(top=0.75, hspace=0.4, wspace=0.9)


def _shade_window(ax: Axes, window) -> None:
    ax.span(window[0], window[1], color="0.93", label=f"analysis window {window[0]:g}-{window[1]:g} s")


def plot_rotor_speed(outcome: RunOutcome, column: str, window, path: Path, title_suffix: str = "") -> Path:
    """Rotor speed [rpm] over time (Fig. 15)."""
    t = outcome.time_s
    w = outcome.column(column) * RPM_PER_RAD_S
    fig = Figure(10.0, 4.0, margins=_SPEED_MARGINS)
    (ax,) = fig.axes[0]
    _shade_window(ax, window)
    ax.curve(*envelope(t, w, fig.axes_pixels()), width_pt=0.8, color="C0", label=f"rotor speed {column}")
    sel = (t >= window[0]) & (t <= window[1])
    if sel.any():
        mean = float(w[sel].mean())
        ax.hline(mean, color="C3", width_pt=1.0, dashed=True, label=f"mean over window: {mean:.4g} rpm")
    ax.xlabel, ax.ylabel = "time [s]", "rotor speed [rpm]"
    ax.set_title("Rotor speed: stochastic wind description, eq. 13-14 (paper Fig. 15)" + title_suffix)
    ax.grid(width_pt=0.3)
    ax.set_legend("best", 8.0)
    ax.xlim = (float(t[0]), float(t[-1]))
    return save_figure(fig, path)


def plot_generator_speed(outcome: RunOutcome, rotor_column: str, gen_column: str, ratio: float, window,
                         path: Path, title_suffix: str = "") -> Path:
    """Generator speed against ratio x rotor speed, and their relative difference (Fig. 16)."""
    t = outcome.time_s
    gen = outcome.column(gen_column) * RPM_PER_RAD_S
    ideal = ratio * outcome.column(rotor_column) * RPM_PER_RAD_S
    fig = Figure(10.0, 6.0, rows=2, margins=_SPEED_MARGINS, sharex="all")
    (ax,), (ax2,) = fig.axes
    bins = fig.axes_pixels()
    _shade_window(ax, window)
    ax.curve(*envelope(t, ideal, bins), width_pt=1.6, color="C1", label=f"ideal gearbox: {ratio:.6g} x rotor speed")
    ax.curve(*envelope(t, gen, bins), width_pt=0.8, color="C0", label=f"simulated generator speed {gen_column}")
    ax.ylabel = "speed [rpm]"
    ax.set_title("Generator speed vs ideal gearbox (paper Fig. 16)" + title_suffix)
    ax.grid(width_pt=0.3)
    ax.set_legend("best", 8.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = 100.0 * (gen / ideal - 1.0)
    _shade_window(ax2, window)
    ax2.curve(*envelope(t, dev, bins), width_pt=0.7, color="C2", label="generator / ideal - 1")
    ax2.hline(0.0, color="0.3", width_pt=0.6)
    ax2.xlabel, ax2.ylabel = "time [s]", "difference [%]"
    ax2.grid(width_pt=0.3)
    ax2.set_legend("best", 8.0)
    ax2.xlim = (float(t[0]), float(t[-1]))
    # scale both panels to the analysis window; a larger start-up transient is clipped
    for axis, curves in ((ax, (gen, ideal)), (ax2, (dev,))):
        limits = window_limits(t, curves, window, 0.15)
        if limits is not None and limits[2]:
            axis.ylim = (limits[0], limits[1])
            axis.note("scaled to the analysis window (start-up transient clipped)", 0.005, 0.02, 7.0, "0.35")
    return save_figure(fig, path)


def symmetric_groups(series: list[tuple[str, str, np.ndarray]]) -> list[tuple[str, str, np.ndarray, list[str]]]:
    """Curves of one stage with identical ones merged: (variable, mesh kind, samples, the identical others).

    The planets of a planetary stage are evenly spaced and share one set of
    parameters, so their meshes carry the same force at every instant; a curve
    equal (to 1e-12 of its range) to an earlier one of the same mesh kind is
    drawn once, its label naming the others.
    """
    groups: list[tuple[str, str, np.ndarray, list[str]]] = []
    for var, kind, y in series:
        for first, first_kind, y0, same in groups:
            span = float(np.nanmax(np.abs(y0))) if y0.size else 0.0
            if first_kind == kind and y.shape == y0.shape and np.allclose(y, y0, rtol=0.0, atol=1e-12 * max(span, 1.0),
                                                                            equal_nan=True):
                same.append(var)
                break
        else:
            groups.append((var, kind, y, []))
    return groups


def window_limits(t: np.ndarray, curves, window, pad_share: float) -> tuple[float, float, bool] | None:
    """y limits that show ``curves`` inside the analysis window, and whether that clips them elsewhere.

    The window's range widened by ``pad_share`` of it on both sides; ``clipped`` is True
    where a curve leaves those limits outside the window (a start-up transient, an
    event before it), so that scaling to the whole run would squeeze the window's
    fluctuation. Non-finite samples are left out; None where no finite sample is inside the window.
    """
    sel = (t >= window[0]) & (t <= window[1])
    inside = [v for v in (c[sel] for c in curves) if v.size]
    inside = [v[np.isfinite(v)] for v in inside]
    inside = [v for v in inside if v.size]
    if not inside:
        return None
    lo, hi = min(float(v.min()) for v in inside), max(float(v.max()) for v in inside)
    everywhere = [v for v in (c[np.isfinite(c)] for c in curves) if v.size]
    full_lo, full_hi = min(float(v.min()) for v in everywhere), max(float(v.max()) for v in everywhere)
    pad = pad_share * (hi - lo) if hi > lo else max(abs(hi), 1e-9) * 0.01
    return lo - pad, hi + pad, bool(full_lo < lo - pad or full_hi > hi + pad)


def plot_contact_forces(outcome: RunOutcome, gearbox: ComponentRole, window, path: Path,
                        title_suffix: str = "") -> Path | None:
    """Every recorded contact force the gearbox declares [kN], one row per stage (Fig. 17).

    Left: the whole run (the analysis window shaded), where the start-up peak
    sets the scale; right: the analysis window alone, scaled to it (:func:`window_limits`),
    where the fluctuation the statistics describe is visible. Planet meshes that carry the
    same force (by symmetry) are drawn once (:func:`symmetric_groups`).
    """
    recorded = {c.column: i for i, c in enumerate(outcome.columns)}
    stages: dict[str, list[tuple[str, str, np.ndarray]]] = {}
    for s in gearbox.of_kind("contact_force"):
        i = recorded.get(f"{gearbox.component}.{s.variable}")
        if i is not None:
            stages.setdefault(s.info.get("stage", ""), []).append(
                (s.variable, s.info.get("mesh", "parallel"), outcome.values[:, i]))  # [N], a view: no copy
    if not stages:
        return None
    names = list(stages)
    fig = Figure(15.0, 2.6 * len(names) + 1.0, rows=len(names), columns=2, margins=_FORCE_MARGINS, sharex="col")
    t = outcome.time_s
    bins = fig.axes_pixels()
    merged = False
    for (whole, zoom), stage in zip(fig.axes, names):
        _shade_window(whole, window)
        groups = symmetric_groups(stages[stage])
        for k, (var, kind, y, same) in enumerate(groups):
            label, style = MESH_KIND_STYLES.get(kind, (kind, "-"))
            text = f"{var} ({label})"
            if same:
                merged = True
                text += " = " + ", ".join(v[v.rfind("["):] if v.endswith("]") else v for v in same)
            # the envelope of the samples in N, drawn in kN (the same points as the envelope of y / 1e3)
            te, ye = envelope(t, y, bins)
            ye = ye / 1e3
            for ax in (whole, zoom):
                ax.curve(te, ye, width_pt=0.7, dashed=style == "--", color=f"C{k % 10}",
                         label=text if ax is zoom else None)
        limits = window_limits(t, [y for _, _, y, _ in groups], window, 0.08)
        if limits is not None:
            zoom.xlim = (max(window[0], float(t[0])), min(window[1], float(t[-1])))
            zoom.ylim = (limits[0] / 1e3, limits[1] / 1e3)
        for ax in (whole, zoom):
            ax.ylabel = "force [kN]"
            ax.grid(width_pt=0.3)
        whole.set_title(f"{gearbox.component}.{stage}: whole run", "left", 10.0)
        zoom.set_title(f"{gearbox.component}.{stage}: analysis window {window[0]:g}-{window[1]:g} s", "left", 10.0)
        # beside the axes: inside, it hid the peaks of load events and start-up swings
        zoom.set_legend("beside", 7.0)
    for ax in fig.axes[-1]:
        ax.xlabel = "time [s]"
    fig.axes[-1][0].xlim = (float(t[0]), float(t[-1]))
    note = ("\nplanet meshes that carry identical forces (by symmetry) are drawn once, named '= [2], [3]' in the "
            "legend") if merged else ""
    fig.set_suptitle("Gear contact forces of all stages (paper Fig. 17)" + title_suffix + note, 10.0)
    return save_figure(fig, path)


def plot_run(system: ResolvedSystem, outcome: RunOutcome, out_dir: str | Path,
             skipped: list[dict[str, str]] | None = None, written: list[Path] | None = None) -> list[Path]:
    """Write the plots that the declared and recorded signals allow; returns the files written.

    Parameters
    ----------
    skipped : list, optional
        Receives ``{"analysis": "plot:<name>", "reason": ...}`` for each plot not drawn.
    written : list, optional
        Receives each file as soon as it is written (and is returned): when a plot cannot be
        written (a full disk raises ``OSError``) the caller still knows the ones before it.
    """
    out_dir = Path(out_dir)
    skipped = [] if skipped is None else skipped
    window = system.scenario.simulation.window_s
    suffix = "" if outcome.complete else f" - INCOMPLETE, stopped at {outcome.stopped_at_s:g} s"
    written = [] if written is None else written
    if outcome.time_s.size < 2:
        skipped.append({"analysis": "plots", "reason": "fewer than 2 samples"})
        return written
    names = set(outcome.names)

    def signal_column(role: str, kind: str) -> str:
        col = single_role(system, role).column(kind)
        if col is None:
            raise Skipped(f"the {role} declares no {kind} output")
        if col not in names:
            raise Skipped(f"{col} ({kind}) was not recorded")
        return col

    try:
        rotor = signal_column(WIND_SOURCE, "rotor_speed")
        written.append(plot_rotor_speed(outcome, rotor, window, out_dir / "rotor_speed.png", suffix))
    except Skipped as exc:
        skipped.append({"analysis": "plot:rotor_speed", "reason": str(exc)})
    try:
        rotor = signal_column(WIND_SOURCE, "rotor_speed")
        gen = signal_column(GENERATOR, "generator_speed")
        fig16 = generator_vs_ideal(system, outcome)
        written.append(plot_generator_speed(outcome, rotor, gen, fig16["ratio"], window,
                                            out_dir / "generator_speed.png", suffix))
    except Skipped as exc:
        skipped.append({"analysis": "plot:generator_speed", "reason": str(exc)})
    # a large run hands the memory its earlier phases freed back before the largest figure
    release_between_phases(outcome.values.nbytes)
    try:
        p = plot_contact_forces(outcome, single_role(system, GEARBOX), window, out_dir / "contact_forces.png", suffix)
        if p is None:
            raise Skipped("no declared contact force was recorded")
        written.append(p)
    except Skipped as exc:
        skipped.append({"analysis": "plot:contact_forces", "reason": str(exc)})
    return written
