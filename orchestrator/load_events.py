"""Generator load events in scenarios: the ``[[events]]`` tables and their FMU event slots.

A scenario lists load events in time order of declaration::

    [[events]]
    kind = "grid_fault"       # torque_step | grid_fault | emergency_stop
    start = 10.0              # s, within [simulation.start, simulation.stop)
    duration = 0.5            # s, > 0 (torque_step: optional, default inf = permanent)
    # factor = 1.5            # torque_step: required, counter torque = factor x base torque
    #                         # emergency_stop: optional (default 1), counter torque = -|factor| x base
    #                         # grid_fault: not allowed (the torque drops to zero)
    # component = "generator" # optional: the FMU that takes the event (default: the only one with event slots)

Meaning (:class:`components.model.generator.LoadEvent`): ``torque_step`` sets the
generator counter torque to ``factor`` x base torque from ``start`` for
``duration``; ``grid_fault`` drops it to zero for ``duration``, then it returns;
``emergency_stop`` reverses it, ``-|factor|`` x base torque, for ``duration``.
Where events overlap the later one in the list wins.

Structural checks (kind, numbers, start inside the run) run when the scenario is
built (:class:`ScenarioEvent`, ``Scenario.__post_init__``). When the scenario is
checked against the FMUs' model descriptions (:func:`assign_events`, called by
:func:`orchestrator.system.resolve_system`; nothing is instantiated) each event
goes into the next free slot of its component: the GeneratorRotor FMU declares
slots ``event{i}.kind`` (Integer: 0 none, 1 torque_step, 2 grid_fault, 3
emergency_stop), ``event{i}.start`` [s], ``event{i}.duration`` [s] and
``event{i}.factor`` [-] for i = 1..4. More events than slots, a component without
slots, or slot parameters also set directly under ``[components.X.parameters]``
are errors naming the ``events[i]`` key. The monolithic reference reads the
same slot parameters (:func:`orchestrator.compare.monolithic_setup`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Mapping

from components.model.generator import EVENT_KINDS, LoadEvent
from components.validation import is_number

from .errors import ScenarioError
from .fmu_interface import FmuInterface

#: FMU code of each event kind in the ``event{i}.kind`` slot parameters (0 = no event)
EVENT_KIND_CODES = {kind: i + 1 for i, kind in enumerate(EVENT_KINDS)}
EVENT_KEYS = ("kind", "start", "duration", "factor", "component")
_SLOT_FIELDS = ("kind", "start", "duration", "factor")


@dataclass(frozen=True)
class ScenarioEvent:
    """One load event of a scenario (the ``[[events]]`` table), validated.

    Parameters
    ----------
    kind : {"torque_step", "grid_fault", "emergency_stop"}
    start_s : float
        Start time [s] (>= 0).
    duration_s : float
        Duration [s] (> 0; ``inf`` only for a permanent ``torque_step``).
    factor : float or None
        Torque factor [-]: required for ``torque_step``, optional for
        ``emergency_stop`` (default 1), not allowed for ``grid_fault``.
    component : str or None
        Component that takes the event; None: the only component with event slots.

    Raises
    ------
    ScenarioError
        Naming ``event.<field>`` (re-keyed to ``events[i].<field>`` by the scenario reader).
    """

    kind: str
    start_s: float
    duration_s: float = math.inf
    factor: float | None = None
    component: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise ScenarioError("event.kind", self.kind, "one of " + ", ".join(repr(k) for k in EVENT_KINDS))
        if not is_number(self.start_s) or not math.isfinite(self.start_s) or self.start_s < 0.0:
            raise ScenarioError("event.start", self.start_s, "a finite time >= 0 [s]")
        if not is_number(self.duration_s) or math.isnan(self.duration_s) or not self.duration_s > 0.0:
            raise ScenarioError("event.duration", self.duration_s, "a duration > 0 [s]")
        if math.isinf(self.duration_s) and self.kind != "torque_step":
            raise ScenarioError("event.duration", self.duration_s,
                                f"a finite duration [s] for a {self.kind} (only a torque_step may last forever)")
        factor = self.factor
        if self.kind == "torque_step" and factor is None:
            raise ScenarioError("event.factor", None, "a torque factor for a torque_step (counter torque = factor x "
                                "base torque), e.g. factor = 1.5 (missing)")
        if self.kind == "grid_fault" and factor is not None:
            raise ScenarioError("event.factor", factor, "no factor for a grid_fault (the counter torque drops to zero)")
        if self.kind == "emergency_stop" and factor is None:
            factor = 1.0
        if factor is not None and (not is_number(factor) or not math.isfinite(factor)):
            raise ScenarioError("event.factor", factor, "a finite number [-]")
        if self.component is not None and not isinstance(self.component, str):
            raise ScenarioError("event.component", self.component, "a component name (string)")
        object.__setattr__(self, "start_s", float(self.start_s))
        object.__setattr__(self, "duration_s", float(self.duration_s))
        object.__setattr__(self, "factor", None if factor is None else float(factor))

    @property
    def end_s(self) -> float:
        """End time [s] (``inf`` for a permanent torque step)."""
        return self.start_s + self.duration_s

    def load_event(self) -> LoadEvent:
        """The physics-core event (:class:`components.model.generator.LoadEvent`)."""
        return LoadEvent(self.kind, self.start_s, self.duration_s, 1.0 if self.factor is None else self.factor)

    def slot_values(self, slot: int) -> dict[str, int | float]:
        """Parameter values of FMU event slot ``slot`` (1-based): ``event{slot}.kind/start/duration/factor``."""
        return {
            f"event{slot}.kind": EVENT_KIND_CODES[self.kind],
            f"event{slot}.start": self.start_s,
            f"event{slot}.duration": self.duration_s,
            f"event{slot}.factor": 1.0 if self.factor is None else self.factor,
        }

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready description (``duration_s`` null for a permanent torque step)."""
        return {"kind": self.kind, "start_s": self.start_s,
                "duration_s": self.duration_s if math.isfinite(self.duration_s) else None,
                "factor": self.factor, "component": self.component}


def events_from_toml(items: Any, source: str | None = None) -> tuple[ScenarioEvent, ...]:
    """Read the ``[[events]]`` array of tables.

    Raises
    ------
    ScenarioError
        Naming ``events[i].<key>``.
    """
    if not isinstance(items, list):
        raise ScenarioError("events", items, "an array of tables [[events]] with kind, start, duration (, factor)", source)
    out = []
    for i, item in enumerate(items):
        path = f"events[{i}]"
        if not isinstance(item, dict):
            raise ScenarioError(path, item, "a table with kind = ..., start = ..., duration = ...", source)
        for key in item:
            if key not in EVENT_KEYS:
                raise ScenarioError(f"{path}.{key}", item[key], "a known key here: " + ", ".join(EVENT_KEYS), source)
        for key in ("kind", "start"):
            if key not in item:
                raise ScenarioError(f"{path}.{key}", None, ("an event kind: " + ", ".join(EVENT_KINDS)) if key == "kind"
                                    else "the start time [s] (missing)", source)
        if "duration" not in item and item["kind"] in ("grid_fault", "emergency_stop"):
            raise ScenarioError(f"{path}.duration", None, f"the duration [s] of the {item['kind']} (missing)", source)
        try:
            out.append(ScenarioEvent(
                kind=item["kind"], start_s=item["start"], duration_s=item.get("duration", math.inf),
                factor=item.get("factor"), component=item.get("component"),
            ))
        except ScenarioError as exc:
            raise ScenarioError(exc.key.replace("event.", f"{path}.", 1), exc.value, exc.expected, source) from None
    return tuple(out)


def check_events_in_run(events: tuple[ScenarioEvent, ...], start_s: float, stop_s: float, components: list[str],
                        source: str | None = None) -> None:
    """Every event starts inside the run ``[start, stop)`` and names a declared component (if any).

    Raises
    ------
    ScenarioError
        Naming ``events[i].start`` or ``events[i].component``.
    """
    for i, ev in enumerate(events):
        if not start_s <= ev.start_s < stop_s:
            raise ScenarioError(f"events[{i}].start", ev.start_s,
                                f"a start time inside the run, simulation.start <= start < simulation.stop = "
                                f"[{start_s:g}, {stop_s:g}) s", source)
        if ev.component is not None and ev.component not in components:
            raise ScenarioError(f"events[{i}].component", ev.component, "a declared component: " + ", ".join(components),
                                source)


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
                     if f"event{slot}.{f}" in variables else None for f in _SLOT_FIELDS[1:]}
            prefix = f"components.{comp.name}.parameters.event{slot}"
            if code not in kinds:
                raise ScenarioError(f"{prefix}.kind", code, "0 (none) or an event code: "
                                    + ", ".join(f"{c} {k}" for c, k in kinds.items()), scenario.source)
            kind = kinds[code]
            try:
                event = ScenarioEvent(kind, value["start"], value["duration"],
                                      None if kind == "grid_fault" else value["factor"], comp.name)
            except ScenarioError as exc:
                raise ScenarioError(exc.key.replace("event.", f"{prefix}.", 1), exc.value, exc.expected,
                                    scenario.source) from None
            found.append(AssignedEvent(event, comp.name, slot))
    return tuple(found)


def assign_events(scenario, interfaces: Mapping[str, FmuInterface]):
    """Map a scenario's events onto its FMUs' event slots.

    Parameters
    ----------
    scenario : orchestrator.scenario.Scenario
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
            if dot and head.startswith("event") and head[5:].isdigit() and tail in _SLOT_FIELDS:
                raise ScenarioError(f"components.{comp.name}.parameters.{pname}", comp.parameters[pname],
                                    "no event-slot parameter on a component that [[events]] fill (give the event "
                                    "as [[events]] only)", src)
        values = dict(comp.parameters)
        for a in assigned:
            if a.component == comp.name:
                values.update(a.event.slot_values(a.slot))
        components.append(replace(comp, parameters=values))
    return replace(scenario, components=tuple(components), events=()), tuple(assigned)
