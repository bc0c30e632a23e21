"""A scenario checked against its FMUs' model descriptions.

:func:`resolve_system` reads every FMU's ``modelDescription.xml`` (the files it is given, found and
built by :mod:`orchestrator.provision`, or the ones the scenario names by path)
(nothing is instantiated) and checks what the master needs and every name the
scenario uses: each FMU is FMI 2.0 co-simulation with a binary for this platform;
parameters and start values exist, may be set before initialisation (FMI 2.0:
parameters, inputs and variables with ``initial="exact"`` or ``"approx"``) and have
the right type; connections join an output to an input of the same type (Real,
Integer, Boolean, String, or Enumeration of the same declared type; an Integer
and an Enumeration connect); initial bindings join an output to a parameter or
input of the same type; parameter bindings join a parameter to a settable parameter of another FMU of the same
type; record patterns match variables (any type); no algebraic
loop (with the scenario's ``no_feedthrough`` declarations for FMUs that omit their
output dependencies, ``"*"`` for all of a component's; iterated with
``algebraic_loops = "iterate"``; with Jacobi, a loop that passes an output without
declared dependencies is run as libcosim runs it, with a note in
``ResolvedSystem.notes``);
values given with a unit (``"0.56 mm"``) converted to the unit the FMU declares
(:mod:`orchestrator.cosim.declared_units`); every value within what the FMU accepts (FMI Integer range, declared bounds, a
dtcosim model's own validation: :mod:`orchestrator.cosim.parameter_checks`); values plausible by physics
(:mod:`orchestrator.cosim.plausibility_checks`); the
results within the size limits (:func:`check_sizes`). The first problem raises
:class:`~orchestrator.errors.ScenarioError` naming the scenario key (for a parameter value, the error of the
place it was given: :mod:`orchestrator.inputs.origins`). The result,
a :class:`~orchestrator.cosim.resolved.ResolvedSystem`, is what the master runs.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Mapping, Sequence


from ..errors import AlgebraicLoopError, ScenarioError, suggestion
from ..frozen_map import FrozenMap
from ..inputs.limits import MAX_RESULT_VALUES
from ..inputs.origins import origin_of
from ..inputs.scenario import Component, Scenario, VariableRef
from .declared_units import quantities_as_values
from .event_slots import assign_events
from .fmu_interface import FmuInterface, FmuVariable, read_fmu_interface
from .coupling_delays import FEEDTHROUGH, coupling_delays
from .graph import algebraic_loop_groups, dependency_order, find_algebraic_loop, initialization_order
from .parameter_checks import model_problem, type_problem, value_problem
from .plausibility_checks import plausibility_problem
from .resolved import RecordedVariable, ResolvedSystem
from .roles import declared_roles
from .values import transformation_problem, type_mismatch

#: causalities a scenario may give a value to
SETTABLE_CAUSALITIES = ("parameter", "input")
#: causalities a connection or initial binding may read from
READABLE_CAUSALITIES = ("output", "calculatedParameter")
#: causalities a parameter binding (``[[bindings]]``) may take its value from
BINDING_SOURCES = ("parameter", "calculatedParameter")


def find_fmu(scenario: Scenario, component: Component, candidates: Sequence[Path]) -> Path:
    """The first of ``candidates`` that is a file, absolute.

    Raises
    ------
    ScenarioError
        ``components.<name>.fmu`` when none is; the message lists the places searched.
    """
    found = next((p for p in candidates if p.is_file()), None)
    odd = next((p for p in candidates if p.exists() and not p.is_file()), None)
    if found is None and odd is not None:
        raise ScenarioError(f"components.{component.name}.fmu", str(component.fmu),
                            f"a regular FMU file ({odd} is a device, pipe or folder)", scenario.source)
    if found is None:
        raise ScenarioError(
            f"components.{component.name}.fmu", str(component.fmu),
            "an existing FMU file (looked in " + ", ".join(str(p.parent) for p in candidates) + ")",
            scenario.source,
        )
    return found.resolve()


def named_fmu_paths(scenario: Scenario) -> dict[str, Path]:
    """The FMU of every component where the scenario names it: absolute, or relative to the scenario's folder.

    An FMU built from a drivetrain file or a load record, or one in an FMU folder, is found (and built)
    by :func:`orchestrator.provision.project_fmus.ensure_fmus`, whose paths :func:`resolve_system` takes.

    Raises
    ------
    ScenarioError
        ``components.<name>.fmu`` when the file is not there, or is built from a drivetrain file or a
        load record (the co-simulation does not know where provisioning keeps those).
    """
    out = {}
    for comp in scenario.components:
        if comp.drivetrain is not None or comp.series is not None:
            raise ScenarioError(f"components.{comp.name}.fmu", str(comp.fmu),
                                "the path of the FMU built from its " + ("drivetrain file" if comp.series is None
                                                                         else "load record")
                                + " (orchestrator.provision.project_fmus.ensure_fmus finds and builds it)",
                                scenario.source)
        out[comp.name] = find_fmu(scenario, comp, scenario.fmu_candidates(comp, None))
    return out


#: FMI 2.0 (section 2.2.7, fmi2SetXXX before fmi2EnterInitializationMode): who may take a start value
START_VALUE_RULE = ('FMI 2.0 allows a start value before initialisation only for a variable that is not a constant '
                    'and has initial="exact" or initial="approx" (parameters, inputs, states such as '
                    'BouncingBall h)')


def takes_start_value(var: FmuVariable) -> bool:
    """True if FMI 2.0 lets a host set ``var`` before initialisation (parameter, input, exact/approx start)."""
    if var.variability == "constant" or var.causality == "independent":
        return False
    return var.causality in SETTABLE_CAUSALITIES or var.initial in ("exact", "approx")


def parameter_problem(iface: FmuInterface, pname: str) -> str | None:
    """What a value for variable ``pname`` of an FMU would have to be, or None if it may be set.

    A scenario or a study may give values to parameters and inputs that are not
    constants, and start values to the other variables FMI 2.0 lets a host set
    before initialisation (``initial="exact"`` or ``"approx"``, e.g. the states of
    BouncingBall); an unknown name gets the closest settable names as a suggestion.
    """
    var = iface.variables.get(pname)
    if var is None:
        settable = [n for n, v in iface.variables.items() if takes_start_value(v)]
        return f"a parameter or start value of {iface.model_name} ({iface.path.name}){suggestion(pname, settable)}"
    if not takes_start_value(var):
        return (f"a variable that can take a start value; {pname} has causality {var.causality}, variability "
                f"{var.variability}, initial {var.initial or '(none)'}: {START_VALUE_RULE}")
    return None


def _pattern_regex(pattern: str) -> re.Pattern:
    """``*`` and ``?`` are wildcards; everything else (dots, brackets) is literal."""
    return re.compile("".join(".*" if ch == "*" else "." if ch == "?" else re.escape(ch) for ch in pattern) + r"\Z")


def _lookup(iface: FmuInterface, ref: VariableRef, key: str, source: str | None, causalities: tuple[str, ...],
            role: str) -> FmuVariable:
    var = iface.variables.get(ref.variable)
    if var is None:
        names = [n for n, v in iface.variables.items() if v.causality in causalities]
        raise ScenarioError(key, str(ref), f"{role} of {iface.model_name} ({iface.path.name}){suggestion(ref.variable, names)}", source)
    if var.causality not in causalities:
        raise ScenarioError(key, str(ref), f"{role} (causality {' or '.join(causalities)}); {ref.variable} has causality {var.causality}", source)
    return var


def _same_type(source: FmuVariable, target: FmuVariable, key: str, link: str, src: str | None) -> None:
    problem = type_mismatch(source, target)
    if problem is not None:
        raise ScenarioError(key, link, f"variables of the same type at both ends; {problem}", src)


def resolve_system(scenario: Scenario, fmu_paths: Mapping[str, Path] | None = None) -> ResolvedSystem:
    """Check a scenario against its FMUs' model descriptions (nothing is instantiated).

    Parameters
    ----------
    scenario : Scenario
    fmu_paths : mapping of str -> path, optional
        The FMU file of every component (:func:`orchestrator.provision.project_fmus.ensure_fmus`,
        :func:`orchestrator.provision.locate.resolve_fmu_paths`); default: where the scenario
        names them (:func:`named_fmu_paths`).

    Raises
    ------
    ScenarioError
        Naming the first offending scenario key.
    AlgebraicLoopError
        If the connections close a direct-feedthrough loop.
    """
    src = scenario.source
    paths = dict(fmu_paths) if fmu_paths is not None else named_fmu_paths(scenario)
    interfaces = {c.name: read_fmu_interface(paths[c.name], f"components.{c.name}.fmu") for c in scenario.components}
    scenario, events = assign_events(scenario, interfaces)

    scenario = _enumeration_items_as_values(scenario, interfaces)
    scenario = quantities_as_values(scenario, interfaces)  # "0.56 mm" -> the declared unit's number
    connected_inputs = {str(c.target) for c in scenario.connections}
    for comp in scenario.components:
        iface = interfaces[comp.name]
        for pname, value in comp.parameters.items():
            key = f"components.{comp.name}.parameters.{pname}"
            var = iface.variables.get(pname)
            problem = parameter_problem(iface, pname)
            if problem is None and f"{comp.name}.{pname}" in connected_inputs:
                problem = "no value for an input that a connection drives"
            elif problem is None:
                problem = type_problem(var, value, pname) or value_problem(iface, var, value)
            if problem is not None:  # named where the value was given (the scenario, --set, a study, an SSP)
                raise origin_of(scenario, comp.name, pname).refusal(key, value, problem)

    for i, con in enumerate(scenario.connections):
        a = _lookup(interfaces[con.source.component], con.source, f"connections[{i}].from", src, READABLE_CAUSALITIES, "an output")
        b = _lookup(interfaces[con.target.component], con.target, f"connections[{i}].to", src, ("input",), "an input")
        _same_type(a, b, f"connections[{i}]", str(con), src)
        problem = transformation_problem(con.transformation, a, b, interfaces[con.source.component].enumerations,
                                         interfaces[con.target.component].enumerations)
        if problem is not None:
            raise ScenarioError(f"connections[{i}].transformation", con.transformation.describe(), problem, src)
    for i, b in enumerate(scenario.initial):
        out = _lookup(interfaces[b.source.component], b.source, f"initial[{i}].from", src, READABLE_CAUSALITIES, "an output")
        var = _lookup(interfaces[b.target.component], b.target, f"initial[{i}].to", src, SETTABLE_CAUSALITIES, "a parameter or input")
        if var.variability == "constant":
            raise ScenarioError(f"initial[{i}].to", str(b.target), "a settable (fixed or tunable) parameter", src)
        _same_type(out, var, f"initial[{i}]", str(b), src)

    for i, b in enumerate(scenario.bindings):
        value = _lookup(interfaces[b.source.component], b.source, f"bindings[{i}].from", src,
                        BINDING_SOURCES, "a parameter")
        var = _lookup(interfaces[b.target.component], b.target, f"bindings[{i}].to", src, ("parameter",),
                      "a parameter")
        if var.variability == "constant":
            raise ScenarioError(f"bindings[{i}].to", str(b.target), "a settable (fixed or tunable) parameter", src)
        _same_type(value, var, f"bindings[{i}]", str(b), src)

    recorded = _resolve_record(scenario, interfaces)

    feedthrough = _feedthrough(scenario, interfaces)
    links = [(str(c.source), str(c.target)) for c in scenario.connections]
    loop = find_algebraic_loop(links, feedthrough)
    loops: tuple[tuple[str, ...], ...] = ()
    solved: list[str] = []
    notes: list[str] = []
    if loop is not None and scenario.simulation.algebraic_loops != "iterate" \
            and scenario.simulation.algorithm == "jacobi" \
            and find_algebraic_loop(links, _feedthrough(scenario, interfaces, declared_only=True)) is None:
        notes.append(_jacobi_note(loop, interfaces))  # every loop passes an output without declared dependencies
        loop = None
    if loop is not None:
        if scenario.simulation.algebraic_loops != "iterate":
            raise AlgebraicLoopError(loop, src, _loop_hint(loop, interfaces))
        groups = algebraic_loop_groups(links, feedthrough)
        loops = _iterated_loops(scenario, interfaces, groups)
        solved = [v for group in groups for v in group]

    names = scenario.component_names
    sim = scenario.simulation
    default = tuple(dependency_order(names, links, feedthrough, solved))
    order = tuple(sim.order) if sim.order else default
    delays = coupling_delays(names, order, sim.algorithm, links, feedthrough,
                             declared=_feedthrough(scenario, interfaces, declared_only=True), solved=solved,
                             explicit=bool(sim.order), default_order=default)
    if notes:  # the Jacobi loop note already says that outputs without declared dependencies may lag a step
        delays = tuple(d for d in delays if not d.undeclared)
    # a pass-through read late is a coupling error nobody chose: said on every run; the lagging direction of a
    # feedback loop is the loop's deliberate explicit coupling: in summary.json (coupling_delays) and run --check
    notes += [d.note for d in delays if d.kind == FEEDTHROUGH]
    edges = [(c.source.component, c.target.component) for c in scenario.connections]
    init_edges = edges + [(b.source.component, b.target.component) for b in scenario.initial]
    init_order = tuple(initialization_order(names, init_edges))
    system = ResolvedSystem(
        scenario=scenario,
        fmu_paths=paths,
        interfaces=interfaces,
        order=order,
        init_order=init_order,
        recorded=recorded,
        events=events,
        roles=FrozenMap(declared_roles(scenario, interfaces)),
        algebraic_loops=loops,
        notes=tuple(notes),
        delays=delays,
    )
    problem = model_problem(system) or plausibility_problem(system)
    if problem is not None:
        raise problem
    check_sizes(system)
    return system


def check_sizes(system: ResolvedSystem) -> None:
    """Refuse a run whose results would exceed :data:`~orchestrator.inputs.limits.MAX_RESULT_VALUES`.

    Raises
    ------
    ScenarioError
        Naming ``simulation.output_interval``, the number of samples and columns and the limit.
    """
    sim = system.scenario.simulation
    rows = sim.n_steps // sim.output_stride + 1
    columns = len(system.recorded) + 1
    if rows * columns > MAX_RESULT_VALUES:
        raise ScenarioError(
            "simulation.output_interval", sim.output_interval_s,
            f"an interval giving at most {MAX_RESULT_VALUES:,} recorded values per run; this one gives {rows:,} "
            f"samples x {columns} columns (time and {len(system.recorded)} variables) = {rows * columns:,}: raise the "
            "output interval, shorten the run or record fewer variables", system.scenario.source)


def _enumeration_items_as_values(scenario: Scenario, interfaces: Mapping[str, FmuInterface]) -> Scenario:
    """Enumeration values given by item name (an SSP ``ssv:Enumeration``) as the item's integer value."""
    for comp in scenario.components:
        iface = interfaces[comp.name]
        changed = {}
        for pname, value in comp.parameters.items():
            var = iface.variables.get(pname)
            if var is not None and var.type == "Enumeration" and isinstance(value, str):
                items = iface.enumerations.get(var.declared_type, {})
                if value not in items:
                    raise origin_of(scenario, comp.name, pname).refusal(
                        f"components.{comp.name}.parameters.{pname}", value,
                        f"an item of {var.declared_type}: {', '.join(items) or 'none'}")
                changed[pname] = items[value]
        if changed:
            scenario = scenario.with_parameters(comp.name, **changed)
    return scenario


def _feedthrough(scenario: Scenario, interfaces: Mapping[str, FmuInterface],
                 declared_only: bool = False) -> dict[str, list[str]]:
    """``"comp.input" -> ["comp.output", ...]`` direct dependencies, less the scenario's ``no_feedthrough``.

    ``no_feedthrough = ["*"]`` means every output of the component whose model description
    declares no dependencies; ``declared_only`` leaves out all such outputs (only the
    dependencies the FMUs state).
    """
    src = scenario.source
    feedthrough: dict[str, list[str]] = {}
    for comp in scenario.components:
        iface = interfaces[comp.name]
        for i, out in enumerate(comp.no_feedthrough):
            if out == "*":
                continue
            key = f"components.{comp.name}.no_feedthrough[{i}]"
            var = iface.variables.get(out)
            if var is None or var.causality != "output":
                raise ScenarioError(key, out, f"an output of {iface.model_name}{suggestion(out, iface.outputs)} "
                                    "(or \"*\": every output without declared dependencies)", src)
            declared = iface.output_dependencies.get(out)
            if declared:
                raise ScenarioError(key, out, f"an output whose model description does not declare direct "
                                    f"dependencies; {out} depends on {', '.join(declared)}", src)
        every_undeclared = declared_only or "*" in comp.no_feedthrough
        for out in iface.outputs:
            if out in comp.no_feedthrough or (every_undeclared and iface.output_dependencies.get(out) is None):
                continue
            for inp in iface.direct_inputs_of(out):
                feedthrough.setdefault(f"{comp.name}.{inp}", []).append(f"{comp.name}.{out}")
    return feedthrough


def _undeclared_on(cycle: list[str], interfaces: Mapping[str, FmuInterface]) -> list[str]:
    """The outputs on a cycle whose model description declares no dependencies (FMI 2: on every input)."""
    out = []
    for name in cycle:
        comp, _, var = name.partition(".")
        iface = interfaces[comp]
        if var in iface.outputs and iface.output_dependencies.get(var) is None and name not in out:
            out.append(name)
    return out


def _jacobi_note(cycle: list[str], interfaces: Mapping[str, FmuInterface]) -> str:
    undeclared = _undeclared_on(cycle, interfaces)
    return (f"the connections close a loop ({' -> '.join(cycle)}) only through outputs that declare no "
            f"dependencies ({', '.join(undeclared)}; FMI 2 reads that as depending directly on every input); "
            "Jacobi gives every FMU its partners' outputs of the previous communication point, so it runs the "
            "system without an order, as libcosim does; where such an output does depend directly on its inputs, "
            "the coupling lags one step: --algebraic-loops iterate solves the loop at each point instead")


def _iterated_loops(scenario: Scenario, interfaces: Mapping[str, FmuInterface],
                    groups: list[list[str]]) -> tuple[tuple[str, ...], ...]:
    """The components of each algebraic loop the master iterates (in stepping order later); Real connections only.

    Raises
    ------
    ScenarioError
        ``connections[i]``: a connection on a loop between variables that are not Real
        (the iteration compares numbers).
    """
    out = []
    for group in groups:
        members = set(group)
        for i, c in enumerate(scenario.connections):
            if str(c.source) in members and str(c.target) in members \
                    and interfaces[c.target.component].variables[c.target.variable].type != "Real":
                raise ScenarioError(f"connections[{i}]", str(c), "a Real connection: simulation.algebraic_loops = "
                                    "\"iterate\" solves loops of Real variables only", scenario.source)
        out.append(tuple(dict.fromkeys(name.partition(".")[0] for name in group)))
    return tuple(out)


def _loop_hint(cycle: list[str], interfaces: Mapping[str, FmuInterface]) -> str:
    """How to state that an output on the loop does not feed through, for FMUs that do not say, or to iterate."""
    iterate = ('or, for a loop that is really there, let the master iterate it: --algebraic-loops iterate on the '
               'command line (a TOML scenario: [simulation] algebraic_loops = "iterate")')
    undeclared = _undeclared_on(cycle, interfaces)
    if not undeclared:
        return iterate
    options = " ".join(f"--no-feedthrough {n}" for n in undeclared)
    tables = "; ".join(f'[components.{n.partition(".")[0]}] no_feedthrough = ["{n.partition(".")[2]}"]'
                       for n in undeclared)
    return (f"{', '.join(undeclared)} {'has' if len(undeclared) == 1 else 'have'} no declared dependencies, which "
            f"FMI 2 reads as depending directly on every input; if an output does not, say so on the command line: "
            f"{options} (--no-feedthrough COMPONENT for all its outputs; a TOML scenario: {tables}); or run it "
            f"with --algorithm jacobi, which needs no order (as libcosim does); {iterate}")


def _resolve_record(scenario: Scenario, interfaces: Mapping[str, FmuInterface]) -> tuple[RecordedVariable, ...]:
    src = scenario.source
    out: list[RecordedVariable] = []
    seen: set[tuple[str, str]] = set()

    def add(comp: str, var: FmuVariable) -> None:
        if (comp, var.name) not in seen:
            seen.add((comp, var.name))
            out.append(RecordedVariable(comp, var.name, var.value_reference, var.unit, var.type))

    if not scenario.recorded:
        for comp in scenario.component_names:
            for name in interfaces[comp].outputs:
                add(comp, interfaces[comp].variables[name])
        return tuple(out)
    for i, pattern in enumerate(scenario.recorded):
        key = f"record.variables[{i}]"
        ref = VariableRef.parse(pattern, key, src)
        comp_rx = _pattern_regex(ref.component)
        var_rx = _pattern_regex(ref.variable)
        matched = 0
        for comp in scenario.component_names:
            if not comp_rx.match(comp):
                continue
            iface = interfaces[comp]
            exact = iface.variables.get(ref.variable)
            candidates = [exact] if exact is not None else [v for n, v in iface.variables.items() if var_rx.match(n)]
            for var in candidates:
                add(comp, var)
                matched += 1
        if not matched:
            comp = ref.component if ref.component in interfaces else None
            hint = suggestion(ref.variable, interfaces[comp].variables) if comp else ""
            raise ScenarioError(key, pattern, f"a name or pattern matching at least one variable{hint}", src)
    return tuple(out)
