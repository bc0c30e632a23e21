"""A scenario's load events placed into its FMUs' event slots (read from the model descriptions only).

The GeneratorRotor FMU declares slots ``event{i}.kind`` (Integer: 0 none, 1
torque_step, 2 grid_fault, 3 emergency_stop), ``event{i}.start`` [s],
``event{i}.duration`` [s] and ``event{i}.factor`` [-] for i = 1..4. Each
``[[events]]`` entry (:mod:`orchestrator.inputs.load_events`) goes into the next
free slot of its component; more events than slots, a component without slots, or
slot parameters also set directly under ``[components.X.parameters]`` are errors
naming the ``events[i]`` key.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Mapping

from ..errors import ScenarioError
from ..inputs.load_events import EVENT_KIND_CODES, SLOT_FIELDS, ScenarioEvent
from ..inputs.origins import origin_of, responsible
from .fmu_interface import FmuInterface


def event_slot_count(iface: FmuInterface) -> int:
    """Number of load-event slots an FMU declares (``event1.kind``, ``event2.kind``, ...)."""
    n = 0
    while f"event{n + 1}.kind" in iface.variables:
        n += 1
    return n


@dataclass(frozen=True)
class AssignedEvent:
    """A scenario event placed into an FMU's event slot.

    Attributes
    ----------
    event : ScenarioEvent
    component : str
        Component (FMU instance) that applies it.
    slot : int
        1-based slot number (``event{slot}.*`` parameters).
    """

    event: ScenarioEvent
    component: str
    slot: int

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: the event with its component and slot."""
        return self.event.as_dict() | {"component": self.component, "slot": self.slot}


def _events_in_slot_parameters(scenario, interfaces: Mapping[str, FmuInterface],
                               slots: Mapping[str, int]) -> tuple[AssignedEvent, ...]:
    """Events a scenario sets directly as slot parameters (e.g. an imported SSP, ``--set``), for the report."""
    kinds = {code: kind for kind, code in EVENT_KIND_CODES.items()}
    found = []
    for comp in scenario.components:
        params = comp.parameters
        variables = interfaces[comp.name].variables
        for slot in range(1, slots.get(comp.name, 0) + 1):
            code = params.get(f"event{slot}.kind", variables[f"event{slot}.kind"].start)
            if not code:
                continue
            value = {f: params.get(f"event{slot}.{f}", variables[f"event{slot}.{f}"].start)
                     if f"event{slot}.{f}" in variables else None for f in SLOT_FIELDS[1:]}
            prefix = f"components.{comp.name}.parameters.event{slot}"
            if code not in kinds:
                raise origin_of(scenario, comp.name, f"event{slot}.kind").refusal(
                    f"{prefix}.kind", code, "0 (none) or an event code: " + ", ".join(f"{c} {k}" for c, k in kinds.items()))
            kind = kinds[code]
            try:
                event = ScenarioEvent(kind, value["start"], value["duration"],
                                      None if kind == "grid_fault" else value["factor"], comp.name)
            except ScenarioError as exc:  # named where the slot's value was given (or its kind, for the FMU's own)
                origin, own = responsible(scenario, comp.name, exc.key.replace("event.", f"event{slot}.", 1),
                                          [f"event{slot}.kind"])
                raise origin.refusal(exc.key.replace("event.", f"{prefix}.", 1), exc.value, exc.expected, own) from None
            found.append(AssignedEvent(event, comp.name, slot))
    return tuple(found)


def assign_events(scenario, interfaces: Mapping[str, FmuInterface]):
    """Map a scenario's events onto its FMUs' event slots.

    Parameters
    ----------
    scenario : orchestrator.inputs.scenario.Scenario
    interfaces : mapping of str -> FmuInterface
        Model description of each component (read, never instantiated).

    Returns
    -------
    scenario : Scenario
        The scenario with the slot parameters added to the target components and no
        ``events`` left (so that checking it again is a no-op).
    assigned : tuple of AssignedEvent
        Every event with its component and slot, in scenario order. A scenario without
        ``[[events]]`` reports the events its slot parameters set directly (an imported
        SSP, ``dtcosim run --set generator.event1.kind=2 ...``).

    Raises
    ------
    ScenarioError
        No component with event slots, ambiguous target, more events than slots,
        or slot parameters also given directly (names the ``events[i]`` key).
    """
    events = scenario.events
    src = scenario.source
    slots = {name: event_slot_count(iface) for name, iface in interfaces.items()}
    if not events:
        return scenario, _events_in_slot_parameters(scenario, interfaces, slots)
    with_slots = [name for name, n in slots.items() if n > 0]
    assigned: list[AssignedEvent] = []
    used: dict[str, int] = {}
    for i, ev in enumerate(events):
        target = ev.component
        if target is None:
            if len(with_slots) != 1:
                have = ", ".join(with_slots) if with_slots else "none of " + ", ".join(interfaces)
                raise ScenarioError(f"events[{i}].component", None,
                                    "the component that takes the event: exactly one FMU with load-event slots "
                                    f"(event1.kind, ... as in GeneratorRotor.fmu) or an explicit component; have {have}",
                                    src)
            target = with_slots[0]
        iface = interfaces[target]
        if slots[target] == 0:
            raise ScenarioError(f"events[{i}].component", target,
                                f"a component whose FMU has load-event slots (event1.kind, ...); {iface.path.name} "
                                f"({iface.model_name}) has none", src)
        slot = used.get(target, 0) + 1
        if slot > slots[target]:
            raise ScenarioError(f"events[{i}]", ev.as_dict(),
                                f"at most {slots[target]} load events for component {target!r}: {iface.path.name} has "
                                f"the event slots event1..event{slots[target]}", src)
        used[target] = slot
        assigned.append(AssignedEvent(ev, target, slot))
    components = []
    for comp in scenario.components:
        if comp.name not in used:
            components.append(comp)
            continue
        for pname in comp.parameters:
            head, dot, tail = pname.partition(".")
            if dot and head.startswith("event") and head[5:].isdigit() and tail in SLOT_FIELDS:
                raise origin_of(scenario, comp.name, pname).refusal(
                    f"components.{comp.name}.parameters.{pname}", comp.parameters[pname],
                    "no event-slot parameter on a component that [[events]] fill (give the event as [[events]] only)")
        values = dict(comp.parameters)
        for a in assigned:
            if a.component == comp.name:
                values.update(a.event.slot_values(a.slot))
        components.append(replace(comp, parameters=values))
    return replace(scenario, components=tuple(components), events=()), tuple(assigned)
