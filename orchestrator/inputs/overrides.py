"""Changes to a scenario from outside its file: one set of rules for ``run``, ``sweep`` and ``export-ssp``.

A command line (``--stop``, ``--step``, ``--output-interval``, ``--algorithm``,
``--extrapolation``, ``--set C.P=V``) and a study (its ``[simulation]`` table
and parameter values) change a scenario the same way:

* the given time-grid values and master options replace the scenario's;
* with a new step the output interval, unless given too, stays the scenario's if
  it is a whole multiple of the step, and becomes the step otherwise;
* the analysis window, unless given, is kept if it lies inside the new run, and
  clipped to it otherwise: it ends at ``min(end, stop)`` and begins where it did
  if that is still inside, else at the start. A window that ended at the
  scenario's stop follows a later stop (``paper-60s`` run to 600 s analyses
  [5, 600] s, not [5, 60] s). The change is reported as a note, which the commands
  print as a warning;
* parameter values are set by ``component.parameter`` and checked against the
  FMUs like the scenario's own; a message about one names where it was given
  (``--set gearbox.stage1.backlash=0.3 (on top of paper-60s.toml)``, a study's axis:
  :mod:`orchestrator.inputs.origins`).
"""

from __future__ import annotations

import math

from dataclasses import dataclass, fields
from typing import Any, Mapping, Sequence

from ..errors import ScenarioError
from .origins import Origin, command_line
from .schema import ParameterValue

#: TOML / command-line key -> SimulationSettings field
SIMULATION_KEYS = {"start": "start_s", "stop": "stop_s", "step": "step_s", "output_interval": "output_interval_s",
                   "window": "window_s", "algorithm": "algorithm", "extrapolation": "extrapolation"}


@dataclass(frozen=True)
class SimulationOverrides:
    """Time-grid and master-option changes (None: keep the scenario's).

    Attributes
    ----------
    start_s, stop_s, step_s, output_interval_s : float or None
        [s].
    window_s : (float, float) or None
        Analysis window [s].
    algorithm, extrapolation : str or None
    """

    start_s: float | None = None
    stop_s: float | None = None
    step_s: float | None = None
    output_interval_s: float | None = None
    window_s: tuple[float, float] | None = None
    algorithm: str | None = None
    extrapolation: str | None = None

    def __post_init__(self) -> None:
        if self.window_s is not None:
            object.__setattr__(self, "window_s", tuple(float(w) for w in self.window_s))

    @classmethod
    def from_table(cls, table: Mapping[str, Any]) -> "SimulationOverrides":
        """From the keys of a ``[simulation]`` table (``start``, ``stop``, ...)."""
        return cls(**{SIMULATION_KEYS[k]: v for k, v in table.items() if v is not None})

    def as_table(self) -> dict[str, Any]:
        """The given values under their TOML keys (for a study's identity and report)."""
        keys = {v: k for k, v in SIMULATION_KEYS.items()}
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not None:
                out[keys[f.name]] = list(value) if isinstance(value, tuple) else value
        return out

    def __bool__(self) -> bool:
        return any(getattr(self, f.name) is not None for f in fields(self))

    def changes(self, sim) -> tuple[dict[str, Any], list[str]]:
        """The :class:`~orchestrator.inputs.scenario.SimulationSettings` changes and notes for ``sim``."""
        changes = {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}
        notes: list[str] = []
        # a step that is no finite number > 0 is left to the settings' validation (an error naming the key)
        if self.step_s is not None and self.output_interval_s is None and math.isfinite(self.step_s) \
                and self.step_s > 0.0:
            ratio = sim.output_interval_s / self.step_s
            if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-9 * ratio:
                changes["output_interval_s"] = self.step_s
                notes.append(f"output interval {sim.output_interval_s:g} s is no whole multiple of the new step "
                             f"{self.step_s:g} s: sampling every step")
        if self.window_s is None:
            start = changes.get("start_s", sim.start_s)
            stop = changes.get("stop_s", sim.stop_s)
            w0, w1 = sim.window_s
            if "stop_s" in changes and w1 == sim.stop_s < stop:  # the window ended at the stop: it follows it
                window = (w0 if start <= w0 < stop else start, stop)
                changes["window_s"] = window
                notes.append(f"analysis window moved from [{w0:g}, {w1:g}] s to [{window[0]:g}, {window[1]:g}] s: "
                             f"it ended at the stop ({sim.stop_s:g} s) and follows the new one")
            elif not (start <= w0 < w1 <= stop):
                end = min(w1, stop)
                window = (w0 if start <= w0 < end else start, end)
                changes["window_s"] = window
                notes.append(f"analysis window moved from [{w0:g}, {w1:g}] s to [{window[0]:g}, {window[1]:g}] s "
                             f"to fit the run [{start:g}, {stop:g}] s")
        return changes, notes

    def apply(self, scenario):
        """``(scenario with the changes, notes)``; the changed settings are validated again (ScenarioError).

        A new algorithm comes with the scenario's coupling for it (:meth:`Scenario.for_algorithm`: Jacobi's
        ``[jacobi]`` table), before the other changes (a step given here replaces its step).
        """
        if not self:
            return scenario, []
        if self.algorithm is not None:
            scenario = scenario.for_algorithm(self.algorithm)
        changes, notes = self.changes(scenario.simulation)
        return scenario.with_simulation(**changes), notes


def parse_value(text: str) -> ParameterValue:
    """A command-line value: ``true``/``false``, an integer, a number, else the text."""
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def parse_assignment(text: str, key: str = "--set") -> tuple[str, ParameterValue]:
    """``"wind.seed=7"`` -> ``("wind.seed", 7)``.

    Raises
    ------
    ScenarioError
        Naming ``key`` if the text is not ``COMPONENT.PARAMETER=VALUE``.
    """
    target, eq, value = text.partition("=")
    comp, dot, param = target.partition(".")
    if not eq or not dot or not comp.strip() or not param.strip():
        raise ScenarioError(key, text, "COMPONENT.PARAMETER=VALUE")
    return f"{comp.strip()}.{param.strip()}", parse_value(value)


def apply_parameters(scenario, values: Mapping[str, ParameterValue], origins: Mapping[str, Origin] | None = None):
    """The scenario with ``component.parameter`` values set (checked against the FMUs when resolved).

    ``origins``: where each value was given (a study's axis, a load-case entry; :mod:`orchestrator.inputs.origins`),
    which every message about the value names; without one, ``component.parameter = value`` on top of the scenario.
    """
    for name, value in values.items():
        comp, _, param = name.partition(".")
        origin = (origins or {}).get(name) or command_line(f"{name} = {value!r}", scenario.source)
        scenario = scenario.with_values(comp, {param: value}, {param: origin})
    return scenario


def apply_assignments(scenario, items: Sequence[str], option: str = "--set"):
    """The scenario with ``--set COMPONENT.PARAMETER=VALUE`` items set, each given by that option as typed."""
    values, origins = {}, {}
    for item in items:
        name, value = parse_assignment(item, option)
        values.pop(name, None)  # the last typed is the last set
        values[name], origins[name] = value, command_line(f"{option} {item.strip()}", scenario.source)
    return apply_parameters(scenario, values, origins)
