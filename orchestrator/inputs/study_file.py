"""The study file (TOML): its schema and how it becomes a :class:`~orchestrator.inputs.study.Study`.

The format is described in :mod:`orchestrator.inputs.study` and, in full, in
``docs/studies.md``. :func:`load_study` reads a file, :func:`study_from_dict` a parsed
document; every structural mistake raises :class:`~orchestrator.inputs.study.StudyError`
naming the key, before anything runs.
"""

from __future__ import annotations

import math

from pathlib import Path
from typing import Annotated, Any, Literal, Mapping

import numpy as np
from pydantic import Field

from .files import find_input_file, packaged_files, read_toml
from .limits import MAX_AXIS_VALUES, MAX_STUDY_POINTS
from .master_options import ALGORITHMS, EXTRAPOLATIONS
from .measures import MeasureError, parse_measure
from .overrides import SimulationOverrides
from .schema import ParameterValue, PlausibilityTable, Table, flatten_parameters, is_parameter_value, read_document
from .study import (
    DEFAULT_SEED_PARAMETER,
    ENGINES,
    SPACINGS,
    Axis,
    Base,
    PlotSpec,
    Study,
    StudyError,
    check_parameter_name,
)


def _parameter_table(table: Mapping[str, Any], key: str, source: str | None) -> dict[str, ParameterValue]:
    out = flatten_parameters(table, key, StudyError, source)
    for name in out:
        check_parameter_name(name, f"{key}.{name}", source)
    return out


_FINITE_S = "a finite number [s]"


class _BaseTable(Table):
    scenario: str | None = Field(None, description="a packaged scenario name or a scenario TOML path")
    model: str | None = Field(None, description="the name of a built-in model (orchestrator.study.models)")
    parameters: dict[str, Any] = Field(default_factory=dict, description='a table of "component.parameter" = value')


class _SimulationTable(Table):
    start: float | None = Field(None, description=_FINITE_S)
    stop: float | None = Field(None, description=_FINITE_S)
    step: float | None = Field(None, description=_FINITE_S)
    output_interval: float | None = Field(None, description=_FINITE_S)
    window: list[float] | None = Field(None, min_length=2, max_length=2, description="[begin, end] in seconds")
    algorithm: Literal[ALGORITHMS] | None = None
    extrapolation: Literal[EXTRAPOLATIONS] | None = None


_POSITIVE = "a finite number > 0"


class _SolverTable(Table):
    rtol: float | None = Field(None, gt=0, description=_POSITIVE)
    atol_angle: float | None = Field(None, gt=0, description=_POSITIVE + " [rad]")
    atol_speed: float | None = Field(None, gt=0, description=_POSITIVE + " [rad/s]")
    max_step: float | None = Field(None, ge=0, description="a finite number >= 0 [s] (0: no limit)")
    max_steps: int | None = Field(None, gt=0, description="an integer > 0")


_SOLVER_FIELDS = {"rtol": "rtol", "atol_angle": "atol_angle_rad", "atol_speed": "atol_speed_rad_s",
                  "max_step": "max_step_s", "max_steps": "max_steps"}


class _AxisTable(Table):
    parameter: str | None = Field(None, description='a parameter name "component.parameter"')
    parameters: list[str] | None = Field(None, min_length=1,
                                         description='a non-empty list of "component.parameter" names')
    values: list[Any] | None = Field(None, min_length=1,
                                     description="a non-empty list of finite numbers, booleans or strings")
    start: float | None = Field(None, description="a finite number")
    stop: float | None = Field(None, description="a finite number")
    num: int | None = Field(None, ge=1, le=MAX_AXIS_VALUES, description=f"an integer within [1, {MAX_AXIS_VALUES}]")
    spacing: Literal[SPACINGS] | None = None
    label: str = Field("", description="a string")
    unit: str = Field("", description="the unit of the values, e.g. \"kN m/rad\" (converted to the parameter's)")
    scale: float | None = Field(None, description="nothing: write the values in unit")


class _PlotTable(Table):
    measure: str = Field(description="a measure name (string)")
    title: str = Field("", description="a string")
    file: str = Field("", description="a PNG file name without directories (*.png)")
    x: int = Field(0, description="an axis index (integer)")
    y: int = Field(1, description="an axis index (integer)")
    log: bool = Field(False, description="true or false")
    vmin: float | None = Field(None, description="a finite number in the measure's unit")
    vmax: float | None = Field(None, description="a finite number in the measure's unit")


class StudyFile(Table):
    """The shape of a study TOML document (see the module docstring and ``docs/studies.md``)."""

    name: str | None = Field(None, description="a study name (string)")
    description: str = Field("", description="a string")
    engine: Literal[ENGINES] = Field(description="one of " + ", ".join(ENGINES))
    base: _BaseTable = Field(description='a [base] table with scenario = "..." or model = "..."')
    simulation: _SimulationTable = Field(default_factory=_SimulationTable, description="a [simulation] table")
    solver: _SolverTable | None = Field(None, description="a [solver] table")
    axes: list[_AxisTable] = Field(default_factory=list, description="an array of tables [[axes]]")
    points: list[dict[str, Any]] = Field(default_factory=list,
                                         description='a list of tables {"component.parameter" = value, ...}')
    seeds: list[Annotated[int, Field(ge=0)]] = Field(default_factory=list, description="a list of integers >= 0")
    seed_parameter: str | None = Field(None, description='a parameter name "component.parameter"')
    measures: list[str] = Field(min_length=1, description='a non-empty list such as ["I_max_acc", "cpu_time"]')
    plots: list[_PlotTable] = Field(default_factory=list, description="an array of tables [[plots]]")
    timeout: float | None = Field(None, description="a finite number of seconds > 0 (wall-clock time per point)")
    plausibility: PlausibilityTable | None = Field(None, description="a [plausibility] table with allow = [...]")


def _axis_values(tab: _AxisTable, key: str, source: str | None) -> tuple[ParameterValue, ...]:
    has_values = tab.values is not None
    has_range = any(v is not None for v in (tab.start, tab.stop, tab.num))
    if has_values == has_range:
        raise StudyError(key, tab.model_dump(exclude_none=True), "either values = [...] or start, stop and num", source)
    if has_values:
        for j, v in enumerate(tab.values):
            if not is_parameter_value(v):
                raise StudyError(f"{key}.values[{j}]", v, "a finite number, a boolean or a string", source)
        if tab.spacing is not None:
            raise StudyError(f"{key}.spacing", tab.spacing, "no spacing with explicit values", source)
        return tuple(tab.values)
    for k in ("start", "stop", "num"):
        if getattr(tab, k) is None:
            raise StudyError(f"{key}.{k}", None, ("an integer >= 1" if k == "num" else "a number") + " (missing)", source)
    spacing = tab.spacing or "linear"
    if tab.num > 1 and tab.start == tab.stop:
        raise StudyError(f"{key}.stop", tab.stop, f"a value other than start = {tab.start:g} for num > 1", source)
    if spacing == "log":
        if not (tab.start > 0 and tab.stop > 0):
            raise StudyError(f"{key}.start", tab.start, "start > 0 and stop > 0 for log spacing", source)
        grid = np.geomspace(tab.start, tab.stop, tab.num)
    else:
        grid = np.linspace(tab.start, tab.stop, tab.num)
    return tuple(float(v) for v in grid)


def _check_grid_size(doc: "StudyFile", source: str | None) -> None:
    """Refuse a study of more than :data:`MAX_STUDY_POINTS` points from the axes' declared lengths.

    Before any axis's values exist: each axis may hold up to :data:`MAX_AXIS_VALUES` values, so
    many axes would allocate far beyond the point limit before the study could count its points.
    """
    lengths = [max(1, len(doc.points))]
    lengths += [len(t.values) if t.values is not None else (t.num or 1) for t in doc.axes]
    lengths.append(max(1, len(doc.seeds)))
    n = 1
    for length in lengths:
        n *= length
        if n > MAX_STUDY_POINTS:
            if len(lengths) <= 8:
                shown, count = " x ".join(map(str, lengths)), f"{math.prod(lengths):,}"
            else:
                shown, count = f"{len(doc.axes)} axes", f"more than {MAX_STUDY_POINTS:,}"
            raise StudyError("axes", shown, f"a study of at most {MAX_STUDY_POINTS:,} points (explicit points x "
                             f"axes x seeds); this one has {count}", source)


def _axis(tab: _AxisTable, i: int, source: str | None) -> Axis:
    key = f"axes[{i}]"
    if (tab.parameter is None) == (tab.parameters is None):
        raise StudyError(key, tab.model_dump(exclude_none=True),
                         'either parameter = "component.parameter" or parameters = [...]', source)
    if tab.parameter is not None:
        params = [check_parameter_name(tab.parameter, f"{key}.parameter", source)]
    else:
        params = [check_parameter_name(p, f"{key}.parameters[{j}]", source) for j, p in enumerate(tab.parameters)]
    values = _axis_values(tab, key, source)
    if tab.scale is not None:
        raise StudyError(f"{key}.scale", tab.scale, f"no scale: an axis's unit is the unit of its values, converted to "
                         f"the parameter's before anything runs (write the values in unit = \"{tab.unit or '...'}\"; plots "
                         "show them as written)", source)
    try:
        return Axis(tuple(params), values, label=tab.label, unit=tab.unit)
    except StudyError as exc:
        raise StudyError(exc.key.replace("axes", key, 1), exc.value, exc.expected, source) from None


def _plot(tab: _PlotTable, i: int, source: str | None) -> PlotSpec:
    key = f"plots[{i}]"
    if tab.file and (Path(tab.file).name != tab.file or not tab.file.endswith(".png")):
        raise StudyError(f"{key}.file", tab.file, "a PNG file name without directories (*.png)", source)
    if tab.vmin is not None and tab.vmax is not None and not tab.vmax > tab.vmin:
        raise StudyError(f"{key}.vmax", tab.vmax, f"> vmin = {tab.vmin}", source)
    return PlotSpec(measure=tab.measure, title=tab.title, file=tab.file, x=tab.x, y=tab.y, log=tab.log,
                    vmin=tab.vmin, vmax=tab.vmax)


def study_from_dict(data: Mapping[str, Any], name: str | None = None, base_dir: Path | None = None,
                    source: str | None = None) -> Study:
    """Build a :class:`Study` from parsed TOML (or an equivalent dict).

    Parameters
    ----------
    data : mapping
        The document (see ``docs/studies.md``).
    name : str, optional
        Name used when the document has none (the file stem).
    base_dir : pathlib.Path, optional
        Directory a relative base scenario path is resolved against first.
    source : str, optional
        File name for error messages.

    Raises
    ------
    StudyError
        Naming the first offending key.
    """
    doc = read_document(StudyFile, data, StudyError, source)
    st_name = doc.name if doc.name is not None else name
    engine = doc.engine
    if (doc.base.scenario is None) == (doc.base.model is None):
        raise StudyError("base", doc.base.model_dump(exclude_none=True),
                         'exactly one of scenario = "..." or model = "..."', source)
    params = _parameter_table(doc.base.parameters, "base.parameters", source)
    if doc.base.scenario is not None:
        if not doc.base.scenario:
            raise StudyError("base.scenario", "", "a packaged scenario name or a scenario TOML path", source)
        base = Base("scenario", doc.base.scenario, _scenario_path(doc.base.scenario, base_dir, source), params)
    else:
        model = doc.base.model
        if not model:
            raise StudyError("base.model", model, "the name of a built-in model (orchestrator.study.models)", source)
        if engine != "monolithic":
            raise StudyError("engine", engine, f"monolithic for the built-in model {model!r} (the co-simulation "
                             "engine runs a scenario's FMUs: give base.scenario)", source)
        base = Base("model", model, None, params)

    simulation = doc.simulation.model_dump(exclude_none=True)
    if base.kind == "model":
        for key in ("step", "algorithm", "extrapolation"):
            if key in simulation:
                raise StudyError(f"simulation.{key}", simulation[key], "no master option with a built-in monolithic model", source)
        if "stop" not in simulation:
            raise StudyError("simulation.stop", None, "the end time [s] of a built-in model's runs (missing)", source)

    solver = doc.solver.model_dump(exclude_none=True) if doc.solver is not None else {}
    if doc.solver is not None and engine != "monolithic":
        raise StudyError("solver", solver, "no [solver] table with the co-simulation engine (the Gearbox FMU has "
                         "its own solver parameters: set them as gearbox parameters)", source)
    solver = {_SOLVER_FIELDS[k]: v for k, v in solver.items()}

    _check_grid_size(doc, source)
    axes = tuple(_axis(tab, i, source) for i, tab in enumerate(doc.axes))
    points = []
    for i, pt in enumerate(doc.points):
        table = _parameter_table(pt, f"points[{i}]", source)
        if not table:
            raise StudyError(f"points[{i}]", pt, "at least one parameter value", source)
        points.append(table)

    seed_parameter = doc.seed_parameter or DEFAULT_SEED_PARAMETER
    check_parameter_name(seed_parameter, "seed_parameter", source)
    if doc.seed_parameter is not None and not doc.seeds:
        raise StudyError("seed_parameter", seed_parameter, "seeds = [...] as well", source)

    measures = []
    for i, text in enumerate(doc.measures):
        try:
            measures.append(parse_measure(text))
        except MeasureError as exc:
            raise StudyError(f"measures[{i}]", text, exc.expected, source) from None

    return Study(
        name=st_name, engine=engine, base=base, measures=tuple(measures), axes=axes, points=tuple(points),
        seeds=tuple(doc.seeds), seed_parameter=seed_parameter, simulation=SimulationOverrides.from_table(simulation),
        solver=solver, plots=tuple(_plot(tab, i, source) for i, tab in enumerate(doc.plots)),
        timeout_s=doc.timeout, description=doc.description, base_dir=base_dir, source=source,
        allow_implausible=tuple(doc.plausibility.allow) if doc.plausibility is not None else (),
    )


def _scenario_path(spec: str, base_dir: Path | None, source: str | None) -> Path:
    """The base scenario file: relative to the study file, else a path or a packaged scenario name."""
    from ..errors import ScenarioError
    from .scenario_file import find_scenario

    p = Path(spec)
    if base_dir is not None and not p.is_absolute() and (base_dir / p).is_file():
        return (base_dir / p).resolve()
    try:
        return find_scenario(spec).resolve()
    except ScenarioError as exc:
        raise StudyError("base.scenario", spec, exc.expected, source) from None


def load_study(path: str | Path) -> Study:
    """Read and validate a study TOML file.

    Raises
    ------
    StudyError
        On a missing/unreadable file, a TOML syntax error, or any invalid entry.
    """
    path = Path(path)
    data = read_toml(path, StudyError)
    return study_from_dict(data, name=path.stem, base_dir=path.resolve().parent, source=str(path))


def packaged_studies() -> dict[str, Path]:
    """Study files shipped with dtcosim, by name (e.g. ``"paper-sensitivity"``)."""
    return packaged_files("studies")


def find_study(spec: str | Path) -> Path:
    """A study file from a path or the name of a packaged study."""
    return find_input_file(spec, "studies", StudyError, described="a study TOML file", plural="studies")
