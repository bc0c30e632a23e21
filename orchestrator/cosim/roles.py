"""Declared roles: what each component is in the drivetrain, and what its outputs are.

A dtcosim FMU declares its role (wind source, gearbox, generator) and the
signal kind of each drivetrain output (``contact_force``, ``shaft_torque``,
``generator_speed``, ...) in its record (:mod:`fmus.slaves.record`). A foreign
FMU has no record; a scenario may declare both for it::

    [components.gen]
    fmu = "MyGenerator.fmu"
    role = "generator"
    signals = { generator_speed = "w", generator_torque = "tau" }

The run analyses (:mod:`orchestrator.run.analyses`), plots and the physics view
(:mod:`orchestrator.cosim.physics_view`) use only these declarations: nothing is
applied because of a variable's name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from fmus.slaves.record import (
    GEARBOX,
    GENERATOR,
    ROLES,
    ROTOR,
    SIGNALS,
    TIME_SERIES,
    TORQUE_CONTROLLER,
    WIND_SOURCE,
)

from ..errors import ScenarioError, suggestion
from ..frozen_map import FrozenMap
from .fmu_interface import FmuInterface

__all__ = ["GEARBOX", "GENERATOR", "ROLES", "ROTOR", "SIGNALS", "TIME_SERIES", "TORQUE_CONTROLLER", "WIND_SOURCE",
           "ComponentRole", "Signal", "declared_roles"]


@dataclass(frozen=True)
class Signal:
    """An output declared as a drivetrain signal.

    Attributes
    ----------
    variable : str
        The FMU variable.
    kind : str
        Its signal kind (a key of :data:`SIGNALS` of the component's role).
    info : mapping of str -> str
        Details (``stage``, ``mesh``, ``planet``; ``shaft``, ``upstream``, ``downstream``; ``body``).
    """

    variable: str
    kind: str
    info: Mapping[str, str] = field(default_factory=FrozenMap)


@dataclass(frozen=True)
class ComponentRole:
    """The declared role of one component.

    Attributes
    ----------
    component : str
        Component (instance) name.
    role : str
        One of :data:`ROLES`.
    declared_by : str
        ``"record"`` (the dtcosim FMU's own record) or ``"scenario"`` (the scenario's ``role`` key).
    signals : tuple of Signal
        Its declared outputs, in the FMU's order.
    record : mapping or None
        The dtcosim record (physics model) of the FMU, None for a foreign FMU.
    """

    component: str
    role: str
    declared_by: str
    signals: tuple[Signal, ...] = ()
    record: Mapping | None = None

    def of_kind(self, kind: str) -> tuple[Signal, ...]:
        """The signals of one kind, in the FMU's order."""
        return tuple(s for s in self.signals if s.kind == kind)

    def variable(self, kind: str) -> str | None:
        """The one variable declared as ``kind`` (None if none is)."""
        found = self.of_kind(kind)
        return found[0].variable if found else None

    def column(self, kind: str) -> str | None:
        """``component.variable`` of the one variable of ``kind`` (None if none is)."""
        var = self.variable(kind)
        return None if var is None else f"{self.component}.{var}"


def _record_signals(record: Mapping) -> tuple[Signal, ...]:
    out = []
    for variable, entry in record["signals"].items():
        info = {k: str(v) for k, v in entry.items() if k != "signal"}
        out.append(Signal(variable, str(entry["signal"]), FrozenMap(info)))
    return tuple(out)


def declared_roles(scenario, interfaces: Mapping[str, FmuInterface]) -> dict[str, ComponentRole]:
    """Every component's declared role: from its FMU's record, else from the scenario (others have none).

    Parameters
    ----------
    scenario : orchestrator.inputs.scenario.Scenario
    interfaces : mapping of str -> FmuInterface

    Raises
    ------
    ScenarioError
        ``components.<name>.role`` contradicting the FMU's record, ``signals`` without a
        role, a signal kind the role does not have, a variable that is not an output of
        the FMU, several variables for a single-valued kind.
    """
    src = scenario.source
    out: dict[str, ComponentRole] = {}
    for comp in scenario.components:
        iface = interfaces[comp.name]
        record = iface.record
        key = f"components.{comp.name}"
        if record is not None:
            if comp.role is not None and comp.role != record["role"]:
                raise ScenarioError(f"{key}.role", comp.role,
                                    f"the role {iface.path.name} declares in its record ({record['role']}) or none", src)
            if comp.signals:
                raise ScenarioError(f"{key}.signals", dict(comp.signals),
                                    f"no signals: {iface.path.name} declares its own in its record", src)
            out[comp.name] = ComponentRole(comp.name, record["role"], "record", _record_signals(record), record)
            continue
        if comp.role is None:
            if comp.signals:
                raise ScenarioError(f"{key}.signals", dict(comp.signals),
                                    f"signals only together with role = one of {', '.join(ROLES)}", src)
            continue
        kinds = SIGNALS[comp.role]
        signals = []
        for kind, variables in comp.signals.items():
            if kind not in kinds:
                raise ScenarioError(f"{key}.signals.{kind}", list(variables),
                                    f"a signal of a {comp.role}: {', '.join(kinds)}{suggestion(kind, kinds)}", src)
            if not kinds[kind] and len(variables) != 1:
                raise ScenarioError(f"{key}.signals.{kind}", list(variables), "one variable name", src)
            for name in variables:
                var = iface.variables.get(name)
                if var is None or var.causality != "output" or var.type != "Real":
                    outputs = [n for n, v in iface.variables.items() if v.causality == "output"]
                    raise ScenarioError(f"{key}.signals.{kind}", name,
                                        f"a Real output of {iface.path.name}{suggestion(name, outputs)}", src)
                signals.append(Signal(name, kind))
        out[comp.name] = ComponentRole(comp.name, comp.role, "scenario", tuple(signals))
    return out
