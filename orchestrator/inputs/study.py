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
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from components.validation import is_number

from ..errors import EntryError, suggestion
from ..frozen_map import FrozenMap
from .files import find_input_file, packaged_files, read_toml
from .measures import Measure, MeasureError, parse_measure

ENGINES = ("cosim", "monolithic")
SPACINGS = ("linear", "log")
DEFAULT_SEED_PARAMETER = "wind.seed"

#: parameter values a study may give (as a scenario: FMI Real, Integer, Boolean, String)
ParameterValue = float | int | bool | str

_NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
_TOP_KEYS = {"name", "description", "engine", "base", "simulation", "solver", "axes", "points", "seeds",
             "seed_parameter", "measures", "plots", "timeout"}
_BASE_KEYS = {"scenario", "model", "parameters"}
_SIMULATION_KEYS = {"start", "stop", "step", "output_interval", "window", "algorithm", "extrapolation"}
_SOLVER_KEYS = {"rtol": "rtol", "atol_angle": "atol_angle_rad", "atol_speed": "atol_speed_rad_s",
                "max_step": "max_step_s", "max_steps": "max_steps"}
_AXIS_KEYS = {"parameter", "parameters", "values", "start", "stop", "num", "spacing", "label", "unit", "scale"}
_PLOT_KEYS = {"measure", "title", "file", "x", "y", "log", "vmin", "vmax"}


class StudyError(EntryError):
    """A study file (or the objects built from it) is invalid (key, value, expected, source)."""

    kind = "study"


def _is_scalar(value: Any) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        return False
    return isinstance(value, (int, float, bool, str))


def split_parameter(name: str) -> tuple[str, str]:
    """``"gearbox.stage1.lambda"`` -> ``("gearbox", "stage1.lambda")`` (component = text before the first dot)."""
    comp, _, param = name.partition(".")
    return comp, param


def _check_parameter_name(name: Any, key: str, source: str | None) -> str:
    if not isinstance(name, str):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    comp, param = split_parameter(name)
    if not comp or not param or not _NAME_RE.match(comp):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    return name


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested TOML tables -> dotted names (``gearbox = {R1 = 8}`` -> ``gearbox.R1``)."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            out.update(_flatten(value, name))
        else:
            out[name] = value
    return out


def _parameter_table(table: Any, key: str, source: str | None) -> dict[str, ParameterValue]:
    if not isinstance(table, dict):
        raise StudyError(key, table, 'a table of "component.parameter" = value', source)
    out = {}
    for name, value in _flatten(table).items():
        _check_parameter_name(name, f"{key}.{name}", source)
        if not _is_scalar(value):
            raise StudyError(f"{key}.{name}", value, "a finite number, boolean or string", source)
        out[name] = value
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
    simulation : mapping
        Overrides of the base's time grid (``start``, ``stop``, ``step``,
        ``output_interval``, ``window``, ``algorithm``, ``extrapolation``).
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
    simulation: Mapping[str, Any] = field(default_factory=dict)
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
        object.__setattr__(self, "simulation", FrozenMap(dict(self.simulation)))
        object.__setattr__(self, "solver", FrozenMap(dict(self.solver)))
        if not isinstance(self.name, str) or not _NAME_RE.match(self.name):
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
        return int(np.prod(self.shape))

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
def _check_keys(table: Mapping[str, Any], allowed: set[str] | Mapping[str, Any], prefix: str, source: str | None) -> None:
    for key in table:
        if key not in allowed:
            where = f"{prefix}.{key}" if prefix else key
            hint = suggestion(key, allowed, n=1)
            if prefix and key in _TOP_KEYS:
                hint += f" ({key} is a top-level key: in TOML it must come before the first [table] header)"
            raise StudyError(where, table[key], "a known key here: " + ", ".join(sorted(allowed)) + hint, source)


def _axis_values(tab: Mapping[str, Any], key: str, source: str | None) -> tuple[ParameterValue, ...]:
    has_values = "values" in tab
    has_range = any(k in tab for k in ("start", "stop", "num"))
    if has_values == has_range:
        raise StudyError(key, dict(tab), "either values = [...] or start, stop and num", source)
    if has_values:
        values = tab["values"]
        if not isinstance(values, list) or not values or not all(_is_scalar(v) for v in values):
            raise StudyError(f"{key}.values", values, "a non-empty list of finite numbers, booleans or strings", source)
        if "spacing" in tab:
            raise StudyError(f"{key}.spacing", tab["spacing"], "no spacing with explicit values", source)
        return tuple(values)
    for k in ("start", "stop"):
        if k not in tab:
            raise StudyError(f"{key}.{k}", None, "a number (missing)", source)
        if not is_number(tab[k]) or not math.isfinite(tab[k]):
            raise StudyError(f"{key}.{k}", tab[k], "a finite number", source)
    num = tab.get("num")
    if not isinstance(num, int) or isinstance(num, bool) or num < 1:
        raise StudyError(f"{key}.num", num, "an integer >= 1", source)
    spacing = tab.get("spacing", "linear")
    if spacing not in SPACINGS:
        raise StudyError(f"{key}.spacing", spacing, "one of " + ", ".join(SPACINGS), source)
    start, stop = float(tab["start"]), float(tab["stop"])
    if num > 1 and start == stop:
        raise StudyError(f"{key}.stop", tab["stop"], f"a value other than start = {start:g} for num > 1", source)
    if spacing == "log":
        if not (start > 0 and stop > 0):
            raise StudyError(f"{key}.start", tab["start"], "start > 0 and stop > 0 for log spacing", source)
        grid = np.geomspace(start, stop, num)
    else:
        grid = np.linspace(start, stop, num)
    return tuple(float(v) for v in grid)


def _axis(tab: Any, i: int, source: str | None) -> Axis:
    key = f"axes[{i}]"
    if not isinstance(tab, dict):
        raise StudyError(key, tab, "a table [[axes]] with parameter(s) and values", source)
    _check_keys(tab, _AXIS_KEYS, key, source)
    if ("parameter" in tab) == ("parameters" in tab):
        raise StudyError(key, dict(tab), 'either parameter = "component.parameter" or parameters = [...]', source)
    if "parameter" in tab:
        params = [_check_parameter_name(tab["parameter"], f"{key}.parameter", source)]
    else:
        plist = tab["parameters"]
        if not isinstance(plist, list) or not plist:
            raise StudyError(f"{key}.parameters", plist, 'a non-empty list of "component.parameter" names', source)
        params = [_check_parameter_name(p, f"{key}.parameters[{j}]", source) for j, p in enumerate(plist)]
    values = _axis_values(tab, key, source)
    label = tab.get("label", "")
    unit = tab.get("unit", "")
    scale = tab.get("scale", 1.0)
    for k, v in (("label", label), ("unit", unit)):
        if not isinstance(v, str):
            raise StudyError(f"{key}.{k}", v, "a string", source)
    if not is_number(scale) or not math.isfinite(scale) or scale == 0:
        raise StudyError(f"{key}.scale", scale, "a finite number other than 0", source)
    try:
        return Axis(tuple(params), values, label=label, unit=unit, scale=float(scale))
    except StudyError as exc:
        raise StudyError(exc.key.replace("axes", key, 1), exc.value, exc.expected, source) from None


def _plot(tab: Any, i: int, source: str | None) -> PlotSpec:
    key = f"plots[{i}]"
    if not isinstance(tab, dict):
        raise StudyError(key, tab, "a table [[plots]] with measure = ...", source)
    _check_keys(tab, _PLOT_KEYS, key, source)
    if "measure" not in tab or not isinstance(tab["measure"], str):
        raise StudyError(f"{key}.measure", tab.get("measure"), "a measure name (string)", source)
    for k in ("title", "file"):
        if k in tab and not isinstance(tab[k], str):
            raise StudyError(f"{key}.{k}", tab[k], "a string", source)
    file = tab.get("file", "")
    if file and (Path(file).name != file or not file.endswith(".png")):
        raise StudyError(f"{key}.file", file, "a PNG file name without directories (*.png)", source)
    if "log" in tab and not isinstance(tab["log"], bool):
        raise StudyError(f"{key}.log", tab["log"], "true or false", source)
    for k in ("x", "y"):
        if k in tab and (not isinstance(tab[k], int) or isinstance(tab[k], bool)):
            raise StudyError(f"{key}.{k}", tab[k], "an axis index (integer)", source)
    for k in ("vmin", "vmax"):
        if k in tab and (not is_number(tab[k]) or not math.isfinite(tab[k])):
            raise StudyError(f"{key}.{k}", tab[k], "a finite number in the measure's unit", source)
    if "vmin" in tab and "vmax" in tab and not tab["vmax"] > tab["vmin"]:
        raise StudyError(f"{key}.vmax", tab["vmax"], f"> vmin = {tab['vmin']}", source)
    return PlotSpec(measure=tab["measure"], title=tab.get("title", ""), file=file, x=tab.get("x", 0),
                    y=tab.get("y", 1), log=tab.get("log", False), vmin=tab.get("vmin"), vmax=tab.get("vmax"))


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
    if not isinstance(data, Mapping):
        raise StudyError("(document)", data, "a table", source)
    _check_keys(data, _TOP_KEYS, "", source)
    st_name = data.get("name", name)
    if not isinstance(st_name, str):
        raise StudyError("name", st_name, "a study name (string)", source)
    description = data.get("description", "")
    if not isinstance(description, str):
        raise StudyError("description", description, "a string", source)
    if "engine" not in data:
        raise StudyError("engine", None, "one of " + ", ".join(ENGINES) + " (missing)", source)
    engine = data["engine"]
    if engine not in ENGINES:
        raise StudyError("engine", engine, "one of " + ", ".join(ENGINES), source)

    base_tab = data.get("base")
    if not isinstance(base_tab, dict):
        raise StudyError("base", base_tab, 'a [base] table with scenario = "..." or model = "..."', source)
    _check_keys(base_tab, _BASE_KEYS, "base", source)
    if ("scenario" in base_tab) == ("model" in base_tab):
        raise StudyError("base", dict(base_tab), 'exactly one of scenario = "..." or model = "..."', source)
    params = _parameter_table(base_tab.get("parameters", {}), "base.parameters", source)
    if "scenario" in base_tab:
        spec = base_tab["scenario"]
        if not isinstance(spec, str) or not spec:
            raise StudyError("base.scenario", spec, "a packaged scenario name or a scenario TOML path", source)
        base = Base("scenario", spec, _scenario_path(spec, base_dir, source), params)
    else:
        model = base_tab["model"]
        if not isinstance(model, str) or not model:
            raise StudyError("base.model", model, "the name of a built-in model (orchestrator.study.models)", source)
        if engine != "monolithic":
            raise StudyError("engine", engine, f"monolithic for the built-in model {model!r} (the co-simulation "
                             "engine runs a scenario's FMUs: give base.scenario)", source)
        base = Base("model", model, None, params)

    simulation = data.get("simulation", {})
    if not isinstance(simulation, dict):
        raise StudyError("simulation", simulation, "a [simulation] table", source)
    _check_keys(simulation, _SIMULATION_KEYS, "simulation", source)
    for key, value in simulation.items():
        path = f"simulation.{key}"
        if key in ("start", "stop", "step", "output_interval"):
            if not is_number(value) or not math.isfinite(value):
                raise StudyError(path, value, "a finite number [s]", source)
        elif key == "window":
            if not isinstance(value, list) or len(value) != 2 or not all(is_number(v) for v in value):
                raise StudyError(path, value, "[begin, end] in seconds", source)
        elif not isinstance(value, str):
            raise StudyError(path, value, "a string", source)
    if base.kind == "model":
        for key in ("step", "algorithm", "extrapolation"):
            if key in simulation:
                raise StudyError(f"simulation.{key}", simulation[key], "no master option with a built-in monolithic model", source)
        if "stop" not in simulation:
            raise StudyError("simulation.stop", None, "the end time [s] of a built-in model's runs (missing)", source)

    solver = data.get("solver", {})
    if not isinstance(solver, dict):
        raise StudyError("solver", solver, "a [solver] table", source)
    _check_keys(solver, _SOLVER_KEYS, "solver", source)
    if solver and engine != "monolithic":
        raise StudyError("solver", dict(solver), "no [solver] table with the co-simulation engine (the Gearbox FMU has "
                         "its own solver parameters: set them as gearbox parameters)", source)
    for key, value in solver.items():
        if not is_number(value) or not math.isfinite(value) or value < 0 or (key != "max_step" and value == 0):
            raise StudyError(f"solver.{key}", value, "a finite number > 0 (max_step >= 0)", source)
        if key == "max_steps" and not isinstance(value, int):
            raise StudyError(f"solver.{key}", value, "an integer", source)
    solver = {_SOLVER_KEYS[k]: v for k, v in solver.items()}

    axes_tab = data.get("axes", [])
    if not isinstance(axes_tab, list):
        raise StudyError("axes", axes_tab, "an array of tables [[axes]]", source)
    axes = tuple(_axis(tab, i, source) for i, tab in enumerate(axes_tab))

    points_tab = data.get("points", [])
    if not isinstance(points_tab, list):
        raise StudyError("points", points_tab, 'a list of tables {"component.parameter" = value, ...}', source)
    points = []
    for i, pt in enumerate(points_tab):
        table = _parameter_table(pt, f"points[{i}]", source)
        if not table:
            raise StudyError(f"points[{i}]", pt, "at least one parameter value", source)
        points.append(table)

    seeds = data.get("seeds", [])
    if not isinstance(seeds, list) or not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds):
        raise StudyError("seeds", seeds, "a list of integers >= 0", source)
    seed_parameter = data.get("seed_parameter", DEFAULT_SEED_PARAMETER)
    _check_parameter_name(seed_parameter, "seed_parameter", source)
    if "seed_parameter" in data and not seeds:
        raise StudyError("seed_parameter", seed_parameter, "seeds = [...] as well", source)

    measures_tab = data.get("measures")
    if not isinstance(measures_tab, list) or not measures_tab:
        raise StudyError("measures", measures_tab, 'a non-empty list such as ["I_max_acc", "cpu_time"]', source)
    measures = []
    for i, text in enumerate(measures_tab):
        try:
            measures.append(parse_measure(text))
        except MeasureError as exc:
            raise StudyError(f"measures[{i}]", text, exc.expected, source) from None

    plots_tab = data.get("plots", [])
    if not isinstance(plots_tab, list):
        raise StudyError("plots", plots_tab, "an array of tables [[plots]]", source)
    plots = tuple(_plot(tab, i, source) for i, tab in enumerate(plots_tab))

    return Study(
        name=st_name, engine=engine, base=base, measures=tuple(measures), axes=axes, points=tuple(points),
        seeds=tuple(seeds), seed_parameter=seed_parameter, simulation=simulation, solver=solver, plots=plots,
        timeout_s=data.get("timeout"), description=description, base_dir=base_dir, source=source,
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
