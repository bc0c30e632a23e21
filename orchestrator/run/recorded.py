"""Simulated against recorded channels: where a TimeSeriesSource plays a record of a simulated signal.

A TimeSeriesSource output declares what it records (``quantity`` of its ``recorded`` signal, e.g.
``generator_speed`` for OpenFAST's GenSpeed). Every other component declaring that signal kind
(a generator's ``generator_speed``, a rotor's ``rotor_speed``) is compared with it over the
analysis window: RMS and largest difference, also relative to the record's RMS, into
``summary["recorded_comparison"]`` and the plot ``recorded_vs_simulated.png``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic_files import atomic_path
from ..cosim.outcome import RunOutcome
from ..cosim.roles import ROLES
from ..cosim.resolved import ResolvedSystem

TIME_SERIES = "time_series"
#: recorded quantities that have a simulated counterpart (the same signal kind in another role)
COMPARED = ("rotor_speed", "generator_speed", "generator_torque")


def recorded_pairs(system: ResolvedSystem, outcome: RunOutcome) -> list[tuple[str, str, str]]:
    """``(quantity, recorded column, simulated column)`` of every comparable, recorded pair."""
    recorded_columns = {c.column for c in outcome.columns}
    pairs = []
    for source in system.with_role(TIME_SERIES):
        for sig in source.of_kind("recorded"):
            quantity = sig.info.get("quantity", "")
            rec = f"{source.component}.{sig.variable}"
            if quantity not in COMPARED or rec not in recorded_columns:
                continue
            for role in ROLES:
                if role == TIME_SERIES:
                    continue
                for other in system.with_role(role):
                    sim = other.column(quantity)
                    if sim is not None and sim in recorded_columns:
                        pairs.append((quantity, rec, sim))
    return pairs


def compare_recorded(system: ResolvedSystem, outcome: RunOutcome) -> list[dict]:
    """RMS and max differences simulated - recorded over the analysis window, per pair."""
    w0, w1 = system.scenario.simulation.window_s
    mask = (outcome.time_s >= w0) & (outcome.time_s <= w1)
    out = []
    for quantity, rec, sim in recorded_pairs(system, outcome):
        r = outcome.column(rec)[mask]
        s = outcome.column(sim)[mask]
        d = s - r
        scale = float(np.sqrt(np.mean(r * r))) or 1.0
        out.append({"quantity": quantity, "recorded": rec, "simulated": sim, "window_s": [w0, w1],
                    "rms_difference": float(np.sqrt(np.mean(d * d))), "max_difference": float(np.max(np.abs(d))),
                    "mean_difference": float(np.mean(d)),
                    "rms_difference_relative": float(np.sqrt(np.mean(d * d)) / scale),
                    "max_difference_relative": float(np.max(np.abs(d)) / scale)})
    return out


def plot_recorded(system: ResolvedSystem, outcome: RunOutcome, out_dir: str | Path) -> Path | None:
    """``recorded_vs_simulated.png``: each pair over the run and its difference (None when there is no pair)."""
    pairs = recorded_pairs(system, outcome)
    if not pairs:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    units = {c.column: c.unit for c in outcome.columns}
    fig, axes = plt.subplots(len(pairs), 2, figsize=(12, 3.2 * len(pairs)), squeeze=False,
                             gridspec_kw={"width_ratios": [2, 1]})
    t = outcome.time_s
    for (quantity, rec, sim), (ax, axd) in zip(pairs, axes):
        r, s = outcome.column(rec), outcome.column(sim)
        ax.plot(t, r, color="k", lw=1.4, label=f"recorded {rec}")
        ax.plot(t, s, color="tab:red", lw=0.9, ls="--", label=f"simulated {sim}")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{quantity} [{units.get(sim, '')}]")
        ax.legend(loc="best", fontsize=8, framealpha=0.6)
        axd.plot(t, s - r, color="tab:blue", lw=0.8)
        axd.set_xlabel("time [s]")
        axd.set_ylabel(f"simulated - recorded [{units.get(sim, '')}]")
        for a in (ax, axd):
            a.axvspan(*system.scenario.simulation.window_s, color="0.92", zorder=0)
            a.grid(alpha=0.3)
    fig.suptitle(f"{system.scenario.name}: simulated against recorded channels (analysis window shaded)")
    fig.tight_layout()
    path = Path(out_dir) / "recorded_vs_simulated.png"
    try:
        with atomic_path(path) as tmp:  # whole or not there
            fig.savefig(tmp, dpi=110)
    finally:
        plt.close(fig)
    return path


def plot_contact_loss_counts(summary_contact_loss: dict, out_dir: str | Path, title: str) -> Path | None:
    """``contact_loss_counts.png``: separations and flank changes per mesh (None without contact loss)."""
    meshes = summary_contact_loss.get("meshes", {}) if summary_contact_loss else {}
    if not meshes or not summary_contact_loss.get("total_separations"):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(meshes)
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(max(6.0, 0.7 * len(names) + 2.0), 4.2))
    ax.bar(x - 0.2, [meshes[n]["separations"] for n in names], 0.4, label="separations (contact -> no contact)")
    ax.bar(x + 0.2, [meshes[n]["flank_changes"] for n in names], 0.4, label="flank changes")
    ax.set_xticks(x, [n.split(".", 1)[1] for n in names], rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("count [-]")
    w0, w1 = summary_contact_loss["window_s"]
    ax.set_title(f"{title}: contact loss per mesh over [{w0:g}, {w1:g}] s")
    ax.legend(loc="best", fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    path = Path(out_dir) / "contact_loss_counts.png"
    try:
        with atomic_path(path) as tmp:  # whole or not there
            fig.savefig(tmp, dpi=110)
    finally:
        plt.close(fig)
    return path
