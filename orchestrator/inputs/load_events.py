"""Generator load events in scenarios: the ``[[events]]`` tables.

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
checked against the FMUs' model descriptions each event goes into the next free
event slot of its component (:mod:`orchestrator.cosim.event_slots`; nothing is
instantiated).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import AllowInfNan, Field

from components.model.generator import EVENT_KINDS, LoadEvent
from components.validation import is_number

from ..errors import ScenarioError
from .schema import Table

#: FMU code of each event kind in the ``event{i}.kind`` slot parameters (0 = no event)
EVENT_KIND_CODES = {kind: i + 1 for i, kind in enumerate(EVENT_KINDS)}
SLOT_FIELDS = ("kind", "start", "duration", "factor")


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


class EventTable(Table):
    """One ``[[events]]`` table of a scenario file."""

    kind: str = Field(description="an event kind: " + ", ".join(EVENT_KINDS))
    start: float = Field(description="the start time [s]")
    duration: Annotated[float, AllowInfNan(True)] | None = Field(
        None, description="a duration > 0 [s] (inf: a permanent torque_step)")
    factor: float | None = Field(None, description="a finite number [-] (the torque factor)")
    component: str | None = Field(None, description="a component name (string)")

    def event(self) -> ScenarioEvent:
        """The event (:class:`ScenarioEvent`; errors name ``event.<key>``)."""
        if self.duration is None and self.kind in ("grid_fault", "emergency_stop"):
            raise ScenarioError("event.duration", None, f"the duration [s] of the {self.kind} (missing)")
        return ScenarioEvent(kind=self.kind, start_s=self.start,
                             duration_s=math.inf if self.duration is None else self.duration,
                             factor=self.factor, component=self.component)


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


