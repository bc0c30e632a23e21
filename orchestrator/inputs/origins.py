"""Where a parameter value was given, so that a message about the value names that place.

A value reaches a scenario from its own file, the command line (``--set``), a study's axis or
point, a load-case set's entry or an SSP's parameter set. Whoever sets a value records its
:class:`Origin` with it (:attr:`orchestrator.inputs.scenario.Component.origins`): the scenario
reader (a value without a recorded origin is the scenario's own entry), the SSP reader (the
``ssv:Parameter``'s file and line), :func:`orchestrator.inputs.overrides.apply_parameters` for
``--set`` and studies, the study and load-case readers for their points. A check that refuses a
value builds its error from that origin (:meth:`Origin.refusal`); nothing works the origin out
afterwards from the key's or the file's name.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ..errors import EntryError, ScenarioError


@dataclass(frozen=True)
class Origin:
    """The place a parameter value was given.

    Attributes
    ----------
    source : str or None
        What the message starts with: the file (``paper-60s.toml``), the line of a file
        (``system.ssp!SystemStructure.ssd, line 12``), or the command line on top of a file
        (``--set gearbox.stage1.backlash=0.3 (on top of paper-60s.toml)``).
    key : str or None
        The entry of that file, where it is not the scenario's key
        (``axes[0].values[3] (gearbox.R1)``, ``operating_points[2].generator_torque (generator.counter_torque)``);
        None: the scenario's key (``components.gearbox.parameters.R1``) names the value.
    note : str
        Which run the value is set for (``point 3``), said after the expectation.
    error : type
        The :class:`~orchestrator.errors.EntryError` of that kind of file (its ``kind`` says
        ``scenario``, ``study``, ``load-case set``).
    """

    source: str | None
    key: str | None = None
    note: str = ""
    error: type = ScenarioError

    @property
    def holder(self) -> str:
        """The kind of input that holds the value (``"scenario"``, ``"study"``, ``"load-case set"``)."""
        return self.error.kind

    def refusal(self, key: str, value: Any, expected: str, own: bool = True) -> EntryError:
        """The error refusing ``value`` of the scenario key ``key``.

        ``own``: the value is the one given here (named by the origin's own key); otherwise the
        value is one nobody gave (an FMU's own), refused because of the value given here,
        which the message then names after the expectation.
        """
        said = [self.note] if own or not self.key else [f"given with {self.key}", self.note]
        said = [s for s in said if s]
        return self.error(self.key if own and self.key else key, value,
                          expected + (f" ({', '.join(said)})" if said else ""), self.source)


def command_line(option: str, scenario_source: str | None) -> Origin:
    """``--set gearbox.stage1.backlash=0.3 (on top of paper-60s.toml)``: an option as typed, on top of its scenario."""
    return Origin(f"{option} (on top of {scenario_source})" if scenario_source else option)


def origin_of(scenario, component: str, parameter: str) -> Origin:
    """Where ``component.parameter``'s value in ``scenario`` was given (the scenario's own entry unless recorded)."""
    return scenario.component(component).origins.get(parameter) or Origin(scenario.source)


def responsible(scenario, component: str, parameter: str, given=None) -> tuple[Origin, bool]:
    """``(origin, own)`` of a refused value: its own origin if ``parameter`` is given, else the last given one.

    A value nobody gave (the FMU's own, refused with the values given around it) is blamed on
    the last value set of ``given`` (parameter names of ``component``; default all it gives),
    ``own`` False; with nothing given, on the scenario itself.
    """
    comp = scenario.component(component)
    if parameter in comp.parameters:
        return origin_of(scenario, component, parameter), True
    return last_given(comp.origins, comp.parameters if given is None else given, Origin(scenario.source)), False


def last_given(origins: Mapping[str, Origin], names, fallback: Origin) -> Origin:
    """The origin of the last of ``names`` set (``origins`` in the order values were set), else ``fallback``."""
    names = set(names)
    return next((o for n, o in reversed(list(origins.items())) if n in names), fallback)
