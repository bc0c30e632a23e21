"""PNG plots of a drivetrain run (matplotlib, Agg canvas; no pyplot global state).

* ``rotor_speed.png`` - rotor speed over time, the wind description (paper Fig. 15);
* ``generator_speed.png`` - generator speed against the ideal gearbox, ratio x rotor
  speed, with their relative difference below (Fig. 16);
* ``contact_forces.png`` - every contact force, one row per stage: the whole run
  and the analysis window alone; identical planet meshes drawn once (Fig. 17).

The variables come from the components' declared roles and signals
(:mod:`orchestrator.cosim.roles`); a plot whose signals are not declared or not
recorded is skipped and :func:`plot_run` says why. The analysis window is shaded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..cosim.outcome import RunOutcome
from ..cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE, ComponentRole
from ..cosim.resolved import ResolvedSystem
from ..plotting import (
    MESH_KIND_STYLES,
    RPM_PER_RAD_S,
    Margins,
    axes_pixels,
    envelope,
    legend_room,
    new_figure,
    new_grid,
    plot_envelope,
    save_figure,
)
from .derived import Skipped, generator_vs_ideal, single_role
from .memory import release_between_phases


#: the layouts of the figures (fixed: each is drawn once, see :class:`~orchestrator.plotting.Margins`)
_SPEED_MARGINS = Margins()
#: contact forces: a title above every row, the window's axes with their own tick labels
_FORCE_MARGINS = Margins(top=0.75, hspace=0.4, wspace=0.9)


def _shade_window(ax, window) -> None:
    ax.axvspan(window[0], window[1], color="0.93", zorder=0, label=f"analysis window {window[0]:g}-{window[1]:g} s")


def plot_rotor_speed(outcome: RunOutcome, column: str, window, path: Path, title_suffix: str = "") -> Path:
    """Rotor speed [rpm] over time (Fig. 15)."""
    t = outcome.time_s
    w = outcome.column(column) * RPM_PER_RAD_S
    fig, (ax,) = new_figure(margins=_SPEED_MARGINS)
    _shade_window(ax, window)
    plot_envelope(ax, t, w, lw=0.8, color="C0", label=f"rotor speed {column}")
    sel = (t >= window[0]) & (t <= window[1])
    if sel.any():
        ax.axhline(w[sel].mean(), color="C3", lw=1.0, ls="--", label=f"mean over window: {w[sel].mean():.4g} rpm")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("rotor speed [rpm]")
    ax.set_title("Rotor speed: stochastic wind description, eq. 13-14 (paper Fig. 15)" + title_suffix)
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_xlim(t[0], t[-1])
    return save_figure(fig, path)


def plot_generator_speed(outcome: RunOutcome, rotor_column: str, gen_column: str, ratio: float, window,
                         path: Path, title_suffix: str = "") -> Path:
    """Generator speed against ratio x rotor speed, and their relative difference (Fig. 16)."""
    t = outcome.time_s
    gen = outcome.column(gen_column) * RPM_PER_RAD_S
    ideal = ratio * outcome.column(rotor_column) * RPM_PER_RAD_S
    fig, (ax, ax2) = new_figure(2, height=6.0, margins=_SPEED_MARGINS)
    _shade_window(ax, window)
    plot_envelope(ax, t, ideal, lw=1.6, color="C1", label=f"ideal gearbox: {ratio:.6g} x rotor speed")
    plot_envelope(ax, t, gen, lw=0.8, color="C0", label=f"simulated generator speed {gen_column}")
    ax.set_ylabel("speed [rpm]")
    ax.set_title("Generator speed vs ideal gearbox (paper Fig. 16)" + title_suffix)
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize=8)
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = 100.0 * (gen / ideal - 1.0)
    _shade_window(ax2, window)
    plot_envelope(ax2, t, dev, lw=0.7, color="C2", label="generator / ideal - 1")
    ax2.axhline(0.0, color="0.3", lw=0.6)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("difference [%]")
    ax2.grid(True, lw=0.3)
    ax2.legend(loc="best", fontsize=8)
    ax2.set_xlim(t[0], t[-1])
    # scale both panels to the analysis window; a larger start-up transient is clipped
    for axis, curves in ((ax, (gen, ideal)), (ax2, (dev,))):
        limits = window_limits(t, curves, window, 0.15)
        if limits is not None and limits[2]:
            axis.set_ylim(limits[0], limits[1])
            axis.text(0.005, 0.02, "scaled to the analysis window (start-up transient clipped)",
                      transform=axis.transAxes, fontsize=7, color="0.35")
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
    fig, axes = new_grid(len(names), 2, height=2.6 * len(names) + 1.0, width=15.0, margins=_FORCE_MARGINS)
    t = outcome.time_s
    bins = axes_pixels(axes[0][0])
    legends = []
    merged = False
    for row, stage in zip(axes, names):
        whole, zoom = row
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
                ax.plot(te, ye, lw=0.7, ls=style, color=f"C{k % 10}", label=text if ax is zoom else None)
        limits = window_limits(t, [y for _, _, y, _ in groups], window, 0.08)
        if limits is not None:
            zoom.set_xlim(max(window[0], t[0]), min(window[1], t[-1]))
            zoom.set_ylim(limits[0] / 1e3, limits[1] / 1e3)
        for ax in (whole, zoom):
            ax.set_ylabel("force [kN]")
            ax.grid(True, lw=0.3)
        whole.set_title(f"{gearbox.component}.{stage}: whole run", fontsize=10, loc="left")
        zoom.set_title(f"{gearbox.component}.{stage}: analysis window {window[0]:g}-{window[1]:g} s", fontsize=10,
                       loc="left")
        # outside the axes: inside, it hid the peaks of load events and start-up swings
        legends.append(zoom.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, ncol=1,
                                   borderaxespad=0.0))
    legend_room(fig, legends, _FORCE_MARGINS)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    axes[-1][0].set_xlim(t[0], t[-1])
    note = ("\nplanet meshes that carry identical forces (by symmetry) are drawn once, named '= [2], [3]' in the "
            "legend") if merged else ""
    fig.suptitle("Gear contact forces of all stages (paper Fig. 17)" + title_suffix + note, fontsize=10)
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
    # a drawn figure is a reference cycle: its pixels go when the collector runs, before the largest figure
    release_between_phases(outcome.values.nbytes)
    try:
        p = plot_contact_forces(outcome, single_role(system, GEARBOX), window, out_dir / "contact_forces.png", suffix)
        if p is None:
            raise Skipped("no declared contact force was recorded")
        written.append(p)
    except Skipped as exc:
        skipped.append({"analysis": "plot:contact_forces", "reason": str(exc)})
    return written
