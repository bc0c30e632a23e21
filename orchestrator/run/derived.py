"""Drivetrain quantities derived from a run: the ideal gearbox and the generator against it (Fig. 16).

The components are found by their declared roles (:mod:`orchestrator.cosim.roles`),
their outputs by their declared signals. The ideal gearbox ratio comes from the
Gearbox FMU's record (:func:`orchestrator.cosim.physics_view.gearbox_drivetrain`);
for a gearbox without a record, from its declared rotor and output speeds at the
start, ``omega_out(t0) / omega_rotor(t0)`` (a kinematically consistent start).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from components.reference.results import window_statistics

from ..cosim.outcome import RunOutcome
from ..cosim.physics_view import PhysicsUnavailable, gearbox_drivetrain
from ..cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE, ComponentRole
from ..cosim.resolved import ResolvedSystem


class Skipped(Exception):
    """An analysis cannot run on this system; the message says why (goes into ``summary.json``)."""


def single_role(system: ResolvedSystem, role: str) -> ComponentRole:
    """The one component declared with ``role`` (:class:`Skipped` naming the problem otherwise)."""
    found = system.with_role(role)
    if len(found) != 1:
        names = f" ({', '.join(r.component for r in found)})" if found else ""
        raise Skipped(f"needs exactly one component with the role {role}, the scenario has {len(found)}{names}")
    return found[0]


def recorded_signal(outcome: RunOutcome, role: ComponentRole, kind: str) -> np.ndarray:
    """Samples of the component's one output declared as ``kind`` (:class:`Skipped` if absent or unrecorded)."""
    column = role.column(kind)
    if column is None:
        raise Skipped(f"{role.component} ({role.role}) declares no {kind} output")
    try:
        return outcome.column(column)
    except KeyError:
        raise Skipped(f"{column} ({kind}) was not recorded") from None


def ideal_ratio(system: ResolvedSystem, outcome: RunOutcome) -> tuple[float, str]:
    """Kinematic ratio generator / rotor speed of the gearbox and where it came from (:class:`Skipped`)."""
    gearbox = single_role(system, GEARBOX)
    if gearbox.record is not None:
        try:
            return float(gearbox_drivetrain(system, gearbox.component).ratio), "the Gearbox FMU's record"
        except PhysicsUnavailable as exc:
            raise Skipped(str(exc)) from None
    rotor = recorded_signal(outcome, single_role(system, WIND_SOURCE), "rotor_speed")
    out = recorded_signal(outcome, gearbox, "output_speed")
    if not rotor.size or rotor[0] == 0:
        raise Skipped("the rotor speed at the start is zero: no ratio from the initial state")
    return float(out[0] / rotor[0]), "gearbox initial state omega_out(t0) / omega_rotor(t0)"


def generator_vs_ideal(system: ResolvedSystem, outcome: RunOutcome) -> dict[str, Any]:
    """Generator speed against ``ratio x rotor speed`` over the analysis window (paper Fig. 16).

    Returns
    -------
    dict
        ``{"ratio", "ratio_source", "relative_deviation": {"mean", "std", "min", "max", "max_abs"}}``
        where the deviation is ``omega_gen / (ratio omega_rotor) - 1``.

    Raises
    ------
    Skipped
        Without a wind source, a generator or a gearbox whose ratio is known, or
        their speeds unrecorded.
    """
    rotor = recorded_signal(outcome, single_role(system, WIND_SOURCE), "rotor_speed")
    gen = recorded_signal(outcome, single_role(system, GENERATOR), "generator_speed")
    ratio, source = ideal_ratio(system, outcome)
    with np.errstate(divide="ignore", invalid="ignore"):
        dev = gen / (ratio * rotor) - 1.0
    stats = window_statistics(outcome.time_s, dev, system.scenario.simulation.window_s)
    stats["max_abs"] = max(abs(stats["min"]), abs(stats["max"])) if np.isfinite(stats["min"]) else float("nan")
    return {"ratio": ratio, "ratio_source": source, "relative_deviation": stats}
