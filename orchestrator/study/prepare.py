"""A study checked against its base, ready to run: the workers' payload and the point keys.

:func:`prepare_study` checks a :class:`~orchestrator.inputs.study.Study` against its
base (a scenario and its FMUs, or a built-in model) and builds everything the
workers need (:class:`~orchestrator.study.engine.StudyPayload`); every mistake is
a :class:`~orchestrator.inputs.study.StudyError` naming the study key, raised before
anything runs. Checked: every varied or fixed parameter exists (with
suggestions), is settable and has its FMI type; a built-in model accepts the
base's values; the time grid; the variables of statistic measures exist (and,
for the monolithic engine, have a counterpart in the monolithic model); the
engine computes each measure.

Point identity
--------------
A point's key is the SHA-256 of its parameter values, the engine, the base
(scenario file content and FMU hashes, or the model name), the study's fixed
parameters, simulation and solver overrides, the measures and the code version
(:func:`code_version`: the dtcosim version and what the code a point runs
computes, wherever that code lives).
:mod:`orchestrator.study.sweep` skips points whose key the journal already holds.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

from ..errors import ScenarioError, suggestion
from ..inputs.measures import Measure
from ..inputs.study import Point, Study, StudyError, split_parameter
from .engine import STAGE_COLUMNS, StudyPayload

#: the module that computes a point (:func:`orchestrator.study.engine.run_point`): its import closure is the code
#: a point's numbers depend on
POINT_ENGINE = "orchestrator.study.engine"


# ------------------------------------------------------------------ identity
def code_version(packages: Mapping[str, Path] | None = None) -> str:
    """SHA-256 (16 hex digits) of the dtcosim version and of the code a point runs.

    The code is the static import closure of :data:`POINT_ENGINE` within the
    project's packages (:func:`fmus.source_closure.import_closure`: everything
    the engine may import, lazily or not, the physics included); each module
    counts by what it computes (:func:`fmus.source_closure.behaviour_digest`:
    docstrings, comments and import lines left out), not by its file name, so
    moving a module changes no point key, and plots, reports and the CLI, which
    a point never imports, change none either. The FMUs a point runs are in its
    key by their own SHA-256.

    Parameters
    ----------
    packages : mapping of str -> pathlib.Path, optional
        Top-level package -> folder (default: the installed ``components``,
        ``orchestrator`` and ``fmus``).
    """
    from importlib import metadata

    from fmus.source_closure import behaviour_digest, import_closure

    if packages is None:
        import components
        import fmus
        import orchestrator

        packages = {m.__name__: Path(m.__file__).parent for m in (components, orchestrator, fmus)}
    h = hashlib.sha256()
    try:
        h.update(metadata.version("dtcosim").encode())
    except metadata.PackageNotFoundError:
        h.update(b"unknown")
    h.update(behaviour_digest(import_closure([POINT_ENGINE], packages)).encode())
    return h.hexdigest()[:16]


def _canonical(value: Any) -> Any:
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    return value


def point_key(identity: Mapping[str, Any], point: Point) -> str:
    """The point's key: SHA-256 (20 hex digits) of the sweep identity and its parameter values."""
    doc = {"sweep": _canonical(identity), "parameters": _canonical(dict(point.parameters))}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:20]


# --------------------------------------------------------------- preparation
@dataclass(frozen=True)
class PreparedStudy:
    """A study checked against its base, ready to run.

    Attributes
    ----------
    study : Study
    points : tuple of Point
    keys : tuple of str
        Key of each point (same order).
    payload : StudyPayload
        What the workers share.
    identity : mapping
        Everything the keys depend on besides the point's own parameters.
    fmu_paths : mapping of str -> pathlib.Path
        The base scenario's FMU files (empty for a built-in model).
    notes : tuple of str
        What the study's ``[simulation]`` changed beyond what it gives (e.g. a clipped
        analysis window; :mod:`orchestrator.inputs.overrides`).
    """

    study: Study
    points: tuple[Point, ...]
    keys: tuple[str, ...]
    payload: StudyPayload
    identity: Mapping[str, Any]
    fmu_paths: Mapping[str, Path] = field(default_factory=dict)
    notes: tuple[str, ...] = ()


def _varied(study: Study) -> list[tuple[str, str, list]]:
    """(study key naming the parameter, parameter, values) of every varied parameter, for error messages."""
    out = []
    for i, axis in enumerate(study.axes):
        for j, p in enumerate(axis.parameters):
            key = f"axes[{i}].parameter" if len(axis.parameters) == 1 else f"axes[{i}].parameters[{j}]"
            out.append((key, p, list(axis.values)))
    for i, pt in enumerate(study.points):
        given = study.point_origins[i] if study.point_origins else {}
        for p, v in pt.items():  # a load-case set's point: its own entry
            out.append((given[p].key if p in given else f"points[{i}].{p}", p, [v]))
    if study.seeds:
        out.append(("seeds", study.seed_parameter, list(study.seeds)))
    return out


def _check_name(system, name: str, key: str, source: str | None) -> None:
    """A varied scenario parameter exists, is settable, not connected, set at initialisation or bound."""
    from ..cosim.system import parameter_problem

    comp, param = split_parameter(name)
    if comp not in system.interfaces:
        raise StudyError(key, name, "a parameter of a component of the base scenario: " + ", ".join(system.interfaces), source)
    problem = parameter_problem(system.interfaces[comp], param)
    if problem is not None:
        raise StudyError(key, name, problem, source)
    if any(str(c.target) == name for c in system.scenario.connections):
        raise StudyError(key, name, "a parameter, not an input a connection drives", source)
    if any(str(b.target) == name for b in system.scenario.initial):
        raise StudyError(key, name, "a parameter the scenario does not set at initialisation (an [[initial]] binding)", source)
    bound = system.scenario.bound_source(name)
    if bound is not None:
        raise StudyError(key, name, f"a parameter the scenario does not bind: {name} takes its value from {bound} "
                         f"([[bindings]]); vary {bound} instead", source)


def _check_values(study: Study, system, skip) -> None:
    """Every value a point sets has its parameter's type and range, each refused where it was given.

    The range is what the FMU declares (an FMI Integer's 32 bits, a dtcosim FMU's
    bounds, ``min``/``max``: :func:`orchestrator.cosim.parameter_checks.value_problem`),
    with the FMU's own message; combinations of values are the model's to refuse
    (that point fails).
    """
    from ..cosim.parameter_checks import type_problem, value_problem

    seen: set = set()
    for point in study.expand():
        for name, value in point.parameters.items():
            if skip(name) or (name, repr(value)) in seen:
                continue
            seen.add((name, repr(value)))
            comp, param = split_parameter(name)
            iface = system.interfaces[comp]
            var = iface.variables[param]
            problem = type_problem(var, value, name)
            if problem is None:
                bound = value_problem(iface, var, value)
                problem = None if bound is None else f"{bound} for {name}"
            if problem is not None:
                raise study.origins(point)[name].refusal(name, value, problem)


def _solver_settings(study: Study):
    from components.errors import ParameterError
    from components.reference.solver import SolverSettings

    try:
        return SolverSettings(**study.solver)
    except ParameterError as exc:
        raise StudyError(f"solver ({exc.name})", exc.value, exc.expected, study.source) from None


def _micro_run_units(drivetrain, driver, start: float) -> dict[str, str]:
    """The series the monolithic solver records for this model and the unit it declares for each (a 2-sample run)."""
    from components.reference.solver import simulate_monolithic

    return simulate_monolithic(drivetrain, driver, start + 1e-7, output_interval_s=1e-7, t_start_s=start).units


def _with_units(measures: tuple[Measure, ...], units: Mapping[str, str]) -> tuple[Measure, ...]:
    """The measures with the units their base declares (``units``: measure name -> unit)."""
    return tuple(replace(m, unit=units[m.name]) if m.name in units else m for m in measures)


def _check_measure_engines(study: Study) -> None:
    for i, m in enumerate(study.measures):
        if study.engine not in m.engines:
            raise StudyError(f"measures[{i}]", m.name, f"a measure the {study.engine} engine computes "
                             f"({m.name} needs the {' or '.join(m.engines)} engine)", study.source)


def _prepare_model(study: Study) -> tuple[Study, StudyPayload, dict[str, Any]]:
    from components.errors import ParameterError

    from .declared_values import check_points, in_declared_units, model_converter, model_problem
    from .models import MODEL_COMPONENT, MODELS

    src = study.source
    if study.base.name not in MODELS:
        raise StudyError("base.model", study.base.name, "one of the built-in models: " + ", ".join(MODELS), src)
    model = MODELS[study.base.name]
    defaults = model.defaults()
    study = in_declared_units(study, model_converter(model.units(), model.exponent), base_too=True)
    checks = [(f"base.parameters.{p}", p, [v]) for p, v in study.base.parameters.items()] + _varied(study)
    for key, name, values in checks:
        if name not in defaults:
            raise StudyError(key, name, f"a parameter of the built-in model {model.name}{suggestion(name, defaults)}", src)
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise StudyError(key, v, f"a number for {name}", src)
    try:
        drivetrain, driver = model.build(dict(study.base.parameters))
    except ParameterError as exc:
        raise StudyError(f"base.parameters ({exc.name})", exc.value, exc.expected, src) from None
    check_points(study, study.expand(),
                 model_problem(study, model.plausibility(dict(study.base.parameters), study.allow_implausible)))
    sim = study.simulation
    start = 0.0 if sim.start_s is None else float(sim.start_s)
    stop = float(sim.stop_s)
    interval = 1e-3 if sim.output_interval_s is None else float(sim.output_interval_s)
    if not stop > start:
        raise StudyError("simulation.stop", sim.stop_s, f"> simulation.start = {start:g} s", src)
    if not 0 < interval <= stop - start:
        raise StudyError("simulation.output_interval", interval, f"> 0 and <= stop - start = {stop - start:g} s", src)
    window = (start, stop) if sim.window_s is None else sim.window_s
    if not start <= window[0] < window[1] <= stop:
        raise StudyError("simulation.window", list(window), f"start <= begin < end <= stop, within [{start:g}, {stop:g}] s", src)
    settings = _solver_settings(study)
    _check_measure_engines(study)
    series_names = {}
    declared_units: dict[str, str] = {}
    stats = [m for m in study.measures if not m.builtin]
    if stats:
        units = _micro_run_units(drivetrain, driver, start)
        for i, m in enumerate(study.measures):
            if m.builtin:
                continue
            comp, var = split_parameter(m.variable)
            if m.of_stage:  # the model's series of the stage's sun-planet forces, planet by planet
                planets = [n for n in units if n.startswith(f"{var}.F_sp[")]
                if comp != MODEL_COMPONENT or len(planets) < 2:
                    raise StudyError(f"measures[{i}]", m.name, f"a planetary stage {MODEL_COMPONENT}.<stage> of the "
                                     "model", src)
                series_names[m.name] = STAGE_COLUMNS.join(sorted(planets, key=lambda n: int(n[n.index("[") + 1:-1])))
                continue
            if comp != MODEL_COMPONENT or var not in units:
                raise StudyError(f"measures[{i}]", m.name, f"a variable {MODEL_COMPONENT}.<series> of the monolithic "
                                 f"result{suggestion(var, units)}", src)
            series_names[m.variable] = var
            declared_units[m.name] = units[var] or "-"  # as the solver declares its series
    study = replace(study, measures=_with_units(study.measures, declared_units))
    payload = StudyPayload(
        study=study.name, engine="monolithic", measures=study.measures, model=model.name,
        model_parameters=dict(study.base.parameters), time_grid=(start, stop, interval), window_s=window,
        solver={k: getattr(settings, k) for k in ("rtol", "atol_angle_rad", "atol_speed_rad_s", "max_step_s", "max_steps")},
        series_names=series_names,
    )
    return study, payload, {"model": model.name}


def _prepare_scenario(study: Study, fmu_dir, build: bool, report: Callable[[str], None] | None = None
                      ) -> tuple[Study, StudyPayload, dict[str, Any], dict[str, Path], tuple[str, ...]]:
    from ..cosim.roles import GEARBOX
    from ..cosim.system import resolve_system
    from ..inputs.overrides import apply_parameters
    from ..provision.project_fmus import ensure_fmus
    from ..run.runner import load_any

    src = study.source
    try:
        scenario = load_any(study.base.path)
    except ScenarioError as exc:
        raise StudyError("base.scenario", study.base.name, f"a valid scenario ({exc})", src) from None
    try:
        scenario, notes = study.simulation.apply(scenario)
    except ScenarioError as exc:
        key = exc.key if exc.key.startswith("simulation.") else "simulation"
        raise StudyError(key, exc.value, exc.expected, src) from None
    try:
        paths = ensure_fmus(scenario, fmu_dir, build=build, report=report)
    except ScenarioError as exc:
        raise StudyError("base.scenario", study.base.name, f"FMUs that exist or can be built ({exc})", src) from None
    from .declared_values import check_points, in_declared_units, scenario_converter, scenario_problem
    from .drivetrain_variants import is_file_entry

    fixed = {name: value for name, value in study.base.parameters.items() if not is_file_entry(name)}
    # drivetrain file entries: see drivetrain_variants; a base value refused is a StudyError naming base.parameters
    scenario = apply_parameters(scenario, fixed, study.base_origins()).with_allowed(*study.allow_implausible)
    try:
        system = resolve_system(scenario, fmu_paths=paths)
    except ScenarioError as exc:  # the scenario's own entries (its file in the message)
        raise StudyError("base.scenario", study.base.name, f"a valid scenario ({exc})", src) from None
    study = in_declared_units(study, scenario_converter(system, is_file_entry))
    for key, name, values in _varied(study):
        if not is_file_entry(name):
            _check_name(system, name, key, src)
    _check_values(study, system, is_file_entry)
    seed = study.seed_parameter if study.seeds else None  # a seed changes no value physics bounds
    # drivetrain file entries are judged when each point's file is read again (drivetrain_variants)
    check_points(study, study.expand(), scenario_problem(system),
                 skip=lambda name: name == seed or is_file_entry(name))
    _check_measure_engines(study)

    series_names: dict[str, str] = {}
    declared_units: dict[str, str] = {}
    gearbox = system.with_role(GEARBOX)
    if study.engine == "cosim":
        extra = []
        for i, m in enumerate(study.measures):
            if m.builtin and m.name != "I_max_acc":
                continue
            if m.of_stage:
                columns = _stage_forces(system, m, i, src)
                series_names[m.name] = STAGE_COLUMNS.join(columns)
                declared_units[m.name] = "1"
                extra += [c for c in columns if scenario.recorded and c not in {r.column for r in system.recorded}]
                continue
            if m.name == "I_max_acc":
                signals = {s.kind: s.variable for s in gearbox[0].signals} if len(gearbox) == 1 else {}
                # the FMU's running peak over its internal steps (eq. 11 exactly) where it has one;
                # FMUs built before it existed: finite differences of the output speed (a lower bound)
                output = signals.get("output_acceleration_peak") or signals.get("output_speed")
                if output is None:
                    raise StudyError(f"measures[{i}]", m.name, "a base scenario with exactly one gearbox that "
                                     f"declares its output speed; found {len(gearbox)} gearbox(es)", src)
                variable = f"{gearbox[0].component}.{output}"
                series_names["I_max_acc"] = variable
            else:
                variable = m.variable
                comp, var = split_parameter(variable)
                iface = system.interfaces.get(comp)
                fv = iface.variables.get(var) if iface is not None else None
                if fv is None or fv.type != "Real":
                    choices = [f"{c}.{n}" for c, f in system.interfaces.items() for n, v in f.variables.items() if v.type == "Real"]
                    raise StudyError(f"measures[{i}]", m.name, f"a Real variable of the base scenario's FMUs{suggestion(variable, choices)}", src)
                declared_units[m.name] = fv.unit or "-"  # the unit its FMU declares, never one read from the name
            if scenario.recorded and variable not in {r.column for r in system.recorded}:
                extra.append(variable)
        if extra:
            scenario = replace(scenario, recorded=scenario.recorded + tuple(dict.fromkeys(extra)))
            system = resolve_system(scenario, fmu_paths=paths)
        variants = _variants(study, scenario, fmu_dir, build)
        blobs = {}
        for each in [system] + list(variants.systems.values() if variants else ()):
            for comp, path in each.fmu_paths.items():
                blobs[each.interfaces[comp].sha256] = Path(path).read_bytes()
        payload = StudyPayload(study=study.name, engine="cosim", measures=_with_units(study.measures, declared_units),
                               system=system,
                               window_s=scenario.simulation.window_s, series_names=series_names, fmu_blobs=blobs)
        settings = None
    else:
        from components.model.wind import RotorSpeedProcess

        from ..cosim.physics_view import PhysicsUnavailable, physics_view
        from ..run.comparison import reference_name

        variants = _variants(study, scenario, fmu_dir, build)
        try:
            setup = physics_view(system)
        except PhysicsUnavailable as exc:
            raise StudyError("engine", "monolithic", f"a base scenario the monolithic model represents ({exc})", src) from None
        settings = _solver_settings(study)
        stats = [m for m in study.measures if not m.builtin]
        if stats:
            units = _micro_run_units(setup.drivetrain, RotorSpeedProcess(setup.wind), scenario.simulation.start_s)
            for i, m in enumerate(study.measures):
                if m.builtin:
                    continue
                if m.of_stage:
                    names = [reference_name(c, system, setup, units) for c in _stage_forces(system, m, i, src)]
                    if any(n is None for n in names):
                        raise StudyError(f"measures[{i}]", m.name, "a stage whose planet forces the monolithic model "
                                         "has", src)
                    series_names[m.name] = STAGE_COLUMNS.join(names)
                    continue
                name = reference_name(m.variable, system, setup, units)
                if name is None:
                    raise StudyError(f"measures[{i}]", m.name, "a variable of the scenario with a counterpart in the "
                                     "monolithic model (e.g. gearbox.stage1.F_sp[1], generator.omega, wind.omega)", src)
                series_names[m.variable] = name
                comp, var = split_parameter(m.variable)
                fv = system.interfaces[comp].variables.get(var) if comp in system.interfaces else None
                # as the scenario's FMU declares it, else as the solver declares its counterpart
                declared_units[m.name] = (fv.unit if fv is not None else units[name]) or "-"
        payload = StudyPayload(
            study=study.name, engine="monolithic", measures=_with_units(study.measures, declared_units), system=system,
            window_s=scenario.simulation.window_s, series_names=series_names,
            solver={k: getattr(settings, k) for k in ("rtol", "atol_angle_rad", "atol_speed_rad_s", "max_step_s", "max_steps")},
        )
    identity = {
        "scenario_sha256": _content_sha256(Path(study.base.path)),
        "fmus": {c: i.sha256 for c, i in system.interfaces.items()},
    }
    if variants is not None:  # the FMUs of every drivetrain structure the points run on
        identity["structures"] = {sid: {c: i.sha256 for c, i in s.interfaces.items()}
                                  for sid, s in variants.systems.items()}
        payload = replace(payload, structures=dict(variants.systems), variants=dict(variants.points))
    return study, payload, identity, dict(system.fmu_paths), tuple(notes)


def _stage_forces(system, m, i: int, src) -> list[str]:
    """The sun-planet force columns (planet order) a gearbox declares for the stage of a stage measure."""
    from ..cosim.roles import GEARBOX

    comp, _, stage = m.variable.partition(".")
    role = next((r for r in system.with_role(GEARBOX) if r.component == comp), None)
    planets = {}
    for s in role.of_kind("contact_force") if role is not None else ():
        if s.info.get("stage") == stage and s.info.get("mesh") == "sun_planet" and str(s.info.get("planet")).isdigit():
            planets[int(s.info["planet"])] = f"{comp}.{s.variable}"
    if len(planets) < 2:
        stages = sorted({f"{r.component}.{s.info.get('stage')}" for r in system.with_role(GEARBOX)
                         for s in r.of_kind("contact_force") if s.info.get("mesh") == "sun_planet"})
        raise StudyError(f"measures[{i}]", m.name, "a planetary stage of a gearbox of the base scenario whose "
                         f"planets' sun-planet forces are declared: {', '.join(stages) or 'none'}", src)
    return [planets[k] for k in sorted(planets)]


def _variants(study: Study, scenario, fmu_dir, build: bool):
    """The drivetrain structures of a study varying drivetrain file entries, the measures checked on each."""
    from ..provision.folders import default_fmu_dir
    from .drivetrain_variants import drivetrain_variants

    fmu_dir = default_fmu_dir() if fmu_dir is None else Path(fmu_dir)
    try:
        variants = drivetrain_variants(study, scenario, study.expand(), fmu_dir, build)
    except ScenarioError as exc:
        raise StudyError("base.scenario", study.base.name, f"FMUs that exist or can be built ({exc})", study.source) from None
    for sid, each in (variants.systems.items() if variants else ()):
        for i, m in enumerate(study.measures):
            if m.builtin:
                continue
            if m.of_stage:
                _stage_forces(each, m, i, study.source)
                continue
            comp, var = split_parameter(m.variable)
            if comp not in each.interfaces or var not in each.interfaces[comp].variables:
                raise StudyError(f"measures[{i}]", m.name, f"a variable every drivetrain structure of the study has "
                                 f"(not the structure {sid})", study.source)
    return variants


def _content_sha256(path: Path) -> str:
    """SHA-256 of a file's content, or of every file under a directory (an SSP directory) with its name."""
    if path.is_file():
        return hashlib.sha256(path.read_bytes()).hexdigest()
    h = hashlib.sha256()
    for f in sorted(p for p in path.rglob("*") if p.is_file()):
        h.update(str(f.relative_to(path)).encode() + b"\0" + f.read_bytes())
    return h.hexdigest()


def prepare_study(study: Study, fmu_dir: str | Path | None = None, build: bool = True,
                  report: Callable[[str], None] | None = None) -> PreparedStudy:
    """Check a study against its base and build the workers' payload (nothing runs).

    Parameters
    ----------
    study : Study
    fmu_dir : path, optional
        Where the base scenario's FMUs are looked for (and missing project FMUs
        built); default :func:`orchestrator.provision.folders.default_fmu_dir`.
    build : bool
        Build missing project FMUs.
    report : callable(str), optional
        Receives what preparing the FMUs does (their builds, the kernels' compile), in one line each.

    Raises
    ------
    StudyError
        Naming the study key of the first problem.
    """
    if study.base.kind == "model":
        study, payload, base_identity = _prepare_model(study)
        fmu_paths: dict[str, Path] = {}
        notes: tuple[str, ...] = ()
    else:
        study, payload, base_identity, fmu_paths, notes = _prepare_scenario(study, fmu_dir, build, report)
    identity = {
        "engine": study.engine,
        "base": {"kind": study.base.kind, **base_identity},
        "base_parameters": dict(study.base.parameters),
        "simulation": study.simulation.as_table(),
        "solver": dict(study.solver),
        "measures": [m.name for m in study.measures],
        "code": code_version(),
    }
    payload = replace(payload, timeout_s=study.timeout_s)  # not in the identity: it changes no result
    study = replace(study, measures=payload.measures)  # units as the base scenario's FMUs declare them
    points = tuple(study.expand())
    keys = tuple(point_key(identity, p) for p in points)
    return PreparedStudy(study, points, keys, payload, identity, fmu_paths, notes)
