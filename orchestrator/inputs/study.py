"""Parameter studies: a validated study and its points (the file that describes one: :mod:`.study_file`).

A study runs one base system many times with some parameters changed: the
design variants, load cases and wind seeds of a wind-turbine drivetrain study,
or the paper's sensitivity analysis (Sec. 4.1). It is a frozen, validated value;
every structural mistake raises :class:`StudyError` naming the key, before
anything runs. The checks that need the base system (parameter names and types,
recorded variables) are made by :func:`orchestrator.study.prepare.prepare_study`, also
before anything runs. A study file (:func:`orchestrator.inputs.study_file.load_study`;
``docs/studies.md`` has the format in full) reads::

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
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from components.validation import is_number

from ..errors import EntryError
from ..frozen_map import FrozenMap
from .limits import MAX_STUDY_POINTS
from .measures import Measure
from .origins import Origin
from .overrides import SimulationOverrides
from .schema import NAME_PATTERN, ParameterValue

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


def check_parameter_name(name: Any, key: str, source: str | None) -> str:
    """``name`` if it is a parameter name ``"component.parameter"``, else a StudyError for ``key``."""
    if not isinstance(name, str):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    comp, param = split_parameter(name)
    if not comp or not param or not NAME_PATTERN.match(comp):
        raise StudyError(key, name, 'a parameter name "component.parameter"', source)
    return name


@dataclass(frozen=True)
class Axis:
    """One axis of the study grid.

    Parameters
    ----------
    parameters : tuple of str
        ``"component.parameter"`` names set together to each value (linked
        parameters, e.g. the regularisation factor of all three stages).
    values : tuple of float, int, bool or str
        The values, at least one: as written in the study file (numbers in ``unit``, or
        quantities with their unit such as ``"5.7 kN m/rad"``); once prepared
        (:mod:`orchestrator.study.declared_values`) in the unit each parameter declares.
    label : str
        Name on plots (default: the first parameter).
    unit : str
        The unit the numbers of ``values`` are written in (``"kN m/rad"``, ``"1/mm"``, ``"rpm"``),
        converted to the parameter's own unit before anything runs; ``""``: the parameter's unit.
    shown : tuple, optional
        The values as written, once ``values`` are converted (plots and the table show them in ``unit``).
    """

    parameters: tuple[str, ...]
    values: tuple[ParameterValue, ...]
    label: str = ""
    unit: str = ""
    shown: tuple[ParameterValue, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", tuple(self.parameters))
        object.__setattr__(self, "values", tuple(self.values))
        if not self.parameters:
            raise StudyError("axes.parameters", list(self.parameters), "at least one parameter")
        if not self.values:
            raise StudyError("axes.values", list(self.values), "at least one value")
        if self.shown is not None and len(self.shown) != len(self.values):
            raise StudyError("axes.values", list(self.shown), f"{len(self.values)} shown values, one per value")
        if not self.label:
            object.__setattr__(self, "label", self.parameters[0])

    def display(self, value: ParameterValue) -> ParameterValue:
        """A value as shown on plots and in the table: as written (in ``unit``), numbers to 12 digits.

        Rounded so that a sum of floats reads 2.8648, not 2.8648000000000002.
        """
        if self.shown is not None and value in self.values:
            value = self.shown[self.values.index(value)]
        return float(f"{value:.12g}") if is_number(value) else value

    def converted(self, values: tuple[ParameterValue, ...]) -> "Axis":
        """The axis running ``values`` (in the parameters' units) and showing the values as written."""
        return replace(self, values=tuple(values), shown=self.shown if self.shown is not None else self.values)

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
    allow_implausible : tuple of str
        ``"component.parameter"`` values kept although implausible by physics (``[plausibility] allow``,
        ``--allow-implausible``), for every point.
    point_origins : tuple of mapping of str -> Origin
        Where the values of each explicit point were given, by whoever made the points (a load-case
        set's entries); default the study's ``points[i]`` (:meth:`origins`).
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
    allow_implausible: tuple[str, ...] = ()
    point_origins: tuple[Mapping[str, Origin], ...] = ()

    def __post_init__(self) -> None:
        src = self.source
        for attr in ("measures", "axes", "points", "seeds", "plots", "allow_implausible", "point_origins"):
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
        for i, key in enumerate(self.allow_implausible):
            check_parameter_name(key, f"plausibility.allow[{i}]", src)
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
            check_parameter_name(self.seed_parameter, "seed_parameter", src)
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

    def origins(self, point: Point) -> dict[str, Origin]:
        """Where each value of ``point`` was given: ``axes[0].values[3] (gearbox.R1)``, ``points[1].wind.omega0``, a seed.

        Made when a point's values are applied (:mod:`orchestrator.inputs.origins`), not kept per point.
        """
        src, note, out = self.source, f"point {point.index}", {}
        if self.points:
            i = point.coords[0]
            given = self.point_origins[i] if self.point_origins else {}
            out.update({p: given.get(p) or Origin(src, f"points[{i}].{p}", note, StudyError) for p in self.points[i]})
        for j, (axis, k) in enumerate(zip(self.axes, point.coords[1:-1])):
            out.update({p: Origin(src, f"axes[{j}].values[{k}] ({p})", note, StudyError) for p in axis.parameters})
        if self.seeds:
            k = point.coords[-1]
            out[self.seed_parameter] = Origin(src, f"seeds[{k}] ({self.seed_parameter})", note, StudyError)
        return out

    def base_origins(self) -> dict[str, Origin]:
        """Where each fixed value of the base was given (``base.parameters.<name>``)."""
        return {p: Origin(self.source, f"base.parameters.{p}", error=StudyError) for p in self.base.parameters}

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

    def with_allowed(self, *keys: str) -> "Study":
        """Copy that keeps these ``"component.parameter"`` values although implausible (``--allow-implausible``)."""
        for key in keys:
            check_parameter_name(key, "--allow-implausible", self.source)
        return replace(self, allow_implausible=self.allow_implausible + tuple(keys))

    def measure(self, name: str) -> Measure:
        """The measure called ``name``."""
        for m in self.measures:
            if m.name == name:
                return m
        raise KeyError(name)
