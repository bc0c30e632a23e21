"""Parameter studies: the study file (TOML), its validation and its points.

A study runs one base system many times with some parameters changed: the
design variants, load cases and wind seeds of a wind-turbine drivetrain study,
or the paper's sensitivity analysis (Sec. 4.1). It is a frozen, validated value;
every structural mistake raises :class:`StudyError` naming the key, before
anything runs. The checks that need the base system (parameter names and types,
recorded variables) are made by :func:`orchestrator.study.prepare.prepare_study`, also
before anything runs. See ``docs/studies.md`` for the format in full::

    name = "seeds-and-stiffness"          # optional, default: file stem
    description = "..."
    engine = "cosim"                      # "cosim" (FMUs + master) or "monolithic"

    [base]
    scenario = "paper-60s"                # packaged scenario name or TOML path (relative to this file)
    # model = "sensitivity-variant"       # or a built-in monolithic model (orchestrator.study.models)
    [base.parameters]                     # fixed overrides, "component.parameter" = value
    "gearbox.shaft3.damping" = 100.0

    [simulation]                          # overrides of the base's time grid [s]
    stop = 5.0
    step = 2.0e-3

    [[axes]]                              # grid: Cartesian product of all axes
    parameter = "gearbox.shaft3.stiffness"
    values = [2.0e3, 5.7e3]               # or start/stop/num (+ spacing = "log")

    seeds = [1, 2, 3]                     # one more axis over seed_parameter (default "wind.seed")
    measures = ["I_max_acc", "cpu_time", "gearbox.stage1.F_sp[1]:std"]

Points: every explicit ``points`` entry (default: one empty point) x every
combination of axis values x every seed, in that nesting order (seeds fastest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Mapping

import numpy as np
from pydantic import Field

from components.validation import is_number

from ..errors import EntryError
from ..frozen_map import FrozenMap
from .files import find_input_file, packaged_files, read_toml
from .limits import MAX_AXIS_VALUES, MAX_STUDY_POINTS
from .master_options import ALGORITHMS, EXTRAPOLATIONS
from .measures import Measure, MeasureError, parse_measure
from .overrides import SimulationOverrides
from .schema import (
    NAME_PATTERN,
    ParameterValue,
    Table,
    flatten_parameters,
    is_parameter_value,
    read_document,
)

ENGINES = ("cosim", "monolithic")
SPACINGS = ("linear", "log")
DEFAULT_SEED_PARAMETER = "wind.seed"



class StudyError(EntryError):
    """A study file (or the objects built from it) is invalid (key, value, expected, source)."""

    kind = "study"


def split_parameter(name: str) -> tuple[str, str]:
    """``"gearbox.stage1.lambda"`` -> ``("gearbox", "stage1.lambda")`` (component = text before the first dot)."""
    comp, _, param = name.partition(".")
    return comp, param


def _check_parameter_name(name: Any, key: str, source: str | None) -> str:
    if not isinstance(name, str):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    comp, param = split_parameter(name)
    if not comp or not param or not NAME_PATTERN.match(comp):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    return name


def _parameter_table(table: Mapping[str, Any], key: str, source: str | None) -> dict[str, ParameterValue]:
    out = flatten_parameters(table, key, StudyError, source)
    for name in out:
        _check_parameter_name(name, f"{key}.{name}", source)
    return out


@dataclass(frozen=True)
class Axis:
    """One axis of the study grid.

    Parameters
    ----------
    parameters : tuple of str
        ``"component.parameter"`` names set together to each value (linked
        parameters, e.g. the regularisation factor of all three stages).
    values : tuple of float, int, bool or str
        The values (SI units, as the parameter), at least one.
    label : str
        Name on plots (default: the first parameter).
    unit : str
        Unit shown on plots (default ``""``: the parameter's own SI unit is not known here).
    scale : float
        Plots show ``value * scale`` in ``unit`` (e.g. 1e-3 for 1/m -> 1/mm).
    """

    parameters: tuple[str, ...]
    values: tuple[ParameterValue, ...]
    label: str = ""
    unit: str = ""
    scale: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", tuple(self.parameters))
        object.__setattr__(self, "values", tuple(self.values))
        if not self.parameters:
            raise StudyError("axes.parameters", list(self.parameters), "at least one parameter")
        if not self.values:
            raise StudyError("axes.values", list(self.values), "at least one value")
        if not self.label:
            object.__setattr__(self, "label", self.parameters[0])

    def display(self, value: ParameterValue) -> ParameterValue:
        """A value as shown on plots and in the table (``value * scale`` for numbers, to 12 digits).

        Rounded so that 2864.8 x 1e-3 reads 2.8648, not 2.8648000000000002.
        """
        return float(f"{value * self.scale:.12g}") if is_number(value) else value

    @property
    def axis_label(self) -> str:
        """``label [unit]`` for plot axes."""
        return f"{self.label} [{self.unit}]" if self.unit else self.label


@dataclass(frozen=True)
class PlotSpec:
    """A plot of one measure over the grid (heat map for two axes, line plot for one).

    Parameters
    ----------
    measure : str
        Name of a measure of the study.
    title : str
        Plot title (default: the measure's description).
    file : str
        PNG file name in the output directory (default ``heatmap_<measure>.png`` or ``plot_<measure>.png``).
    x, y : int
        Axis indices shown along x and y (default 0 and 1).
    log : bool
        Logarithmic colour (or y) scale.
    vmin, vmax : float, optional
        Fixed ends of the colour (or y) scale in the measure's unit (default: the data's range),
        e.g. ``vmin = 0`` to show a nearly constant measure as such.
    """

    measure: str
    title: str = ""
    file: str = ""
    x: int = 0
    y: int = 1
    log: bool = False
    vmin: float | None = None
    vmax: float | None = None


@dataclass(frozen=True)
class Base:
    """What every point starts from.

    Parameters
    ----------
    kind : {"scenario", "model"}
        A co-simulation scenario file, or a built-in monolithic model.
    name : str
        Scenario name/path as written in the study, or the model name.
    path : pathlib.Path, optional
        Scenario file (``kind == "scenario"``).
    parameters : mapping of str -> value
        Fixed overrides applied to every point, ``"component.parameter"``.
    """

    kind: str
    name: str
    path: Path | None = None
    parameters: Mapping[str, ParameterValue] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", FrozenMap(dict(self.parameters)))


@dataclass(frozen=True)
class Point:
    """One run of a study.

    Attributes
    ----------
    index : int
        Position in the study's point list (0-based).
    parameters : mapping of str -> value
        The values this point sets (explicit point, axes, seed); the base's fixed
        overrides come on top of nothing and under these.
    coords : tuple of int
        Index of the explicit point (0 without ``points``), of each axis value,
        and of the seed (0 without ``seeds``).
    """

    index: int
    parameters: Mapping[str, ParameterValue]
    coords: tuple[int, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", FrozenMap(dict(self.parameters)))


@dataclass(frozen=True)
class Study:
    """A complete, structurally valid study.

    Parameters
    ----------
    name : str
        Names the results directory.
    engine : {"cosim", "monolithic"}
        ``cosim``: the FMUs stepped by the orchestrator's master; ``monolithic``:
        :func:`components.reference.solver.simulate_monolithic` on the base's monolithic model.
    base : Base
    measures : tuple of Measure
        Computed for every point.
    axes : tuple of Axis
        Grid axes (Cartesian product).
    points : tuple of mapping
        Explicit points (each combined with every grid combination).
    seeds : tuple of int
        Values of ``seed_parameter`` (one more, innermost axis).
    seed_parameter : str
    simulation : SimulationOverrides
        Changes of the base's time grid and master options (``[simulation]``:
        ``start``, ``stop``, ``step``, ``output_interval``, ``window``, ``algorithm``,
        ``extrapolation``), applied by the rules of :mod:`orchestrator.inputs.overrides`.
    solver : mapping
        Monolithic solver tolerances (:class:`components.reference.solver.SolverSettings` fields).
    plots : tuple of PlotSpec
    timeout_s : float or None
        Wall-clock time [s] one point may take; past it the point fails with a
        message naming the limit and the simulation time reached. Not part of the
        point keys (it does not change a result). None: no limit.
    description : str
    base_dir : pathlib.Path, optional
        Directory of the study file.
    source : str, optional
        The study file (error messages).
    """

    name: str
    engine: str
    base: Base
    measures: tuple[Measure, ...]
    axes: tuple[Axis, ...] = ()
    points: tuple[Mapping[str, ParameterValue], ...] = ()
    seeds: tuple[int, ...] = ()
    seed_parameter: str = DEFAULT_SEED_PARAMETER
    simulation: SimulationOverrides = field(default_factory=SimulationOverrides)
    solver: Mapping[str, Any] = field(default_factory=dict)
    plots: tuple[PlotSpec, ...] = ()
    timeout_s: float | None = None
    description: str = ""
    base_dir: Path | None = None
    source: str | None = None

    def __post_init__(self) -> None:
        src = self.source
        for attr in ("measures", "axes", "points", "seeds", "plots"):
            object.__setattr__(self, attr, tuple(getattr(self, attr)))
        object.__setattr__(self, "points", tuple(FrozenMap(dict(p)) for p in self.points))
        if isinstance(self.simulation, Mapping):
            object.__setattr__(self, "simulation", SimulationOverrides.from_table(self.simulation))
        object.__setattr__(self, "solver", FrozenMap(dict(self.solver)))
        if not isinstance(self.name, str) or not NAME_PATTERN.match(self.name):
            raise StudyError("name", self.name, "a name of letters, digits, '_' or '-'", src)
        t = self.timeout_s
        if t is not None and not (is_number(t) and math.isfinite(t) and t > 0):
            raise StudyError("timeout", t, "a finite number of seconds > 0 (wall-clock time per point)", src)
        if self.engine not in ENGINES:
            raise StudyError("engine", self.engine, "one of " + ", ".join(ENGINES), src)
        if not self.measures:
            raise StudyError("measures", [], "at least one measure", src)
        names = [m.name for m in self.measures]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise StudyError("measures", dup[0], "each measure once", src)
        owner: dict[str, str] = {name: "base.parameters" for name in self.base.parameters}

        def claim(name: str, key: str) -> None:
            if name in owner and owner[name] != key:
                raise StudyError(key, name, f"a parameter set in one place only (also set by {owner[name]})", src)
            owner[name] = key

        for i, axis in enumerate(self.axes):
            if len(set(axis.parameters)) != len(axis.parameters):
                raise StudyError(f"axes[{i}].parameters", list(axis.parameters), "distinct parameters", src)
            for p in axis.parameters:
                claim(p, f"axes[{i}]")
            if len(set(map(repr, axis.values))) != len(axis.values):
                raise StudyError(f"axes[{i}].values", list(axis.values), "distinct values", src)
        for i, pt in enumerate(self.points):
            for p in pt:
                claim(p, "points")
        n_points = math.prod(self.shape)
        if n_points > MAX_STUDY_POINTS:
            raise StudyError("axes", " x ".join(str(n) for n in self.shape), f"a study of at most {MAX_STUDY_POINTS:,} "
                             f"points (explicit points x axes x seeds); this one has {n_points:,}", src)
        if self.seeds:
            _check_parameter_name(self.seed_parameter, "seed_parameter", src)
            claim(self.seed_parameter, "seeds")
            if len(set(self.seeds)) != len(self.seeds):
                raise StudyError("seeds", list(self.seeds), "distinct seeds", src)
        for i, plot in enumerate(self.plots):
            if plot.measure not in names:
                raise StudyError(f"plots[{i}].measure", plot.measure, "one of the study's measures: " + ", ".join(names), src)
            if not self.axes:
                raise StudyError(f"plots[{i}]", plot.measure, "a study with at least one axis to plot over", src)
            for attr in ("x", "y") if len(self.axes) >= 2 else ("x",):
                idx = getattr(plot, attr)
                if not (isinstance(idx, int) and not isinstance(idx, bool) and 0 <= idx < len(self.axes)):
                    raise StudyError(f"plots[{i}].{attr}", idx, f"an axis index 0..{len(self.axes) - 1}", src)
            if len(self.axes) >= 2 and plot.x == plot.y:
                raise StudyError(f"plots[{i}].y", plot.y, "an axis other than x", src)

    # ------------------------------------------------------------------ points
    @property
    def shape(self) -> tuple[int, ...]:
        """Sizes of (explicit points, axis 0, axis 1, ..., seeds)."""
        return (max(1, len(self.points)), *(len(a.values) for a in self.axes), max(1, len(self.seeds)))

    @property
    def n_points(self) -> int:
        """Number of runs."""
        return math.prod(self.shape)

    def expand(self) -> list[Point]:
        """Every point, explicit points outermost, seeds innermost."""
        out = []
        for index, coords in enumerate(np.ndindex(*self.shape)):
            params: dict[str, ParameterValue] = {}
            if self.points:
                params.update(self.points[coords[0]])
            for axis, k in zip(self.axes, coords[1:-1]):
                for p in axis.parameters:
                    params[p] = axis.values[k]
            if self.seeds:
                params[self.seed_parameter] = self.seeds[coords[-1]]
            out.append(Point(index, params, tuple(int(c) for c in coords)))
        return out

    @property
    def varied_parameters(self) -> list[str]:
        """Every parameter some point sets, in order of first appearance."""
        seen: dict[str, None] = {}
        for pt in self.points:
            seen.update(dict.fromkeys(pt))
        for axis in self.axes:
            seen.update(dict.fromkeys(axis.parameters))
        if self.seeds:
            seen[self.seed_parameter] = None
        return list(seen)

    def measure(self, name: str) -> Measure:
        """The measure called ``name``."""
        for m in self.measures:
            if m.name == name:
                return m
        raise KeyError(name)


# ---------------------------------------------------------------------- TOML
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
    unit: str = Field("", description="a string")
    scale: float = Field(1.0, description="a finite number other than 0")


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


def _axis(tab: _AxisTable, i: int, source: str | None) -> Axis:
    key = f"axes[{i}]"
    if (tab.parameter is None) == (tab.parameters is None):
        raise StudyError(key, tab.model_dump(exclude_none=True),
                         'either parameter = "component.parameter" or parameters = [...]', source)
    if tab.parameter is not None:
        params = [_check_parameter_name(tab.parameter, f"{key}.parameter", source)]
    else:
        params = [_check_parameter_name(p, f"{key}.parameters[{j}]", source) for j, p in enumerate(tab.parameters)]
    values = _axis_values(tab, key, source)
    if tab.scale == 0:
        raise StudyError(f"{key}.scale", tab.scale, "a finite number other than 0", source)
    try:
        return Axis(tuple(params), values, label=tab.label, unit=tab.unit, scale=float(tab.scale))
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

    axes = tuple(_axis(tab, i, source) for i, tab in enumerate(doc.axes))
    points = []
    for i, pt in enumerate(doc.points):
        table = _parameter_table(pt, f"points[{i}]", source)
        if not table:
            raise StudyError(f"points[{i}]", pt, "at least one parameter value", source)
        points.append(table)

    seed_parameter = doc.seed_parameter or DEFAULT_SEED_PARAMETER
    _check_parameter_name(seed_parameter, "seed_parameter", source)
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
    )


def _scenario_path(spec: str, base_dir: Path | None, source: str | None) -> Path:
    """The base scenario file: relative to the study file, else a path or a packaged scenario name."""
    from ..errors import ScenarioError
    from .scenario import find_scenario

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
