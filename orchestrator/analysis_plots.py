"""PNG plots of the analyses: mode shapes, Campbell diagram, contact-force spectra, LDD, load events.

matplotlib with the Agg backend (no display needed). Every function takes the
plain result objects of :mod:`components.analysis.modes`, :mod:`components.analysis.campbell` and
:mod:`components.analysis.fatigue` (or arrays) and a path, writes one PNG and returns the path.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from components.analysis.campbell import CampbellDiagram  # noqa: E402
from components.analysis.fatigue import LoadDurationDistribution  # noqa: E402
from components.analysis.modes import DrivetrainModalAnalysis  # noqa: E402
from components.analysis.spectrum import amplitude_spectrum  # noqa: E402

from .plots import shade_inside_backlash  # noqa: E402

_STAGE_COLOURS = {"stage1": "tab:blue", "stage2": "tab:orange", "stage3": "tab:green", "generator": "tab:red"}


def _colour_of(body: str) -> str:
    return _STAGE_COLOURS.get(body.split(".", 1)[0], "tab:gray")


def _finish(fig, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_mode_shapes(analysis: DrivetrainModalAnalysis, path: str | Path, n_modes: int = 8) -> Path:
    """Bar chart per mode of the referred mode shape (``q_i / kappa_i``, largest = 1) per body.

    Parameters
    ----------
    analysis : DrivetrainModalAnalysis
    path : str or Path
        PNG file.
    n_modes : int
        Number of lowest modes shown.
    """
    modes = analysis.modes[: max(1, n_modes)]
    names = analysis.dof_names
    ncol = min(4, len(modes))
    nrow = math.ceil(len(modes) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.3 * ncol, 0.28 * len(names) * nrow + 1.6), sharey=True, squeeze=False)
    y = np.arange(len(names))
    colours = [_colour_of(n) for n in names]
    for ax, dm in zip(axes.flat, modes):
        m = dm.mode
        ax.barh(y, dm.shape_referred, color=colours)
        ax.axvline(0.0, color="black", lw=0.6)
        ax.set_xlim(-1.1, 1.1)
        damp = "overdamped" if m.overdamped else f"f_d = {m.damped_frequency_hz:.4g} Hz"
        ax.set_title(
            f"mode {m.index} ({dm.kind}{'' if dm.stage is None else ' ' + dm.stage})\n"
            f"f_n = {m.undamped_frequency_hz:.4g} Hz, zeta = {m.damping_ratio:.3g}\n{damp}",
            fontsize=8,
        )
        ax.set_xlabel("referred angle q/kappa [-]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(axis="x", alpha=0.3)
    for ax in axes.flat[len(modes):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_yticks(y)
        ax.set_yticklabels(names)
        ax.set_ylim(len(names) - 0.5, -0.5)  # rotor side on top
    op = analysis.model.operating_point
    fig.suptitle(
        f"Mode shapes at {op.rotor_speed_rpm:.4g} rpm, {op.output_torque_nm / 1e3:.4g} kN m "
        "(deviation angles referred to the rotor, normalised to the largest)",
        fontsize=10,
    )
    fig.tight_layout()
    return _finish(fig, path)


def plot_campbell(diagram: CampbellDiagram, path: str | Path, operating_speed_rpm: float | None = None) -> Path:
    """Campbell diagram: natural frequencies and excitation lines over rotor speed (log frequency axis).

    Underdamped modes are solid, overdamped ones dashed grey (they cannot resonate);
    crossings of underdamped modes with an excitation line are circled.
    """
    s = diagram.rotor_speed_rpm
    fig, ax = plt.subplots(figsize=(10, 6.5))
    f = diagram.undamped_frequency_hz
    labelled_over = False
    for j in range(diagram.n_modes):
        over = diagram.overdamped[:, j]
        if over.all():
            ax.plot(s, f[:, j], ls="--", color="0.6", lw=1.0, label=None if labelled_over else "natural frequency, overdamped mode")
            labelled_over = True
        else:
            ax.plot(s, f[:, j], color="black", lw=1.8,
                    label=f"mode {j + 1} ({diagram.mode_label[j]}), underdamped")
            if over.any():
                ax.plot(s[over], f[over, j], ls="--", color="0.6", lw=1.0)
    styles = ["-.", ":", (0, (5, 2)), (0, (3, 1, 1, 1)), (0, (1, 1))]
    cmap = plt.get_cmap("tab10")
    for k, (name, line) in enumerate(diagram.excitation_hz.items()):
        label = name
        stage = name.split(" ")[0]
        if stage in diagram.mesh_formula and name.endswith("mesh"):
            label = f"{name}: {diagram.mesh_formula[stage]}"
        ax.plot(s, line, ls=styles[k % len(styles)], color=cmap(k % 10), lw=1.4, label=label)
    for c in diagram.crossings():
        if not c["overdamped"]:
            ax.plot(c["rotor_speed_rpm"], c["frequency_hz"], "o", ms=10, mfc="none", mec="red", mew=1.8)
            ax.annotate(f"{c['excitation']} x mode {c['mode']}\n{c['rotor_speed_rpm']:.3g} rpm",
                        (c["rotor_speed_rpm"], c["frequency_hz"]), textcoords="offset points", xytext=(-70, 12), fontsize=8, color="red")
    if operating_speed_rpm is not None:
        ax.axvline(operating_speed_rpm, color="tab:purple", lw=1.0, alpha=0.7, label=f"operating point {operating_speed_rpm:g} rpm")
    ax.set_yscale("log")
    ax.set_xlim(s[0], s[-1])
    ax.set_xlabel("rotor speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.grid(True, which="both", alpha=0.25)
    ax.set_title(f"Campbell diagram - load law: {diagram.load_law.describe()}", fontsize=10)
    ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return _finish(fig, path)


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
    fig, axes = plt.subplots(len(series), 1, figsize=(10, 2.6 * len(series)), squeeze=False)
    cmap = plt.get_cmap("tab10")
    for ax, (name, x) in zip(axes[:, 0], series.items()):
        f, amp = amplitude_spectrum(np.asarray(x)[sel], dt)
        ax.semilogy(f[1:], np.maximum(amp[1:], 1e-12), lw=0.8, color="black")
        for k, (label, fm) in enumerate((mesh_frequencies_hz or {}).items()):
            ax.axvline(fm, ls="--", lw=1.0, color=cmap(k % 10), label=f"{label} {fm:.4g} Hz")
        ax.set_ylabel(f"|{name}| [N]")
        ax.set_xlim(0.0, max_frequency_hz or f[-1])
        ax.grid(True, which="both", alpha=0.25)
        if mesh_frequencies_hz:
            ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("frequency [Hz]")
    fig.suptitle(f"Contact-force amplitude spectra (Hann window, {t[sel][-1] - t[sel][0]:.3g} s, "
                 f"resolution {1.0 / (t[sel][-1] - t[sel][0]):.3g} Hz)", fontsize=10)
    fig.tight_layout()
    return _finish(fig, path)


def plot_load_duration(ldds: Sequence[LoadDurationDistribution], path: str | Path) -> Path:
    """Load duration distributions (time per load bin, log scale), one panel per signal.

    Torques are drawn in kN m (forces in kN); the log time axis shows the rare extreme
    loads (e.g. of a load event) next to the hours-equivalent of normal operation.
    """
    fig, axes = plt.subplots(len(ldds), 1, figsize=(9, 2.5 * len(ldds)), squeeze=False)
    for ax, ld in zip(axes[:, 0], ldds):
        scale, unit = (1e-3, "kN m") if ld.unit in ("N.m", "N m") else (1e-3, "kN") if ld.unit == "N" else (1.0, ld.unit)
        edges = ld.edges * scale
        centres = 0.5 * (edges[1:] + edges[:-1])
        keep = ld.time_s > 0.0
        ax.bar(centres[keep], ld.time_s[keep], width=np.diff(edges)[keep], color="tab:blue", edgecolor="none")
        ax.set_yscale("log")
        ax.set_xlim(edges[0], edges[-1])
        ax.set_xlabel(f"{ld.name} [{unit}]")
        ax.set_ylabel("time in bin [s]")
        extra = f", {ld.time_outside_s:.3g} s outside the bins" if ld.time_outside_s > 0 else ""
        ax.set_title(f"{ld.name}: load duration distribution ({ld.analysed_time_s:.4g} s analysed, "
                     f"{edges.size - 1} bins of {np.diff(edges).mean():.3g} {unit}{extra})", fontsize=9)
        ax.grid(True, which="both", alpha=0.25)
    fig.tight_layout()
    return _finish(fig, path)


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
    fig, axes = plt.subplots(n, 1, figsize=(10, 2.3 * n + 0.6), sharex=True, squeeze=False)
    axes = axes[:, 0]
    for ax in axes:
        for k, (label, a, b) in enumerate(events):
            ax.axvspan(a, min(b, span[1]), color="gold", alpha=0.25, lw=0, label=label if ax is axes[0] else None)
        ax.grid(True, alpha=0.3)
    cmap = plt.get_cmap("tab10")
    for k, (name, y) in enumerate(torques.items()):
        axes[0].plot(ts, np.asarray(y)[sel] * 1e-3, lw=1.2, color=cmap(k), label=name)
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
    fig.tight_layout()
    return _finish(fig, path)
