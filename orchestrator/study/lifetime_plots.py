"""Plots of a load-case set's lifetime results: damage by wind-speed bin, LDD and LRD (PNG)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import new_figure, save_figure
from .lifetime_results import HOURS, LifetimeResults, ranking_targets


def _scale(unit: str) -> tuple[float, str]:
    """Display factor and unit: kN m for torques, kN for forces."""
    if unit in ("N.m", "N m", "Nm"):
        return 1e-3, "kN m"
    if unit == "N":
        return 1e-3, "kN"
    return 1.0, unit


def plot_damage_by_bin(res: LifetimeResults, path: Path) -> Path:
    """Share of the lifetime damage per wind-speed bin: the high-speed shaft and each stage's mesh (grouped bars)."""
    plc = res.plc
    targets = ranking_targets(res)
    centres = np.array([b.centre_m_s for b in plc.bins])
    width = np.min(np.diff([b.low_m_s for b in plc.bins] + [plc.bins[-1].high_m_s]))
    fig, (ax,) = new_figure(1, height=4.5)
    n = max(len(targets), 1)
    bar = 0.8 * width / n
    for k, (label, col) in enumerate(targets):
        share = 100.0 * res.channels[col].ranking_share
        ax.bar(centres - 0.4 * width + (k + 0.5) * bar, share, bar, label=f"{label} ({col})")
    ax2 = ax.twinx()
    ax2.plot(centres, [100.0 * b.probability for b in plc.bins], "k.--", label="bin probability")
    ax2.set_ylabel("probability of the bin [%]")
    ax.set_xlabel("wind speed [m/s]")
    ax.set_ylabel("share of lifetime damage [%]")
    ax.set_xticks(centres)
    ax.set_title(f"{plc.load_cases.name}: damage by wind-speed bin")
    handles = ax.get_legend_handles_labels()
    handles2 = ax2.get_legend_handles_labels()
    fig.legend(handles[0] + handles2[0], handles[1] + handles2[1], loc="outside lower center", ncol=2, fontsize=7)
    return save_figure(fig, path)


def _torque_channels(res: LifetimeResults) -> list[str]:
    return [c for c, cl in res.channels.items() if cl.channel.gears and cl.channel.kind in ("shaft_torque", "rotor_torque")]


def plot_ldd(res: LifetimeResults, path: Path) -> Path:
    """Lifetime load duration distribution (hours at each level) of every torque channel with gears."""
    cols = _torque_channels(res) or list(res.channels)[:4]
    fig, axes = new_figure(len(cols), height=2.2 * len(cols), sharex=False)
    for ax, col in zip(axes, cols):
        cl = res.channels[col]
        f, unit = _scale(cl.channel.unit)
        edges, time_s, _ = cl.ldd.dense()
        ax.stairs(time_s / HOURS, edges * f, fill=True, alpha=0.6, label=col)
        ax.set_xlabel(f"{col} [{unit}]")
        ax.set_ylabel("time [h]")
        ax.legend(loc="upper left", fontsize=7)
    axes[0].set_title(f"{res.plc.load_cases.name}: lifetime load duration distribution")
    return save_figure(fig, path)


def plot_lrd(res: LifetimeResults, path: Path) -> Path:
    """Lifetime load revolution distribution per gear: level vs cumulative revolutions at or above it (ISO 6336-6)."""
    cols = _torque_channels(res)
    fig, axes = new_figure(max(len(cols), 1), height=2.4 * max(len(cols), 1), sharex=False)
    for ax, col in zip(axes, cols):
        cl = res.channels[col]
        f, unit = _scale(cl.channel.unit)
        h = cl.ldd
        for k, (gear, revs) in enumerate(h.revolutions.items()):
            above = np.cumsum(revs[::-1])[::-1]  # revolutions at this level or higher
            # the gears at the two ends of a shaft may turn alike: dashed over solid keeps both visible
            ax.step(np.maximum(above, 1e-3), h.upper * f, where="post", label=f"{gear}",
                    linestyle=("-", "--", ":")[k % 3], linewidth=2.0 - 0.6 * k)
        ax.set_xscale("log")
        ax.set_xlabel("revolutions at or above the level [-]")
        ax.set_ylabel(f"{col} [{unit}]", fontsize=8)
        ax.legend(loc="lower left", fontsize=7)
    axes[0].set_title(f"{res.plc.load_cases.name}: lifetime load revolution distribution per gear")
    return save_figure(fig, path)
