"""Monolithic reference of a co-simulation scenario and the co-simulation-vs-monolithic report.

The reference is :func:`components.reference.solver.simulate_monolithic` (one stiff ODE,
LSODA, analytic Jacobian) on the *same* system: the physics view of the scenario
(:func:`orchestrator.cosim.physics_view.physics_view`), i.e. the drivetrain, wind
and generator the FMUs' records describe, with the scenario's parameter values.
Co-simulated columns are paired with the reference's series by the signals the
FMUs declare (:mod:`orchestrator.cosim.roles`).
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from components.reference.results import SimulationResult, window_statistics

from ..cosim.outcome import RunOutcome
from ..cosim.physics_view import PhysicsView, physics_view
from ..cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE
from ..cosim.resolved import ResolvedSystem

STATISTICS = ("mean", "std", "min", "max")

#: declared signal -> the monolithic result's series
_REFERENCE_SERIES = {
    (WIND_SOURCE, "rotor_speed"): "omega_rotor",
    (WIND_SOURCE, "rotor_angle"): "phi_rotor",
    (GENERATOR, "generator_speed"): "omega_gen",
    (GENERATOR, "generator_angle"): "phi_gen",
    (GENERATOR, "generator_torque"): "load_torque",
}


def reference_name(column: str, system: ResolvedSystem, view: PhysicsView,
                   series: Mapping[str, np.ndarray]) -> str | None:
    """Name in the monolithic result of a co-simulation column ``component.variable`` (None: no counterpart).

    Wind source and generator outputs pair by their declared signal; the Gearbox's
    outputs have the names of the monolithic series (both come from
    :class:`components.model.gearbox_model.GearboxModel`), its generator-shaft
    torque outputs pair with the last shaft's torque.
    """
    comp, _, var = column.partition(".")
    if comp not in view.components.values():
        return None
    role = system.roles[comp]
    kinds = {s.variable: s.kind for s in role.signals}
    if role.role == GEARBOX:
        if kinds.get(var) == "generator_shaft_torque":
            last = view.drivetrain.output_shaft
            name = f"{last.name}.torque" if last is not None else None
        else:
            name = var
    else:
        name = _REFERENCE_SERIES.get((role.role, kinds.get(var, "")))
    return name if name in series else None


def run_reference(system: ResolvedSystem, view: PhysicsView | None = None, settings=None) -> SimulationResult:
    """The monolithic solution on the scenario's time grid (start, stop, output interval), started where the Gearbox is.

    ``settings``: the solver's tolerances (:class:`components.reference.solver.SolverSettings`; default its own).

    Raises
    ------
    PhysicsUnavailable
        If the scenario's physics cannot be read from its FMUs' records.
    """
    from components.model.wind import RotorSpeedProcess
    from components.reference.solver import simulate_monolithic

    setup = view or physics_view(system)
    sim = system.scenario.simulation
    return simulate_monolithic(
        setup.drivetrain, RotorSpeedProcess(setup.wind), sim.stop_s,
        output_interval_s=sim.output_interval_s, t_start_s=sim.start_s, start=setup.start, settings=settings,
    )


def _rel(a: float, b: float, scale: float) -> float:
    return float((a - b) / scale) if scale > 0 else (0.0 if a == b else math.inf)


def compare(outcome: RunOutcome, reference: SimulationResult, system: ResolvedSystem,
            setup: PhysicsView) -> dict[str, Any]:
    """Every statistic, co-simulation vs monolithic, over the scenario's analysis window.

    Returns
    -------
    dict
        ``{"variables": {column: {"reference": name, "cosim": {stat}, "monolithic": {stat},
        "relative_difference": {stat}, "rms_difference": float, "rms_relative_to_std": float}},
        "notes": [...]}``. Relative differences of mean, min and max are relative to
        the monolithic mean's magnitude, the std's to the monolithic std;
        ``rms_difference`` is the RMS of the pointwise difference on the common time
        grid within the window.
    """
    window = system.scenario.simulation.window_s
    t_co = outcome.time_s
    t_ref = reference.time_s
    n = min(t_co.size, t_ref.size)
    same_grid = n > 0 and np.allclose(t_co[:n], t_ref[:n], rtol=0, atol=1e-9)
    sel = (t_co[:n] >= window[0] - 1e-12) & (t_co[:n] <= window[1] + 1e-12)
    result: dict[str, Any] = {}
    for i, col in enumerate(outcome.columns):
        ref_name = reference_name(col.column, system, setup, reference.series)
        if ref_name is None:
            continue
        co = outcome.values[:, i]
        ref = reference.series[ref_name]
        s_co = window_statistics(t_co, co, window)
        s_ref = window_statistics(t_ref, ref, window)
        scale_mean = abs(s_ref["mean"])
        rel = {
            "mean": _rel(s_co["mean"], s_ref["mean"], scale_mean),
            "std": _rel(s_co["std"], s_ref["std"], s_ref["std"]),
            "min": _rel(s_co["min"], s_ref["min"], scale_mean),
            "max": _rel(s_co["max"], s_ref["max"], scale_mean),
        }
        entry = {"reference": ref_name, "cosim": s_co, "monolithic": s_ref, "relative_difference": rel}
        if same_grid and sel.any():
            d = co[:n][sel] - ref[:n][sel]
            rms = float(np.sqrt(np.mean(d * d)))
            entry["rms_difference"] = rms
            entry["rms_relative_to_std"] = rms / s_ref["std"] if s_ref["std"] > 0 else math.inf
        result[col.column] = entry
    return {
        "reference": "monolithic LSODA (components.reference.solver.simulate_monolithic)",
        "built_from": dict(setup.sources),
        "window_s": list(window),
        "reference_complete": bool(reference.complete),
        "reference_wall_time_s": float(reference.wall_time_s),
        "notes": list(setup.notes),
        "variables": result,
    }


def format_comparison(report: Mapping[str, Any]) -> str:
    """A plain-text table of :func:`compare`'s report, 80 columns wide.

    Shown: the co-simulation's mean and std, their differences to the monolithic
    reference (mean relative to ``|monolithic mean|``, std to the monolithic std)
    and the rms difference relative to the std; every number of both, min and
    max too, is in ``summary.json`` (``comparison``).
    """
    from .text_tables import fit_table, number

    w0, w1 = report["window_s"]
    lines = [f"co-simulation vs monolithic reference over [{w0:g}, {w1:g}] s (d: relative difference;",
             "all values of both in summary.json, comparison):"]
    rows = []
    for name, e in report["variables"].items():
        c, r = e["cosim"], e["relative_difference"]
        rows.append([name, number(c["mean"], ".6g"), number(r["mean"], "+.2e"), number(c["std"], ".5g"),
                     number(r["std"], "+.2e"), number(e.get("rms_relative_to_std"), ".2e")])
    lines += fit_table(["variable", "mean co-sim", "d mean", "std co-sim", "d std", "rms/std"], rows, indent=0)
    for note in report.get("notes", []):
        lines.append(f"note: {note}")
    return "\n".join(lines)
