"""PNG plots of a modal analysis: mode shapes and the Campbell diagram (matplotlib, Agg backend)."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from components.analysis.campbell import CampbellDiagram  # noqa: E402
from components.analysis.modes import DrivetrainModalAnalysis

from ..plotting import close_figure  # noqa: E402

_STAGE_COLOURS = {"stage1": "tab:blue", "stage2": "tab:orange", "stage3": "tab:green", "generator": "tab:red"}


def _colour_of(body: str) -> str:
    return _STAGE_COLOURS.get(body.split(".", 1)[0], "tab:gray")


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
    return close_figure(fig, path)


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
    return close_figure(fig, path)
