"""Drivetrain quantities derived from a run: component roles, the ideal gearbox, Fig. 16.

Roles are recognised by the FMU model names ``WindSource``, ``Gearbox`` and
``GeneratorRotor`` (instance names are free). The ideal gearbox ratio comes from
the gearbox itself: the drivetrain rebuilt from the Gearbox FMU's parameters
(:func:`orchestrator.run.comparison.monolithic_setup`), or, if that is not possible,
the gearbox's kinematically consistent initial state,
``omega_out(t0) / omega_rotor(t0)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from components.reference.results import window_statistics

from ..cosim.master import RunOutcome
from ..cosim.system import ResolvedSystem

WIND, GEARBOX, GENERATOR = "WindSource", "Gearbox", "GeneratorRotor"


def roles(system: ResolvedSystem) -> dict[str, str]:
    """Role -> component name for the roles present (first component of each model name)."""
    out: dict[str, str] = {}
    for name in system.scenario.component_names:
        model = system.interfaces[name].model_name
        if model in (WIND, GEARBOX, GENERATOR) and model not in out:
            out[model] = name
    return out


def _column(outcome: RunOutcome, name: str) -> np.ndarray | None:
    try:
        return outcome.column(name)
    except KeyError:
        return None


def ideal_ratio(system: ResolvedSystem, outcome: RunOutcome) -> tuple[float | None, str]:
    """Kinematic ratio generator / rotor speed of the gearbox and where it came from."""
    from .comparison import ReferenceError, monolithic_setup

    try:
        return float(monolithic_setup(system).drivetrain.ratio), "gearbox parameters (components.model.parameter_map)"
    except ReferenceError:  # a system the reference model cannot express
        pass
    r = roles(system)
    if WIND in r and GEARBOX in r:
        rotor = _column(outcome, f"{r[WIND]}.omega")
        out = _column(outcome, f"{r[GEARBOX]}.omega_out")
        if rotor is not None and out is not None and rotor.size and rotor[0] != 0:
            return float(out[0] / rotor[0]), "gearbox initial state omega_out(t0) / omega_rotor(t0)"
    return None, "unavailable"


def generator_vs_ideal(system: ResolvedSystem, outcome: RunOutcome) -> dict[str, Any] | None:
    """Generator speed against ``ratio x rotor speed`` over the analysis window (paper Fig. 16).

    Returns
    -------
    dict or None
        ``{"ratio", "ratio_source", "relative_deviation": {"mean", "std", "min", "max", "max_abs"}}``
        where the deviation is ``omega_gen / (ratio omega_rotor) - 1``; None if the
        scenario has no wind source or generator, or they were not recorded.
    """
    r = roles(system)
    if WIND not in r or GENERATOR not in r:
        return None
    rotor = _column(outcome, f"{r[WIND]}.omega")
    gen = _column(outcome, f"{r[GENERATOR]}.omega")
    if rotor is None or gen is None:
        return None
    ratio, source = ideal_ratio(system, outcome)
    if ratio is None:
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = gen / (ratio * rotor) - 1.0
    stats = window_statistics(outcome.time_s, dev, system.scenario.simulation.window_s)
    stats["max_abs"] = max(abs(stats["min"]), abs(stats["max"])) if np.isfinite(stats["min"]) else float("nan")
    return {"ratio": ratio, "ratio_source": source, "relative_deviation": stats}
