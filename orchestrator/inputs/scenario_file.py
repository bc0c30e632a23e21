"""Scenario files (TOML): their tables, reading one into a :class:`~orchestrator.inputs.scenario.Scenario`, finding one.

Every mistake is a :class:`~orchestrator.errors.ScenarioError` naming the file and the key.

TOML format (units SI; see ``docs/orchestrator.md`` for the full reference)::

    name = "paper-60s"                    # optional, default: file stem
    description = "..."                   # optional

    [simulation]
    start = 0.0                           # s, default 0
    stop = 60.0                           # s, required, > start
    step = 1e-3                           # s, communication step H, required, > 0
    output_interval = 1e-3                # s, multiple of step, default step
    window = [5.0, 60.0]                  # s, analysis window, default [start, stop]
    algorithm = "gauss-seidel"            # or "jacobi"
    extrapolation = "hold"                # or "linear"
    order = ["wind", "gearbox", "generator"]  # optional stepping order
    algebraic_loops = "refuse"            # or "iterate": solve direct-feedthrough loops by fixed-point iteration
    loop_tolerance = 1e-10                # iteration stops when every loop input moves by <= tol x max(1, |u|)
    loop_max_iterations = 100             # ... or fails the run at that communication point

    [components.gearbox]
    fmu = "Gearbox.fmu"                   # relative to the scenario file or the FMU directory
    # no_feedthrough = ["y"]              # outputs not depending directly on inputs (FMU does not say)
    [components.gearbox.parameters]
    "stage1.k0" = 1.58e10                 # dotted names quoted, or as nested tables; also start values
                                          # of variables with initial="exact"/"approx" (states)

    [[connections]]
    from = "wind.omega"                   # an output
    to = "gearbox.omega_rotor"            # an input

    [[initial]]                           # set a parameter from an output at initialisation
    from = "gearbox.omega_out"
    to = "generator.omega_start"

    [[bindings]]                          # a parameter takes another FMU's parameter value (one source)
    from = "generator.inertia"
    to = "gearbox.generator_inertia"

    [record]
    variables = ["wind.omega", "gearbox.stage*.F_sp[1]"]  # names or * / ? patterns
    format = "auto"                       # results file: "csv", "parquet" or "auto" (Parquet for long runs)

    [[events]]                            # generator load events (orchestrator.inputs.load_events)
    kind = "grid_fault"                   # torque_step | grid_fault | emergency_stop
    start = 10.0                          # s
    duration = 0.5                        # s

    [analysis]                            # result analyses (orchestrator.inputs.analysis_settings)
    woehler_exponents = [3, 5, 8, 10]

    [plausibility]                        # values kept although implausible by physics (a deliberate study)
    allow = ["gearbox.stage1.backlash"]

    [jacobi]                              # the coupling when stepped with Jacobi (libcosim, ecos, --algorithm jacobi)
    step = 2e-2                           # s, optional: the step under Jacobi
    step_criteria = "..."                 # optional: what the step was chosen by
    [jacobi.parameters.gearbox]           # values that replace the scenario's
    generator_interface = 2
    [[jacobi.connections]]                # connections added to the scenario's
    from = "gearbox.omega_generator"
    to = "generator.omega_gearbox"
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal, Mapping

from pydantic import Field

from fmus import registry
from fmus.slaves.record import GENERATOR

from ..errors import ScenarioError
from .analysis_settings import AnalysisSettings, AnalysisTable
from .drivetrain_file import DrivetrainSpec, find_drivetrain, load_drivetrain_file
from .files import find_input_file, packaged_files, read_toml
from .load_events import EventTable
from .master_options import ALGEBRAIC_LOOPS, ALGORITHMS, EXTRAPOLATIONS
from .results_format import RESULTS_FORMATS
from .scenario import (
    Component,
    Connection,
    InitialBinding,
    JacobiCoupling,
    ParameterBinding,
    Scenario,
    SimulationSettings,
    VariableRef,
)
from .schema import PlausibilityTable, Table, flatten_parameters, read_document
from .series_spec import SeriesTable, series_from_table


class _SimulationTable(Table):
    start: float = Field(0.0, description="a finite number [s]")
    stop: float = Field(description="a finite number [s]")
    step: float = Field(description="a finite number [s] (the communication step H)")
    output_interval: float | None = Field(None, description="a finite number [s]")
    window: list[float] | None = Field(None, min_length=2, max_length=2, description="[begin, end] in seconds")
    algorithm: Literal[ALGORITHMS] = "gauss-seidel"
    extrapolation: Literal[EXTRAPOLATIONS] = "hold"
    order: list[str] | None = Field(None, description="a list of component names")
    algebraic_loops: Literal[ALGEBRAIC_LOOPS] = "refuse"
    loop_tolerance: float = Field(1e-10, description="a number > 0 and < 1")
    loop_max_iterations: int = Field(100, description="a whole number >= 1")


class _ComponentTable(Table):
    fmu: str = Field(description="an FMU file name (string)")
    parameters: dict[str, Any] = Field(default_factory=dict, description="a table of parameter values")
    role: str | None = Field(None, description="a role name (string)")
    signals: dict[str, Any] = Field(default_factory=dict, description="a table of signal kind = output name(s)")
    drivetrain: str | None = Field(None, description="a drivetrain file (path relative to this file, or a packaged "
                                   "name such as grc-like)")
    no_feedthrough: list[str] = Field(default_factory=list,
                                      description="a list of outputs that do not depend directly on any input")
    series: SeriesTable | None = Field(None, description="a [components.<name>.series] table (recorded channels)")


class _LinkTable(Table):
    source: str = Field(alias="from", description='a string "component.variable"')
    to: str = Field(description='a string "component.variable"')


class _RecordTable(Table):
    variables: list[str] = Field(default_factory=list, description='a list of "component.variable" strings')
    format: Literal[RESULTS_FORMATS] = "auto"


class _JacobiTable(Table):
    step: float | None = Field(None, description="a finite number [s] (the communication step under Jacobi)")
    step_criteria: str = Field("", description="a string: what the step was chosen by")
    parameters: dict[str, dict[str, Any]] = Field(default_factory=dict,
                                                  description="a table of components' parameter values")
    connections: list[_LinkTable] = Field(default_factory=list,
                                         description="an array of tables [[jacobi.connections]] with from/to")


class ScenarioFile(Table):
    """The shape of a scenario TOML document (see the module docstring and ``docs/orchestrator.md``)."""

    name: str | None = Field(None, description="a scenario name (string)")
    description: str = Field("", description="a string")
    simulation: _SimulationTable = Field(description="a [simulation] table")
    components: dict[str, _ComponentTable] = Field(description="a [components.<name>] table per FMU")
    connections: list[_LinkTable] = Field(default_factory=list,
                                         description="an array of tables [[connections]] with from/to")
    initial: list[_LinkTable] = Field(default_factory=list, description="an array of tables [[initial]] with from/to")
    bindings: list[_LinkTable] = Field(default_factory=list,
                                       description="an array of tables [[bindings]] with from/to (parameters)")
    record: _RecordTable | None = Field(None, description="a [record] table with variables = [...]")
    events: list[EventTable] = Field(default_factory=list,
                                     description="an array of tables [[events]] with kind, start, duration (, factor)")
    analysis: AnalysisTable | None = Field(None, description="an [analysis] table")
    plausibility: PlausibilityTable | None = Field(None, description="a [plausibility] table with allow = [...]")
    jacobi: _JacobiTable | None = Field(None, description="a [jacobi] table (the coupling under Jacobi)")


_SIM_FIELDS = {"start": "start_s", "stop": "stop_s", "step": "step_s", "output_interval": "output_interval_s",
               "window": "window_s", "algorithm": "algorithm", "extrapolation": "extrapolation", "order": "order",
               "algebraic_loops": "algebraic_loops", "loop_tolerance": "loop_tolerance",
               "loop_max_iterations": "loop_max_iterations"}


def _rekeyed(exc: ScenarioError, key: str | None, source: str | None) -> ScenarioError:
    return ScenarioError(key or exc.key, exc.value, exc.expected, source)


def scenario_from_dict(data: Mapping[str, Any], name: str | None = None, base_dir: Path | None = None,
                       source: str | None = None) -> Scenario:
    """Build a :class:`Scenario` from parsed TOML (or an equivalent dict).

    Parameters
    ----------
    data : mapping
        The document (see the module docstring for the keys).
    name : str, optional
        Name used when the document has none.
    base_dir : pathlib.Path, optional
        Directory relative FMU paths are resolved against.
    source : str, optional
        File name for error messages.

    Raises
    ------
    ScenarioError
        Naming the first offending key.
    """
    doc = read_document(ScenarioFile, data, ScenarioError, source)
    sc_name = doc.name if doc.name is not None else name
    if sc_name is None:
        raise ScenarioError("name", None, "a scenario name (missing)", source)
    sim = doc.simulation
    given = {k for k in sim.model_fields_set}
    kwargs = {attr: getattr(sim, key) for key, attr in _SIM_FIELDS.items() if key in given}
    if "window_s" in kwargs:
        kwargs["window_s"] = tuple(kwargs["window_s"])
    if "order" in kwargs:
        kwargs["order"] = tuple(kwargs["order"])
    try:
        settings = SimulationSettings(**kwargs)
    except ScenarioError as exc:
        raise _rekeyed(exc, None, source) from None

    components = []
    specs = {cname: _drivetrain_of(ctab.drivetrain, f"components.{cname}.drivetrain", base_dir, source)
             for cname, ctab in doc.components.items() if ctab.drivetrain is not None}
    inherited = next(iter(specs.values())) if len({s.sha256 for s in specs.values()}) == 1 else None
    for cname, ctab in doc.components.items():
        path = f"components.{cname}"
        params = flatten_parameters(ctab.parameters, f"{path}.parameters", ScenarioError, source)
        spec = specs.get(cname)
        if spec is None and inherited is not None and _is_drivetrain_generator(ctab.fmu):
            spec = inherited  # the generator of a drivetrain file's gearbox takes its defaults from the same file
        series = (series_from_table(ctab.series, f"{path}.series", base_dir, source)
                  if ctab.series is not None else None)
        try:
            components.append(Component(cname, Path(ctab.fmu), params, ctab.role, ctab.signals, spec,
                                        tuple(ctab.no_feedthrough), series))
        except ScenarioError as exc:
            raise _rekeyed(exc, path if exc.key == "components" else None, source) from None

    def links(tables: list[_LinkTable], key: str, cls):
        return tuple(cls(VariableRef.parse(link.source, f"{key}[{i}].from", source),
                         VariableRef.parse(link.to, f"{key}[{i}].to", source)) for i, link in enumerate(tables))

    events = []
    for i, table in enumerate(doc.events):
        try:
            events.append(table.event())
        except ScenarioError as exc:
            raise _rekeyed(exc, exc.key.replace("event.", f"events[{i}].", 1), source) from None
    try:
        analysis = doc.analysis.settings() if doc.analysis is not None else AnalysisSettings()
    except ScenarioError as exc:
        raise _rekeyed(exc, None, source) from None

    jacobi = None
    if doc.jacobi is not None:
        jacobi = JacobiCoupling(
            doc.jacobi.step, doc.jacobi.step_criteria,
            {comp: flatten_parameters(values, f"jacobi.parameters.{comp}", ScenarioError, source)
             for comp, values in doc.jacobi.parameters.items()},
            links(doc.jacobi.connections, "jacobi.connections", Connection))
    scenario = Scenario(
        name=sc_name,
        description=doc.description,
        components=tuple(components),
        connections=links(doc.connections, "connections", Connection),
        initial=links(doc.initial, "initial", InitialBinding),
        bindings=links(doc.bindings, "bindings", ParameterBinding),
        simulation=settings,
        recorded=tuple(doc.record.variables) if doc.record is not None else (),
        events=tuple(events),
        analysis=analysis,
        results_format=doc.record.format if doc.record is not None else "auto",
        base_dir=base_dir,
        source=source,
        allow_implausible=tuple(doc.plausibility.allow) if doc.plausibility is not None else (),
        jacobi=jacobi,
    )
    if jacobi is not None:  # checked as applied; a scenario stepped with Jacobi is coupled so from the start
        try:
            coupled = scenario.for_algorithm("jacobi")
        except ScenarioError as exc:
            raise ScenarioError(f"jacobi ({exc.key})", exc.value, exc.expected, source) from None
        if settings.algorithm == "jacobi":
            return coupled
    return scenario


def _is_drivetrain_generator(fmu: str) -> bool:
    """Whether ``fmu`` names the project's generator FMU that a drivetrain file builds."""
    kind = registry.of_file(fmu)
    return kind is not None and kind.role == GENERATOR and registry.DRIVETRAIN_FILE in kind.built_from


def _drivetrain_of(spec: str, key: str, base_dir: Path | None, source: str | None) -> DrivetrainSpec:
    """The drivetrain file a component names: a path relative to the scenario file, or a packaged name."""
    if not spec:
        raise ScenarioError(key, spec, "a drivetrain file path or a packaged drivetrain name", source)
    local = (base_dir / spec) if base_dir is not None else Path(spec)
    path = local if local.is_file() else find_drivetrain(spec)
    drivetrain = load_drivetrain_file(path)
    drivetrain.cosim_drivetrain()  # a generator behind an output shaft, or an error naming the file
    return drivetrain


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file.

    Relative FMU paths are resolved against the file's directory first (see
    :meth:`Scenario.fmu_candidates`).

    Raises
    ------
    ScenarioError
        On a missing/unreadable file, a TOML syntax error, or any invalid entry.
    """
    path = Path(path)
    data = read_toml(path, ScenarioError)
    return scenario_from_dict(data, name=path.stem, base_dir=path.resolve().parent, source=str(path))


def packaged_scenarios() -> dict[str, Path]:
    """Scenario files shipped with dtcosim, by name (e.g. ``"paper-60s"``)."""
    return packaged_files("scenarios")


def find_scenario(spec: str | Path | None) -> Path:
    """A scenario file from a path or the name of a packaged scenario (default ``paper-60s``)."""
    return find_input_file("paper-60s" if spec is None else spec, "scenarios", ScenarioError,
                           suffixes=(".toml", ".ssp", ".ssd"), directories=True)
