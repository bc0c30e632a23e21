"""Modal report of a drivetrain at an operating point: table, CSV, JSON and PNG files.

:func:`modal_report` is what ``dtcosim modes`` runs; a scenario (or a results
pipeline) calls it with its own drivetrain and operating point. Files written:

* ``modes.csv`` - one row per mode: kind, undamped and damped frequency, damping
  ratio, overdamped flag, dominant bodies and springs, referred mode shape per body;
* ``modes.json`` - the full modal analysis (equilibrium, energies, shapes, roots);
* ``modes.png`` - bar charts of the lowest mode shapes;
* ``campbell.csv`` - natural frequencies, damping and excitation lines per rotor speed;
* ``campbell_crossings.csv`` - where modes meet excitation lines;
* ``campbell.png`` - the Campbell diagram.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from components.analysis.campbell import (
    CampbellDiagram,
    LoadLaw,
    campbell_diagram,
    write_rows_csv,
)
from components.analysis.equilibrium import OperatingPoint
from components.analysis.modal_verification import (
    FreeResponseCheck,
    free_response_check,
)
from components.analysis.modes import DrivetrainModalAnalysis, drivetrain_modes
from components.errors import ParameterError
from components.model.drivetrain import Drivetrain
from components.model.rotor import RotorParameters

from ..atomic_files import atomic_path, write_text_atomic
from .modal_plots import plot_campbell, plot_mode_shapes


def _rows_csv(path: Path, rows: list[dict]) -> Path:
    """:func:`write_rows_csv` through a temporary file and rename: whole or not there, a write error names ``path``."""
    with atomic_path(path) as tmp:
        write_rows_csv(tmp, rows)
    return path


def format_mode_table(analysis: DrivetrainModalAnalysis) -> str:
    """The modal table as fixed-width text."""
    head = f"{'mode':>4}  {'kind':<21}{'undamped f [Hz]':>16}{'damped f [Hz]':>15}{'zeta':>10}  {'overdamped':<11}dominant bodies (kinetic energy) | springs (strain energy)"
    lines = [head, "-" * len(head)]
    for dm in analysis.modes:
        m = dm.mode
        kind = dm.kind if dm.stage is None else f"{dm.kind} {dm.stage}"
        kind += f" x{dm.multiplicity}" if dm.multiplicity > 1 else ""
        fd = "-" if m.overdamped else f"{m.damped_frequency_hz:.5g}"
        zeta = m.damping_ratio if abs(m.damping_ratio) > 1e-12 else 0.0  # an undamped system's round-off
        lines.append(
            f"{m.index:>4}  {kind:<21}{m.undamped_frequency_hz:>16.5g}{fd:>15}{zeta:>10.4g}  "
            f"{'yes' if m.overdamped else 'no':<11}{dm.dominant_bodies} | {dm.dominant_elements}"
        )
    return "\n".join(lines)


def format_verification(checks: list[FreeResponseCheck]) -> str:
    """The free-response comparison as text."""
    if not checks:
        return "no underdamped mode: nothing to compare"
    lines = [f"{'mode':>4}{'linear damped f [Hz]':>22}{'free-response peak [Hz]':>25}{'error':>11}{'record [s]':>12}"]
    for c in checks:
        lines.append(f"{c.mode:>4}{c.damped_frequency_hz:>22.6g}{c.spectral_peak_hz:>25.6g}{100 * c.relative_error:>10.3g}%{c.record_s:>12.4g}")
    return "\n".join(lines)


def modal_report(
    drivetrain: Drivetrain,
    operating_point: OperatingPoint,
    out_dir: str | Path | None = None,
    load_law: LoadLaw | None = None,
    campbell_speeds_rad_s: np.ndarray | None = None,
    n_shapes: int = 8,
    verify: bool = False,
    rotor: RotorParameters | None = None,
    free_input: bool = False,
) -> dict:
    """Modal analysis, Campbell diagram (and optionally the free-response check) with files.

    Parameters
    ----------
    drivetrain : Drivetrain
    operating_point : OperatingPoint
        Linearisation point of the modal table.
    out_dir : str or Path, optional
        Directory for the files; None writes nothing.
    load_law : LoadLaw, optional
        Campbell load law; default quadratic up to the operating point (rated point).
    campbell_speeds_rad_s : ndarray, optional
        Campbell rotor speeds [rad/s]; default 4-20 rpm in 33 points.
    n_shapes : int
        Modes shown in ``modes.png``.
    verify : bool
        Also run :func:`components.analysis.modal_verification.free_response_check` (held rotor only).
    rotor : RotorParameters, optional
        A torque-driven rotor: the drivetrain free at both ends (default: the rotor held).
    free_input : bool
        The stage-1 input member free, no rotor (a gearbox on its own).

    Returns
    -------
    dict
        ``{"analysis", "campbell", "verification", "files"}``: the result objects and the
        written paths (a plain-JSON summary is in ``modes.json``).
    """
    if verify and (rotor is not None or free_input):
        raise ParameterError("verify", True, "a held rotor (the free-response check prescribes the rotor speed)")
    analysis = drivetrain_modes(drivetrain, operating_point, rotor=rotor, free_input=free_input)
    law = load_law or LoadLaw("quadratic", abs(operating_point.rotor_speed_rad_s), operating_point.output_torque_nm)
    if campbell_speeds_rad_s is None:
        campbell_speeds_rad_s = np.linspace(4.0, 20.0, 33) * np.pi / 30.0
    campbell: CampbellDiagram = campbell_diagram(drivetrain, campbell_speeds_rad_s, law, rotor=rotor,
                                                 free_input=free_input)
    checks = free_response_check(drivetrain, operating_point, analysis) if verify else None
    files: dict[str, Path] = {}
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        files["modes.csv"] = _rows_csv(out / "modes.csv", analysis.table_rows())
        summary = analysis.as_dict()
        if checks is not None:
            summary["free_response_check"] = [c.as_dict() for c in checks]
        summary["campbell"] = {"load_law": law.as_dict(), "crossings": campbell.crossings(), "mesh_frequency": campbell.mesh_formula}
        write_text_atomic(out / "modes.json", json.dumps(summary, indent=2))
        files["modes.json"] = out / "modes.json"
        files["modes.png"] = plot_mode_shapes(analysis, out / "modes.png", n_shapes)
        files["campbell.csv"] = _rows_csv(out / "campbell.csv", campbell.rows())
        crossings = campbell.crossings()
        if crossings:
            files["campbell_crossings.csv"] = _rows_csv(out / "campbell_crossings.csv", crossings)
        files["campbell.png"] = plot_campbell(campbell, out / "campbell.png", operating_point.rotor_speed_rpm)
    return {"analysis": analysis, "campbell": campbell, "verification": checks, "files": files}
