"""Files of ``dtcosim reference --out DIR``: a paper case's time series, summary and figure.

``timeseries.csv`` holds every series of the monolithic result (header
``name [unit]``, SI), ``summary.json`` the printed statistics, and
``reference.png`` the input speed over the contact forces of every stage with
the intervals inside the backlash (``|F| <`` :data:`CONTACT_LOSS_THRESHOLD_N`) shaded:
for the ``sine`` case this is the paper's Fig. 10-11.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from components.model.contact import CONTACT_LOSS_THRESHOLD_N
from components.model.signals import CONTACT_FORCE, ROTOR_SPEED
from components.reference.cases import ReferenceCase
from components.reference.results import SimulationResult

from ..plotting import (
    MESH_KIND_STYLES,
    new_figure,
    plot_envelope,
    save_figure,
    shade_inside_backlash,
)
from ..result_files import write_series_csv, write_summary


def plot_reference(result: SimulationResult, case: ReferenceCase, path: str | Path) -> Path:
    """Input speed [rpm] over the contact forces of every stage [N or kN]; returns ``path``.

    The input speed, the contact forces, their stages and mesh kinds are those the solver declares
    (:attr:`SimulationResult.signals`).
    """
    t = result.time_s
    stages: dict[str, list[tuple[str, str]]] = {}
    for name in result.names_of(CONTACT_FORCE):
        signal = result.signals[name]
        stages.setdefault(signal.detail("stage"), []).append((name, signal.detail("mesh")))
    fig, axes = new_figure(1 + len(stages), height=2.4 * (1 + len(stages)) + 0.8, width=11.0)
    ax = axes[0]
    for name in result.names_of(ROTOR_SPEED):
        plot_envelope(ax, t, result[name] * 30.0 / math.pi, lw=0.9, color="k", label="input (carrier / drive) speed")
    ax.set_ylabel("speed [rpm]")
    ax.legend(loc="upper right", fontsize=8)
    for ax, (stage, forces) in zip(axes[1:], stages.items()):
        peak = max(float(np.abs(result[n]).max()) for n, _ in forces)
        scale, unit = (1e3, "kN") if peak >= 1e4 else (1.0, "N")
        for k, (name, kind) in enumerate(forces):
            label, style = MESH_KIND_STYLES.get(kind, (kind, "-"))
            plot_envelope(ax, t, result[name] / scale, lw=0.7, ls=style, color=f"C{k % 10}", label=f"{name} ({label})")
        shade_inside_backlash(ax, t, result[forces[0][0]], CONTACT_LOSS_THRESHOLD_N,
                              f"{forces[0][0]} inside the backlash (|F| < {CONTACT_LOSS_THRESHOLD_N:g} N)")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel(f"contact force [{unit}]")
        ax.set_title(stage, fontsize=10, loc="left")
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, borderaxespad=0.0)
    for ax in axes:
        ax.grid(True, lw=0.3)
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_xlim(t[0], t[-1])
    fig.suptitle(f"{case.name}: {case.description} (monolithic reference)")
    return save_figure(fig, Path(path))


def write_reference_outputs(result: SimulationResult, case: ReferenceCase, summary: Mapping[str, Any],
                            out_dir: str | Path, plot: bool = True) -> list[Path]:
    """Write ``timeseries.csv``, ``summary.json`` and (``plot``) ``reference.png`` into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    names = result.names
    header = ["time [s]"] + [f"{n} [{result.signals[n].unit}]" for n in names]  # as the solver declares them
    values = np.column_stack([result[n] for n in names]) if names else np.empty((result.time_s.size, 0))
    files = [write_series_csv(out / "timeseries.csv", header, result.time_s, values),
             write_summary(out / "summary.json", summary)]
    if plot:
        files.append(plot_reference(result, case, out / "reference.png"))
    return files
