"""System description of a co-simulation scenario, and its TOML format.

A :class:`Scenario` says which FMUs take part (with parameter values), how their
variables are connected, which outputs set which parameters at initialisation,
how the master steps them and what is recorded. It is a frozen, validated value:
structural mistakes (unknown key, wrong type, step <= 0, stop <= start, an input
connected twice, ...) raise :class:`~orchestrator.errors.ScenarioError` naming the
key when the object is built, before any FMU file is opened. The checks that need
the FMUs' model descriptions (variable names, causalities, types) are in
:mod:`orchestrator.cosim.system`; they read XML only and instantiate nothing.

The TOML file format and its reading are :mod:`orchestrator.inputs.scenario_file`.
"""


from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

from fmus import registry
from fmus.slaves.record import ROLES

from ..errors import ScenarioError
from ..frozen_map import FrozenMap
from .analysis_settings import AnalysisSettings
from .drivetrain_file import DrivetrainSpec
from .load_events import ScenarioEvent, check_events_in_run
from .origins import Origin
from .results_format import RESULTS_FORMATS
from .series_spec import SeriesSpec
from .schema import NAME_PATTERN, ParameterValue
from .simulation_settings import SimulationSettings, steps_between
from .transformations import Transformation

__all__ = ["Component", "Connection", "InitialBinding", "JacobiCoupling", "ParameterBinding", "Scenario",
           "SimulationSettings", "VariableRef", "steps_between"]


@dataclass(frozen=True)
class VariableRef:
    """A variable of one component, written ``"component.variable"`` in a scenario.

    The component name is the part before the first dot; the variable name (which
    may itself contain dots and brackets, e.g. ``stage1.F_sp[1]``) is the rest.
    """

    component: str
    variable: str

    @classmethod
    def parse(cls, text: Any, key: str, source: str | None = None) -> "VariableRef":
        """Parse ``"component.variable"``; a malformed value raises ScenarioError naming ``key``."""
        if not isinstance(text, str):
            raise ScenarioError(key, text, 'a string "component.variable"', source)
        comp, dot, var = text.partition(".")
        if not dot or not comp or not var or not NAME_PATTERN.match(comp):
            raise ScenarioError(key, text, 'a string "component.variable"', source)
        return cls(comp, var)

    def __str__(self) -> str:
        return f"{self.component}.{self.variable}"


@dataclass(frozen=True)
class Component:
    """One FMU instance of the system.

    Parameters
    ----------
    name : str
        Instance name (letters, digits, ``_``, ``-``; no dots).
    fmu : pathlib.Path
        FMU file as written in the scenario (may be relative, see
        :meth:`Scenario.fmu_candidates`).
    parameters : mapping of str -> float, int, bool or str
        Start values of parameters (or unconnected inputs) by FMU variable name.
    role : str, optional
        What a foreign FMU is in the drivetrain (``wind_source``, ``gearbox``,
        ``generator``; :mod:`orchestrator.cosim.roles`). dtcosim FMUs declare their own.
    signals : mapping of str -> tuple of str
        With ``role``: signal kind -> the FMU outputs that are that signal
        (``{"generator_speed": ("w",)}``).
    drivetrain : DrivetrainSpec, optional
        The drivetrain file this project FMU (``Gearbox.fmu`` or ``GeneratorRotor.fmu``) is
        built from (:mod:`orchestrator.inputs.drivetrain_file`); the FMU lives in a folder
        of the FMU directory keyed by the file's content (:meth:`Scenario.fmu_candidates`).
    no_feedthrough : tuple of str
        Outputs that do not depend directly on any input, for an FMU whose model
        description does not say (no ``dependencies`` attribute: FMI 2 then means
        "depends on all inputs"); a loop through them is not algebraic. ``"*"``:
        every output of the FMU without declared dependencies (``--no-feedthrough COMPONENT``).
    origins : mapping of str -> Origin
        Where parameter values were given, in the order they were set (:mod:`orchestrator.inputs.origins`);
        a value without one is the scenario's own entry.
    """

    name: str
    fmu: Path
    parameters: Mapping[str, ParameterValue] = field(default_factory=dict)
    role: str | None = None
    signals: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    drivetrain: DrivetrainSpec | None = None
    no_feedthrough: tuple[str, ...] = ()
    series: SeriesSpec | None = None
    origins: Mapping[str, Origin] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not NAME_PATTERN.match(self.name):
            raise ScenarioError("components", self.name, "a component name of letters, digits, '_' or '-' (no dots)")
        object.__setattr__(self, "fmu", Path(self.fmu))
        params = dict(self.parameters)
        object.__setattr__(self, "origins", FrozenMap(self.origins))
        for pname, value in params.items():
            if not isinstance(value, (int, float, bool, str)):
                raise self.origins.get(pname, Origin(None)).refusal(f"components.{self.name}.parameters.{pname}",
                                                                    value, "a number, boolean or string")
        object.__setattr__(self, "parameters", FrozenMap(params))
        if self.role is not None and self.role not in ROLES:
            raise ScenarioError(f"components.{self.name}.role", self.role, "one of " + ", ".join(ROLES))
        signals = {}
        for kind, names in dict(self.signals).items():
            names = (names,) if isinstance(names, str) else names
            if not isinstance(names, (list, tuple)) or not names or not all(isinstance(n, str) for n in names):
                raise ScenarioError(f"components.{self.name}.signals.{kind}", names,
                                    "an output name or a list of output names")
            signals[kind] = tuple(names)
        object.__setattr__(self, "signals", FrozenMap(signals))
        kind = registry.of_file(self.fmu)
        if self.drivetrain is not None and (kind is None or registry.DRIVETRAIN_FILE not in kind.built_from):
            raise ScenarioError(f"components.{self.name}.drivetrain", self.drivetrain.name,
                                "a drivetrain file only for a project FMU built from it: fmu = "
                                + " or ".join(f'"{k.file_name}"' for k in registry.built_from(registry.DRIVETRAIN_FILE))
                                + f" (not {str(self.fmu)!r})")
        if self.series is not None and (kind is None or registry.LOAD_RECORD not in kind.built_from):
            raise ScenarioError(f"components.{self.name}.series", self.series.record.name,
                                "a series only for fmu = "
                                + " or ".join(f'"{k.file_name}"' for k in registry.built_from(registry.LOAD_RECORD))
                                + f" (not {str(self.fmu)!r})")
        outputs = (self.no_feedthrough,) if isinstance(self.no_feedthrough, str) else self.no_feedthrough
        if not isinstance(outputs, (list, tuple)) or not all(isinstance(n, str) and n for n in outputs):
            raise ScenarioError(f"components.{self.name}.no_feedthrough", self.no_feedthrough,
                                "a list of output names")
        object.__setattr__(self, "no_feedthrough", tuple(outputs))


@dataclass(frozen=True)
class Connection:
    """Output ``source`` drives input ``target`` at every communication step.

    ``transformation`` (from an SSP connection: linear, or a Boolean/Integer/Enumeration
    mapping; :mod:`orchestrator.inputs.transformations`) changes the value on the way;
    the target receives, and records, the transformed value.
    """

    source: VariableRef
    target: VariableRef
    transformation: Transformation | None = None

    def __str__(self) -> str:
        return f"{self.source} -> {self.target}"


@dataclass(frozen=True)
class InitialBinding:
    """Parameter (or input) ``target`` is set from output ``source`` during initialisation.

    Example: the generator's initial speed from the gearbox's output speed, which
    itself follows from the rotor speed at t = start.
    """

    source: VariableRef
    target: VariableRef

    def __str__(self) -> str:
        return f"{self.source} => {self.target}"


@dataclass(frozen=True)
class ParameterBinding:
    """Parameter ``target`` takes the value of parameter ``source`` of another FMU: one value, one source.

    Example: the Gearbox's interface model needs the generator's inertia
    (``gearbox.generator_inertia``), which is the GeneratorRotor's ``inertia``. The
    master reads the source's value through FMI once the FMUs have their start values
    and sets the target before anything is computed from it
    (:mod:`orchestrator.cosim.initialisation`); the target takes no value of its own.
    """

    source: VariableRef
    target: VariableRef

    def __str__(self) -> str:
        return f"{self.target} = {self.source}"


@dataclass(frozen=True)
class JacobiCoupling:
    """How the system is coupled when it is stepped with Jacobi (the ``[jacobi]`` table).

    A host that exchanges values after every component stepped (Jacobi: libcosim, ecos) gives
    each component its partners' values of the last communication point; a cut designed for
    Gauss-Seidel may then need other interface settings and connections (the paper scenario:
    the Gearbox's ``inertia_own`` interface and a generator that follows it) and another step.
    :meth:`Scenario.for_algorithm` applies them; ``dtcosim export-ssp --target libcosim|ecos``
    and ``--algorithm jacobi`` use it.

    Attributes
    ----------
    step_s : float or None
        Communication step under Jacobi [s] (None: the scenario's).
    step_criteria : str
        What the step was chosen by (written into an exported SSD and printed).
    parameters : mapping of str -> mapping of str -> value
        Component -> parameter values that replace the scenario's.
    connections : tuple of Connection
        Connections added to the scenario's.
    """

    step_s: float | None = None
    step_criteria: str = ""
    parameters: Mapping[str, Mapping[str, ParameterValue]] = field(default_factory=dict)
    connections: tuple[Connection, ...] = ()

    def describe(self) -> str:
        """``"gearbox.generator_interface = 2, ..., gearbox.omega_generator -> generator.omega_gearbox"``."""
        items = [f"{comp}.{name} = {value}" for comp, values in self.parameters.items() for name, value in values.items()]
        return ", ".join(items + [str(c) for c in self.connections])


@dataclass(frozen=True)
class Scenario:
    """A complete, structurally valid co-simulation scenario.

    Parameters
    ----------
    name : str
        Scenario name (names the results directory).
    components : tuple of Component
        FMU instances, in declaration order.
    connections : tuple of Connection
        Output -> input couplings.
    simulation : SimulationSettings
        Time grid and master options.
    initial : tuple of InitialBinding
        Output -> parameter assignments made during initialisation.
    bindings : tuple of ParameterBinding
        Parameters that take the value of another FMU's parameter (``[[bindings]]``).
    recorded : tuple of str
        The recorded variables (the ``[record]`` table's ``variables``): ``"component.name"`` or
        ``"component.pattern"`` with ``*``/``?`` wildcards; empty means every output of every component.
    description : str
        Free text.
    base_dir : pathlib.Path, optional
        Directory relative FMU paths are resolved against first (the scenario
        file's directory).
    source : str, optional
        File the scenario was read from (used in error messages).
    events : tuple of ScenarioEvent
        Generator load events (``[[events]]``); each must start inside the run.
    analysis : AnalysisSettings
        Settings of the result analyses (``[analysis]``).
    results_format : {"auto", "csv", "parquet"}
        File the samples go to (``[record] format``, :mod:`orchestrator.inputs.results_format`).
    import_notes : tuple of str
        What the SSP import passed over (other tools' annotations, skipped mapping
        entries, parameter values not applied); listed in the run's summary.
    allow_implausible : tuple of str
        ``"component.parameter"`` values kept although implausible by physics (``[plausibility] allow``,
        ``--allow-implausible``; :mod:`orchestrator.cosim.plausibility_checks`).
    jacobi : JacobiCoupling or None
        How the system is coupled when stepped with Jacobi (``[jacobi]``; applied by
        :meth:`for_algorithm`).
    """

    name: str
    components: tuple[Component, ...]
    connections: tuple[Connection, ...]
    simulation: SimulationSettings
    initial: tuple[InitialBinding, ...] = ()
    recorded: tuple[str, ...] = ()
    description: str = ""
    base_dir: Path | None = None
    source: str | None = None
    events: tuple[ScenarioEvent, ...] = ()
    analysis: AnalysisSettings = field(default_factory=AnalysisSettings)
    results_format: str = "auto"
    import_notes: tuple[str, ...] = ()
    bindings: tuple[ParameterBinding, ...] = ()
    allow_implausible: tuple[str, ...] = ()
    jacobi: JacobiCoupling | None = None

    def __post_init__(self) -> None:
        src = self.source
        if not isinstance(self.name, str) or not NAME_PATTERN.match(self.name):
            raise ScenarioError("name", self.name, "a name of letters, digits, '_' or '-'", src)
        object.__setattr__(self, "components", tuple(self.components))
        object.__setattr__(self, "connections", tuple(self.connections))
        object.__setattr__(self, "initial", tuple(self.initial))
        object.__setattr__(self, "recorded", tuple(self.recorded))
        if not self.components:
            raise ScenarioError("components", {}, "at least one component", src)
        names = [c.name for c in self.components]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ScenarioError(f"components.{dup[0]}", dup[0], "unique component names", src)
        known = set(names)
        driven: dict[str, str] = {}
        for i, con in enumerate(self.connections):
            for end, ref in (("from", con.source), ("to", con.target)):
                if ref.component not in known:
                    raise ScenarioError(f"connections[{i}].{end}", str(ref), "a variable of a declared component: " + ", ".join(names), src)
            if con.source.component == con.target.component:
                raise ScenarioError(f"connections[{i}].to", str(con.target), f"a variable of another component than {con.source.component!r}", src)
            tgt = str(con.target)
            if tgt in driven:
                raise ScenarioError(f"connections[{i}].to", tgt, f"an input connected once (already driven by {driven[tgt]})", src)
            driven[tgt] = str(con.source)
        set_initially: dict[str, int] = {}
        for i, b in enumerate(self.initial):
            for end, ref in (("from", b.source), ("to", b.target)):
                if ref.component not in known:
                    raise ScenarioError(f"initial[{i}].{end}", str(ref), "a variable of a declared component: " + ", ".join(names), src)
            tgt = str(b.target)
            if tgt in driven:
                raise ScenarioError(f"initial[{i}].to", tgt, f"a variable not also driven by a connection (from {driven[tgt]})", src)
            if tgt in set_initially:
                raise ScenarioError(f"initial[{i}].to", tgt, f"a variable set once (already by initial[{set_initially[tgt]}])", src)
            comp = next(c for c in self.components if c.name == b.target.component)
            if b.target.variable in comp.parameters:  # named where that value was given
                raise comp.origins.get(b.target.variable, Origin(src)).refusal(
                    f"initial[{i}].to", tgt, f"a variable without a value in components.{comp.name}.parameters", own=False)
            set_initially[tgt] = i
        object.__setattr__(self, "bindings", tuple(self.bindings))
        self._check_bindings(known, names, driven, set_initially)
        for i, pattern in enumerate(self.recorded):
            ref = VariableRef.parse(pattern, f"record.variables[{i}]", src)
            if ref.component not in known and not any(ch in ref.component for ch in "*?"):
                raise ScenarioError(f"record.variables[{i}]", pattern, "a variable of a declared component: " + ", ".join(names), src)
        order = self.simulation.order
        if order is not None and sorted(order) != sorted(names):
            raise ScenarioError("simulation.order", list(order), "each component exactly once: " + ", ".join(names), src)
        object.__setattr__(self, "events", tuple(self.events))
        for i, ev in enumerate(self.events):
            if not isinstance(ev, ScenarioEvent):
                raise ScenarioError(f"events[{i}]", ev, "a ScenarioEvent", src)
        check_events_in_run(self.events, self.simulation.start_s, self.simulation.stop_s, names, src)
        for comp in self.components:
            if comp.series is not None:  # a record shorter than the run: refused before any FMU exists
                comp.series.check_covers(self.simulation.start_s, self.simulation.stop_s,
                                         f"components.{comp.name}.series."
                                         + ("records" if comp.series.selectable else "record"), src)
        if not isinstance(self.analysis, AnalysisSettings):
            raise ScenarioError("analysis", self.analysis, "an AnalysisSettings", src)
        if self.results_format not in RESULTS_FORMATS:
            raise ScenarioError("record.format", self.results_format, "one of " + ", ".join(RESULTS_FORMATS), src)
        object.__setattr__(self, "allow_implausible", tuple(dict.fromkeys(self.allow_implausible)))

    def _check_bindings(self, known: set[str], names: list[str], driven: Mapping[str, str],
                        set_initially: Mapping[str, int]) -> None:
        """Each binding joins declared components, sets its target once, from no cycle, with no value of its own."""
        src = self.source
        bound: dict[str, str] = {}
        for i, b in enumerate(self.bindings):
            for end, ref in (("from", b.source), ("to", b.target)):
                if ref.component not in known:
                    raise ScenarioError(f"bindings[{i}].{end}", str(ref), "a variable of a declared component: "
                                        + ", ".join(names), src)
            tgt = str(b.target)
            if b.source.component == b.target.component:
                raise ScenarioError(f"bindings[{i}].to", tgt, f"a parameter of another component than "
                                    f"{b.source.component!r} (a binding joins two FMUs)", src)
            if tgt in bound:
                raise ScenarioError(f"bindings[{i}].to", tgt, f"a parameter bound once (already to {bound[tgt]})", src)
            if tgt in driven or tgt in set_initially:
                other = f"the connection from {driven[tgt]}" if tgt in driven else f"initial[{set_initially[tgt]}]"
                raise ScenarioError(f"bindings[{i}].to", tgt, f"a parameter not also set by {other}", src)
            bound[tgt] = str(b.source)
        for b in self.bindings:  # a chain a -> b -> c is fine, a cycle has no source
            seen, ref = [str(b.target)], str(b.source)
            while ref in bound:
                if ref in seen:
                    raise ScenarioError("bindings", " = ".join(seen + [ref]), "bindings without a cycle (a bound "
                                        "value needs one parameter that is set, not bound)", src)
                seen.append(ref)
                ref = bound[ref]
        for comp in self.components:
            for pname, value in comp.parameters.items():
                key = f"{comp.name}.{pname}"
                if key in bound:
                    raise comp.origins.get(pname, Origin(src)).refusal(
                        f"components.{comp.name}.parameters.{pname}", value,
                        f"no value: {key} takes its value from {bound[key]} ([[bindings]]: one source for a value "
                        f"two FMUs need; a value here would break the link); set {bound[key]} instead (--set "
                        f"{bound[key]}=...), or remove the binding")

    def bound_source(self, ref: "VariableRef | str") -> str | None:
        """``"component.parameter"`` whose value ``ref`` takes through the bindings (the chain's start), or None."""
        bound = {str(b.target): str(b.source) for b in self.bindings}
        key, found = str(ref), None
        while key in bound:
            key = found = bound[key]
        return found

    # ------------------------------------------------------------------ access
    def component(self, name: str) -> Component:
        """The component called ``name``."""
        for c in self.components:
            if c.name == name:
                return c
        raise KeyError(name)

    @property
    def component_names(self) -> list[str]:
        """Component names in declaration order."""
        return [c.name for c in self.components]

    def with_simulation(self, **changes) -> "Scenario":
        """Copy with some :class:`SimulationSettings` fields replaced (validated again)."""
        return replace(self, simulation=replace(self.simulation, **changes))

    def for_algorithm(self, algorithm: str, **changes) -> "Scenario":
        """The scenario stepped with ``algorithm``: with Jacobi, its :class:`JacobiCoupling` applied.

        The coupling's parameter values replace the scenario's, its connections are added and
        its step (if any) becomes the scenario's; the result declares no coupling of its own.
        ``changes`` are :class:`SimulationSettings` fields set at the same time (they win over
        the coupling's step).
        """
        if algorithm != "jacobi" or self.jacobi is None:
            return self.with_simulation(algorithm=algorithm, **changes)
        coupling, scenario = self.jacobi, self
        for comp, values in coupling.parameters.items():
            scenario = scenario.with_values(comp, values, {p: Origin(self.source, f"jacobi.parameters.{comp}.{p}")
                                                           for p in values})
        step = {} if coupling.step_s is None else {"step_s": coupling.step_s}
        return replace(scenario, connections=scenario.connections + coupling.connections, jacobi=None,
                       simulation=replace(scenario.simulation, algorithm="jacobi", **{**step, **changes}))

    def with_parameters(self, component: str, **values: ParameterValue) -> "Scenario":
        """Copy with parameter values of one component added or replaced, each where its value was given before."""
        return self.with_values(component, values, {})

    def with_values(self, component: str, values: Mapping[str, ParameterValue],
                    origins: Mapping[str, Origin]) -> "Scenario":
        """Copy with values of one component set, given at ``origins`` (a value without one keeps its origin)."""
        if component not in self.component_names:
            raise next(iter(origins.values()), Origin(self.source)).refusal(
                "components", component, "a declared component: " + ", ".join(self.component_names), own=False)
        comps = tuple(replace(c, parameters={**c.parameters, **values},
                              origins={**{k: o for k, o in c.origins.items() if k not in origins}, **origins})
                      if c.name == component else c for c in self.components)
        return replace(self, components=comps)

    def with_allowed(self, *keys: str) -> "Scenario":
        """Copy that keeps these ``"component.parameter"`` values although implausible (``--allow-implausible``)."""
        return replace(self, allow_implausible=self.allow_implausible + tuple(keys))

    def with_no_feedthrough(self, item: str) -> "Scenario":
        """Copy where ``"component.output"`` (or ``"component"``: all its undeclared outputs) does not feed through.

        The command line's ``--no-feedthrough``; the FMU's model description is checked
        when the system is resolved (:func:`orchestrator.cosim.system.resolve_system`).
        """
        component, _, output = str(item).partition(".")
        if component not in self.component_names:
            raise ScenarioError("--no-feedthrough", item, "COMPONENT or COMPONENT.OUTPUT of a declared component: "
                                + ", ".join(self.component_names), self.source)
        comps = tuple(replace(c, no_feedthrough=c.no_feedthrough + (output or "*",)) if c.name == component else c
                      for c in self.components)
        return replace(self, components=comps)

    def fmu_candidates(self, component: Component, fmu_dir: Path | None = None) -> list[Path]:
        """Where the FMU path a component names is looked for, in order.

        An absolute path is used as is; a relative one is tried against the
        scenario's directory, then the FMU folder ``fmu_dir``. (A component built
        from a drivetrain file or a load record is found by provisioning instead:
        :func:`orchestrator.provision.locate.fmu_candidates`.)
        """
        if component.fmu.is_absolute():
            return [component.fmu]
        out = []
        if self.base_dir is not None:
            out.append(self.base_dir / component.fmu)
        if fmu_dir is not None:
            out.append(Path(fmu_dir) / component.fmu)
        if not out:
            out.append(Path.cwd() / component.fmu)
        return out
