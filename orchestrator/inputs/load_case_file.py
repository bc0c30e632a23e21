"""The load-case file (TOML): its schema and how it becomes a :class:`~orchestrator.inputs.load_cases.LoadCaseSet`.

The format is described in :mod:`orchestrator.inputs.load_cases` and, in full, in
``docs/lifetime.md``. :func:`load_load_cases` reads a file, :func:`load_cases_from_dict`
a parsed document; every mistake raises
:class:`~orchestrator.inputs.load_cases.LoadCaseError` naming the file, the key, the
value and what was expected, before anything runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal, Mapping

import numpy as np
from pydantic import Field

from components import units
from components.analysis.lifetime import DesignLife
from components.analysis.operating_law import OperatingLaw
from components.analysis.sn_curve import SNCurve
from components.analysis.wind_distribution import IEC_CLASS_MEAN_SPEED_M_S, WindDistribution
from components.errors import ParameterError

from .files import find_input_file, packaged_files, read_toml
from .load_cases import (
    DEFAULT_EQUIVALENT_CYCLES,
    DEFAULT_EXPONENTS,
    DEFAULT_LENGTH_S,
    DEFAULT_LEVELS,
    FOLDER,
    MAX_SEEDS,
    MAX_RUNS,
    SETTLED,
    TO_STOP,
    CurveRule,
    FatigueOptions,
    LoadCaseError,
    LoadCaseSet,
    OperatingRow,
)
from .master_options import ALGORITHMS, EXTRAPOLATIONS
from .rating_options import BearingLifeTable, GearRatingTable, bearing_life_options, gear_rating_options
from .overrides import SimulationOverrides
from .quantities import si_number
from .schema import NAME_PATTERN, PlausibilityTable, Table, flatten_parameters, read_document
_SPEED = "a finite number [m/s]"
#: a bare number in the unit its key names, or a quantity with its unit ("10 m/s", "16 rpm", "25.4 kN m")
_MS, _RPM, _NM = si_number("m/s"), si_number("rpm"), si_number("N.m")


class _BaseTable(Table):
    scenario: str = Field(description="a packaged scenario name or a scenario TOML path")
    parameters: dict[str, Any] = Field(default_factory=dict, description='a table of "component.parameter" = value')


class _SimulationTable(Table):
    step: float | None = Field(None, gt=0, description="a communication step > 0 [s]")
    output_interval: float | None = Field(None, gt=0, description="a sampling interval > 0 [s]")
    algorithm: Literal[ALGORITHMS] | None = None
    extrapolation: Literal[EXTRAPOLATIONS] | None = None


class _RunsTable(Table):
    length: Annotated[float, Field(gt=0)] | Literal["to_stop"] = Field(
        DEFAULT_LENGTH_S, description='the analysed length of each run > 0 [s], or "to_stop" (to the base scenario\'s stop)')
    transient: Annotated[float, Field(ge=0)] | Literal["settled"] = Field(
        "settled", description='the discarded start of each run >= 0 [s], or "settled" (the drivetrain\'s settling time)')
    seeds: Annotated[int, Field(ge=1)] | list[Annotated[int, Field(ge=0)]] = Field(
        1, description="a number of seeds >= 1 (seeds 1..n) or a list of distinct integers >= 0")
    seed_parameter: str | None = Field(None, description='a parameter name "component.parameter" ("" for none)')


class _WindTable(Table):
    distribution: Literal["weibull", "rayleigh"] = Field(description='"weibull" (k, A) or "rayleigh" (iec_class or mean_speed)')
    k: float | None = Field(None, gt=0, description="a Weibull shape > 0")
    A: _MS | None = Field(None, gt=0, description="a Weibull scale > 0 [m/s]")
    iec_class: Literal[tuple(IEC_CLASS_MEAN_SPEED_M_S)] | None = None
    mean_speed: _MS | None = Field(None, gt=0, description="an annual mean wind speed > 0 [m/s]")


class _BinsTable(Table):
    edges: list[_MS] | None = Field(None, min_length=2, description="increasing wind speeds [m/s]")
    cut_in: _MS | None = Field(None, ge=0, description="the cut-in wind speed >= 0 [m/s]")
    cut_out: _MS | None = Field(None, gt=0, description="the cut-out wind speed [m/s]")
    width: _MS | None = Field(None, gt=0, description="a bin width > 0 [m/s]")


class _LawTable(Table):
    rated_wind_speed: _MS = Field(gt=0, description="the rated wind speed > 0 [m/s]")
    rated_rotor_speed_rpm: _RPM = Field(16.0, gt=0, description="the rated rotor speed > 0 [rpm]")
    rated_torque: _NM = Field(25.4e3, gt=0, description="the rated generator torque > 0 [N m]")
    rated_sigma_rpm: _RPM = Field(0.12, gt=0, description="the rotor-speed fluctuation at rated > 0 [rpm]")
    rated_spectrum_level: float = Field(0.02, gt=0, description="the spectral level a at rated > 0 (eq. 14, rpm units)")
    minimum_rotor_speed_rpm: _RPM = Field(0.0, ge=0, description="a minimum rotor speed >= 0 [rpm]")


class _RowTable(Table):
    wind_speed: _MS = Field(description=_SPEED + " inside the bin")
    rotor_speed_rpm: _RPM | None = Field(None, gt=0, description="a mean rotor speed > 0 [rpm]")
    generator_torque: _NM | None = Field(None, description="a generator counter torque [N m]")
    sigma_rpm: _RPM | None = Field(None, gt=0, description="a rotor-speed fluctuation > 0 [rpm]")
    spectrum_level: float | None = Field(None, ge=0, description="a spectral level a >= 0 (eq. 14, rpm units)")
    parameters: dict[str, Any] = Field(default_factory=dict, description='a table of "component.parameter" = value')


class _LifeTable(Table):
    design_life: float = Field(20.0, gt=0, description="a design life > 0 [years]")
    availability: float = Field(1.0, gt=0, le=1, description="an availability in (0, 1]")


class _FatigueTable(Table):
    wohler_exponents: list[Annotated[float, Field(gt=0)]] = Field(list(DEFAULT_EXPONENTS), min_length=1,
                                                                  description="a non-empty list of exponents > 0")
    equivalent_cycles: float = Field(DEFAULT_EQUIVALENT_CYCLES, gt=0, description="a cycle count > 0")
    reference_frequency: float = Field(1.0, gt=0, description="a frequency > 0 [Hz] (short-term DELs)")
    residue: Literal["half", "repeat"] = "half"
    gate_fraction: float = Field(1e-3, ge=0, lt=1, description="a fraction in [0, 1)")
    levels: int = Field(DEFAULT_LEVELS, ge=2, description="an integer >= 2")
    channels: list[str] = Field(default_factory=list, description='a list of "component.variable" names')


class _CurveTable(Table):
    applies_to: list[str] = Field(min_length=1, description="a non-empty list of channels or signal kinds")
    slope: float = Field(gt=0, description="a Woehler slope m > 0")
    reference_range: float | None = Field(None, gt=0, description="a load range > 0 [unit of the channel]")
    reference_cycles: float | None = Field(None, gt=0, description="a cycle count > 0")
    ultimate: float | None = Field(None, gt=0, description="an ultimate load > 0 [unit of the channel]")
    knee_cycles: float | None = Field(None, gt=0, description="a cycle count > 0")
    slope_after_knee: float | None = Field(None, gt=0, description="a slope > 0")
    goodman: bool = Field(False, description="true or false")


class LoadCaseFile(Table):
    """The shape of a load-case set TOML document (module docstring, ``docs/lifetime.md``)."""

    name: str | None = Field(None, description="a set name (string)")
    description: str = Field("", description="a string")
    base: _BaseTable = Field(description='a [base] table with scenario = "..."')
    simulation: _SimulationTable = Field(default_factory=_SimulationTable, description="a [simulation] table")
    runs: _RunsTable = Field(default_factory=_RunsTable, description="a [runs] table")
    wind: _WindTable = Field(description='a [wind] table with distribution = "weibull" or "rayleigh"')
    bins: _BinsTable = Field(description="a [bins] table with edges, or cut_in, cut_out and width")
    operating_law: _LawTable | None = Field(None, description="an [operating_law] table")
    operating_points: list[_RowTable] = Field(default_factory=list, description="an array of tables [[operating_points]]")
    life: _LifeTable = Field(default_factory=_LifeTable, description="a [life] table")
    fatigue: _FatigueTable = Field(default_factory=_FatigueTable, description="a [fatigue] table")
    sn_curves: list[_CurveTable] = Field(default_factory=list, description="an array of tables [[sn_curves]]")
    timeout: float | None = Field(None, gt=0, description="a wall-clock time per run > 0 [s]")
    gear_rating: GearRatingTable | None = Field(None, description="a [gear_rating] table (ISO 6336)")
    bearing_life: BearingLifeTable | None = Field(None, description="a [bearing_life] table (ISO 281)")
    plausibility: PlausibilityTable | None = Field(None, description="a [plausibility] table with allow = [...]")


def _wind(tab: _WindTable, src: str | None) -> WindDistribution:
    if tab.distribution == "weibull":
        for key in ("k", "A"):
            if getattr(tab, key) is None:
                raise LoadCaseError(f"wind.{key}", None, "a Weibull " + ("shape > 0" if key == "k" else "scale > 0 [m/s]")
                                    + " (missing)", src)
        for key in ("iec_class", "mean_speed"):
            if getattr(tab, key) is not None:
                raise LoadCaseError(f"wind.{key}", getattr(tab, key), 'no iec_class or mean_speed with distribution = "weibull"', src)
        return WindDistribution.weibull(tab.k, tab.A)
    for key in ("k", "A"):
        if getattr(tab, key) is not None:
            raise LoadCaseError(f"wind.{key}", getattr(tab, key), 'no k or A with distribution = "rayleigh" (k = 2)', src)
    if (tab.iec_class is None) == (tab.mean_speed is None):
        raise LoadCaseError("wind", tab.model_dump(exclude_none=True),
                            'exactly one of iec_class = "I" | "II" | "III" or mean_speed = ... [m/s] for a Rayleigh', src)
    if tab.iec_class is not None:
        return WindDistribution.iec(tab.iec_class)
    return WindDistribution.rayleigh(tab.mean_speed)


def _edges(tab: _BinsTable, src: str | None) -> tuple[float, ...]:
    regular = (tab.cut_in, tab.cut_out, tab.width)
    if (tab.edges is None) == all(v is None for v in regular):
        raise LoadCaseError("bins", tab.model_dump(exclude_none=True), "either edges = [...] or cut_in, cut_out and width", src)
    if tab.edges is not None:
        if any(v is not None for v in regular):
            raise LoadCaseError("bins", tab.model_dump(exclude_none=True), "either edges = [...] or cut_in, cut_out and width", src)
        if len(tab.edges) > MAX_RUNS + 1:  # every bin is run at least once
            raise LoadCaseError("bins.edges", f"{len(tab.edges)} wind speeds", f"at most {MAX_RUNS + 1} edges "
                                f"({MAX_RUNS} bins: a set runs at most {MAX_RUNS} runs)", src)
        edges = tuple(float(v) for v in tab.edges)
        if np.any(np.diff(edges) <= 0) or edges[0] < 0:
            raise LoadCaseError("bins.edges", list(edges), "increasing wind speeds >= 0 m/s", src)
        return edges
    for key, v in zip(("cut_in", "cut_out", "width"), regular):
        if v is None:
            raise LoadCaseError(f"bins.{key}", None, "a wind speed [m/s] (missing)", src)
    if not tab.cut_out > tab.cut_in:
        raise LoadCaseError("bins.cut_out", tab.cut_out, f"> cut_in = {tab.cut_in:g} m/s", src)
    n = (tab.cut_out - tab.cut_in) / tab.width
    if n > MAX_RUNS:  # before a tuple of that many edges exists
        raise LoadCaseError("bins.width", tab.width, f"a width of at least (cut_out - cut_in) / {MAX_RUNS} = "
                            f"{(tab.cut_out - tab.cut_in) / MAX_RUNS:g} m/s (at most {MAX_RUNS} bins: a set runs at "
                            f"most {MAX_RUNS} runs; this one has {n:.3g} bins)", src)
    if abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise LoadCaseError("bins.width", tab.width, f"a width that divides cut_out - cut_in = {tab.cut_out - tab.cut_in:g} m/s", src)
    return tuple(float(tab.cut_in + i * tab.width) for i in range(int(round(n)) + 1))


def _law(tab: _LawTable | None, src: str | None) -> OperatingLaw | None:
    if tab is None:
        return None
    try:
        return OperatingLaw(
            rated_wind_speed_m_s=tab.rated_wind_speed, rated_rotor_speed_rad_s=units.rpm(tab.rated_rotor_speed_rpm),
            rated_torque_nm=tab.rated_torque, rated_sigma_rad_s=units.rpm(tab.rated_sigma_rpm),
            rated_spectrum_level=tab.rated_spectrum_level * units.RPM_TO_RAD_PER_S ** 2,
            minimum_rotor_speed_rad_s=units.rpm(tab.minimum_rotor_speed_rpm))
    except ParameterError as exc:
        key = exc.name.removeprefix("operating_law.")
        key = {"minimum_rotor_speed": "minimum_rotor_speed_rpm"}.get(key, key)
        raise LoadCaseError(f"operating_law.{key}", exc.value, exc.expected, src) from None


def _row(tab: _RowTable, i: int, src: str | None) -> OperatingRow:
    key = f"operating_points[{i}]"
    params = flatten_parameters(tab.parameters, f"{key}.parameters", LoadCaseError, src)
    for name in params:
        comp, _, param = name.partition(".")
        if not comp or not param or not NAME_PATTERN.match(comp):
            raise LoadCaseError(f"{key}.parameters.{name}", name, 'a parameter name "component.parameter"', src)
    return OperatingRow(
        wind_speed_m_s=tab.wind_speed,
        rotor_speed_rad_s=None if tab.rotor_speed_rpm is None else units.rpm(tab.rotor_speed_rpm),
        generator_torque_nm=tab.generator_torque,
        sigma_rad_s=None if tab.sigma_rpm is None else units.rpm(tab.sigma_rpm),
        spectrum_level=None if tab.spectrum_level is None else tab.spectrum_level * units.RPM_TO_RAD_PER_S ** 2,
        parameters=params,
    )


def _curve(tab: _CurveTable, i: int, src: str | None) -> CurveRule:
    key = f"sn_curves[{i}]"
    if tab.reference_range is None and tab.reference_cycles is None and tab.ultimate is None:
        raise LoadCaseError(key, tab.model_dump(exclude_none=True),
                            "reference_range and reference_cycles, or ultimate (the curve through 1 cycle)", src)
    if tab.reference_range is not None and tab.reference_cycles is None:
        raise LoadCaseError(f"{key}.reference_cycles", None, "the cycle count of reference_range (missing)", src)
    if tab.reference_cycles is not None and tab.reference_range is None:
        raise LoadCaseError(f"{key}.reference_range", None, "the load range at reference_cycles (missing)", src)
    try:
        if tab.reference_range is not None:
            curve = SNCurve(tab.slope, tab.reference_range, tab.reference_cycles, tab.knee_cycles, tab.slope_after_knee,
                            tab.ultimate, tab.goodman)
        else:
            curve = SNCurve.from_ultimate(tab.slope, tab.ultimate, knee_cycles=tab.knee_cycles,
                                          slope_after_knee=tab.slope_after_knee, goodman=tab.goodman)
    except ParameterError as exc:
        name = exc.name.removeprefix("sn_curve.")
        name = {"ultimate_load": "ultimate"}.get(name, name)
        raise LoadCaseError(f"{key}.{name}", exc.value, exc.expected, src) from None
    return CurveRule(tuple(tab.applies_to), curve)


def _scenario_path(spec: str, base_dir: Path | None, source: str | None) -> Path:
    from ..errors import ScenarioError
    from .scenario_file import find_scenario

    p = Path(spec)
    if base_dir is not None and not p.is_absolute() and (base_dir / p).is_file():
        return (base_dir / p).resolve()
    try:
        return find_scenario(spec).resolve()
    except ScenarioError as exc:
        raise LoadCaseError("base.scenario", spec, exc.expected, source) from None


def load_cases_from_dict(data: Mapping[str, Any], name: str | None = None, base_dir: Path | None = None,
                         source: str | None = None) -> LoadCaseSet:
    """Build a :class:`LoadCaseSet` from parsed TOML (or an equivalent dict).

    Raises
    ------
    LoadCaseError
        Naming the first offending key.
    """
    doc = read_document(LoadCaseFile, data, LoadCaseError, source)
    if not doc.base.scenario:
        raise LoadCaseError("base.scenario", "", "a packaged scenario name or a scenario TOML path", source)
    path = _scenario_path(doc.base.scenario, base_dir, source)
    params = flatten_parameters(doc.base.parameters, "base.parameters", LoadCaseError, source)
    runs = doc.runs
    count = runs.seeds if isinstance(runs.seeds, int) else len(runs.seeds)
    if count > MAX_SEEDS:  # before a tuple of that many exists
        raise LoadCaseError("runs.seeds", runs.seeds if isinstance(runs.seeds, int) else count,
                            f"at most {MAX_SEEDS} seeds per bin", source)
    seeds = tuple(range(1, runs.seeds + 1)) if isinstance(runs.seeds, int) else tuple(runs.seeds)
    if runs.seed_parameter:
        comp, _, param = runs.seed_parameter.partition(".")
        if not comp or not param or not NAME_PATTERN.match(comp):
            raise LoadCaseError("runs.seed_parameter", runs.seed_parameter, 'a parameter name "component.parameter"', source)
    f = doc.fatigue
    exps = tuple(float(m) for m in f.wohler_exponents)
    if len(set(exps)) != len(exps):
        raise LoadCaseError("fatigue.wohler_exponents", list(exps), "distinct exponents", source)
    fatigue = FatigueOptions(exps, f.equivalent_cycles, f.reference_frequency, f.residue, f.gate_fraction, f.levels,
                             tuple(dict.fromkeys(f.channels)))
    life = DesignLife(doc.life.design_life, doc.life.availability)
    sim = SimulationOverrides(step_s=doc.simulation.step, output_interval_s=doc.simulation.output_interval,
                              algorithm=doc.simulation.algorithm, extrapolation=doc.simulation.extrapolation)
    return LoadCaseSet(
        name=doc.name if doc.name is not None else (name or "load-cases"), base_scenario=doc.base.scenario, base_path=path,
        base_parameters=params, simulation=sim, length_s=None if runs.length == TO_STOP else runs.length,
        transient_s=None if runs.transient == SETTLED else runs.transient, seeds=seeds,
        seed_parameter=runs.seed_parameter, wind=_wind(doc.wind, source), edges_m_s=_edges(doc.bins, source),
        law=_law(doc.operating_law, source), rows=tuple(_row(r, i, source) for i, r in enumerate(doc.operating_points)),
        life=life, fatigue=fatigue, curves=tuple(_curve(c, i, source) for i, c in enumerate(doc.sn_curves)),
        timeout_s=doc.timeout, description=doc.description, source=source,
        gear_rating=gear_rating_options(doc.gear_rating, LoadCaseError, source),
        bearing_life=bearing_life_options(doc.bearing_life, LoadCaseError, source),
        allow_implausible=tuple(doc.plausibility.allow) if doc.plausibility is not None else (),
    )


def load_load_cases(path: str | Path) -> LoadCaseSet:
    """Read and validate a load-case set TOML file.

    Raises
    ------
    LoadCaseError
        On a missing/unreadable file, a TOML syntax error, or any invalid entry.
    """
    path = Path(path)
    data = read_toml(path, LoadCaseError)
    return load_cases_from_dict(data, name=path.stem, base_dir=path.resolve().parent, source=str(path))


def packaged_load_cases() -> dict[str, Path]:
    """Load-case sets shipped with dtcosim, by name (e.g. ``"paper-turbine"``)."""
    return packaged_files(FOLDER)


def find_load_cases(spec: str | Path) -> Path:
    """A load-case set file from a path or the name of a packaged set."""
    return find_input_file(spec, FOLDER, LoadCaseError, described="a load-case set TOML file",
                           plural="load-case sets")
