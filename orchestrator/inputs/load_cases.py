"""Load-case sets: fatigue design load cases over a wind-speed distribution, validated.

A load-case set is a kind of study: one base scenario run in every wind-speed
bin with several seeds, each bin at its own operating point, the runs weighted
by the site's wind distribution over the design life. It is a frozen, validated
value; every mistake raises :class:`LoadCaseError` naming the file, the key, the
value and what was expected, before anything runs (the checks that need the
FMUs, such as parameter names and declared roles, are made by
:func:`orchestrator.study.load_cases.prepare_load_cases`, also before anything
runs). A load-case file (:func:`orchestrator.inputs.load_case_file.load_load_cases`;
``docs/lifetime.md`` has the format in full) reads::

    name = "paper-turbine"
    [base]
    scenario = "paper-60s"                 # packaged scenario name or TOML path (relative to this file)
    [runs]
    length = 600.0                         # s analysed per run (default 600; "to_stop": to the base scenario's stop)
    transient = "settled"                  # s simulated first and discarded (default "settled", see below)
    seeds = 3                              # seeds 1, 2, 3 (or a list)
    [wind]
    distribution = "rayleigh"              # or "weibull" with k and A
    iec_class = "II"                       # V_ave 10 / 8.5 / 7.5 m/s for I / II / III
    [bins]
    cut_in = 3.0                           # m/s
    cut_out = 25.0
    width = 2.0                            # or edges = [...]
    [operating_law]                        # region 2 / region 3 (components.analysis.operating_law)
    rated_wind_speed = 12.0
    [[operating_points]]                   # a table per bin, overriding the law or replacing it
    wind_speed = 4.0
    generator_torque = 3.0e3
    [life]
    design_life = 20.0                     # years
    availability = 0.97
    [fatigue]
    equivalent_cycles = 1.0e7
    [[sn_curves]]
    applies_to = ["shaft_torque"]
    slope = 5.0
    reference_range = 5.0e4
    reference_cycles = 1.0e7
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Mapping

import numpy as np

from components.analysis.lifetime import DesignLife
from components.analysis.operating_law import OperatingLaw, OperatingPoint
from components.analysis.sn_curve import SNCurve
from components.analysis.wind_distribution import WindDistribution, bin_probabilities

from ..errors import EntryError
from ..frozen_map import FrozenMap
from .origins import Origin
from .overrides import SimulationOverrides
from .rating_options import BearingLifeOptions, GearRatingOptions
from .schema import NAME_PATTERN, ParameterValue

#: folder of the packaged load-case sets (in the ``orchestrator`` package)
FOLDER = "load_cases"
DEFAULT_LENGTH_S = 600.0
DEFAULT_TRANSIENT_S = 10.0
#: ``runs.transient = "settled"`` (the default): the drivetrain's settling time, rounded up to 0.1 s
#: (:func:`orchestrator.cosim.operating_point.start_analyses`: five time constants of its slowest mode at
#: the base scenario's start)
SETTLED = "settled"
#: the most seeds per bin and runs per set: far above any design load case set (IEC 61400-1 asks for six
#: seeds per bin), low enough that a mistyped count is refused before anything is allocated
MAX_SEEDS = 1000
MAX_RUNS = 100_000
#: ``runs.length = "to_stop"``: each run analyses up to the base scenario's stop (a record's end)
TO_STOP = "to_stop"
DEFAULT_EXPONENTS = (3.0, 5.0, 8.0, 10.0)
DEFAULT_EQUIVALENT_CYCLES = 1.0e7
DEFAULT_LEVELS = 64
#: ``{seed}`` in a string parameter value is replaced by the run's seed
SEED_PLACEHOLDER = "{seed}"
#: signal kinds whose channels a load-case set analyses (every one the gearbox declares), and chosen channels
CHANNEL_KINDS = ("rotor_torque", "shaft_torque", "contact_force", "recorded", "bearing_force")


class LoadCaseError(EntryError):
    """A load-case set file (or the objects built from it) is invalid (key, value, expected, source)."""

    kind = "load-case set"


# ------------------------------------------------------------------- values
@dataclass(frozen=True)
class OperatingRow:
    """One row of ``[[operating_points]]``: the values given for the bin containing ``wind_speed_m_s``.

    Attributes
    ----------
    wind_speed_m_s : float
    rotor_speed_rad_s, generator_torque_nm, sigma_rad_s, spectrum_level : float or None
        SI (None: from the law, or the base scenario's without a law).
    parameters : mapping of str -> value
        More ``component.parameter`` values of this bin (``{seed}`` in strings replaced per run).
    """

    wind_speed_m_s: float
    rotor_speed_rad_s: float | None = None
    generator_torque_nm: float | None = None
    sigma_rad_s: float | None = None
    spectrum_level: float | None = None
    parameters: Mapping[str, ParameterValue] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", FrozenMap(dict(self.parameters)))


@dataclass(frozen=True)
class LoadBin:
    """A wind-speed bin with its probability and operating point.

    Attributes
    ----------
    index : int
    low_m_s, high_m_s : float
        Edges [m/s].
    probability : float
        ``F(high) - F(low)``.
    point : OperatingPoint
        At the bin centre (from the law, a row, or both).
    parameters : mapping of str -> value
        The row's extra parameters.
    row : int or None
        Index of the bin's ``[[operating_points]]`` row (None: the law alone).
    """

    index: int
    low_m_s: float
    high_m_s: float
    probability: float
    point: OperatingPoint
    parameters: Mapping[str, ParameterValue] = field(default_factory=dict)
    row: int | None = None

    @property
    def centre_m_s(self) -> float:
        """Bin centre [m/s]."""
        return 0.5 * (self.low_m_s + self.high_m_s)

    @property
    def label(self) -> str:
        """``"[3, 5) m/s"``."""
        return f"[{self.low_m_s:g}, {self.high_m_s:g}) m/s"


@dataclass(frozen=True)
class CurveRule:
    """An S-N curve and the channels it applies to.

    Attributes
    ----------
    applies_to : tuple of str
        Channel columns (``gearbox.shaft3.torque``), signal kinds (``shaft_torque``) or
        ``contact_force:<stage>``; a column beats ``kind:stage``, which beats a kind.
    curve : SNCurve
    """

    applies_to: tuple[str, ...]
    curve: SNCurve


@dataclass(frozen=True)
class FatigueOptions:
    """How the runs' loads are counted and combined.

    Attributes
    ----------
    wohler_exponents : tuple of float
        m of the short-term and lifetime DELs.
    equivalent_cycles : float
        N_eq of the lifetime DEL.
    reference_frequency_hz : float
        f_ref of the short-term DELs (``N_ref = f_ref T``).
    residue : {"half", "repeat"}
    gate_fraction : float
        Rainflow hysteresis gate (fraction of each run's range).
    levels : int
        At most this many load levels in the LDD/LRD tables and plots.
    channels : tuple of str
        Recorded channels analysed besides the declared loads.
    """

    wohler_exponents: tuple[float, ...] = DEFAULT_EXPONENTS
    equivalent_cycles: float = DEFAULT_EQUIVALENT_CYCLES
    reference_frequency_hz: float = 1.0
    residue: str = "half"
    gate_fraction: float = 1e-3
    levels: int = DEFAULT_LEVELS
    channels: tuple[str, ...] = ()


@dataclass(frozen=True)
class LoadCaseSet:
    """A complete, structurally valid load-case set (see the module docstring).

    Attributes
    ----------
    name : str
    base_scenario : str
        As written (packaged name or path).
    base_path : pathlib.Path
        The scenario file.
    base_parameters : mapping
        Fixed ``component.parameter`` overrides of every run.
    simulation : SimulationOverrides
        Master options (step, output interval, algorithm, extrapolation); the time grid
        comes from :attr:`length_s` and :attr:`transient_s`.
    length_s, transient_s : float or None
        Analysed length and discarded transient of each run [s]; None before :meth:`settled`
        (``runs.length = "to_stop"``, ``runs.transient = "settled"``).
    seeds : tuple of int
    seed_parameter : str or None
        ``component.parameter`` each seed sets; None: the wind source's ``seed``
        (found by its declared role); ``""``: none (seeds then only fill ``{seed}``).
    wind : WindDistribution
    edges_m_s : tuple of float
        Wind-speed bin edges [m/s].
    law : OperatingLaw or None
    rows : tuple of OperatingRow
    life : DesignLife
    fatigue : FatigueOptions
    curves : tuple of CurveRule
    timeout_s : float or None
        Wall-clock limit per run [s].
    description : str
    source : str or None
    gear_rating : GearRatingOptions
        ``[gear_rating]``: material, factors and S-N curves of the ISO 6336 ratings.
    bearing_life : BearingLifeOptions
        ``[bearing_life]``: reliability and a_ISO of the ISO 281 lives.
    allow_implausible : tuple of str
        ``"component.parameter"`` values kept although implausible by physics (``[plausibility] allow``,
        ``--allow-implausible``).
    """

    name: str
    base_scenario: str
    base_path: Path
    base_parameters: Mapping[str, ParameterValue]
    simulation: SimulationOverrides
    length_s: float | None
    transient_s: float | None
    seeds: tuple[int, ...]
    seed_parameter: str | None
    wind: WindDistribution
    edges_m_s: tuple[float, ...]
    law: OperatingLaw | None
    rows: tuple[OperatingRow, ...]
    life: DesignLife
    fatigue: FatigueOptions = field(default_factory=FatigueOptions)
    curves: tuple[CurveRule, ...] = ()
    timeout_s: float | None = None
    description: str = ""
    source: str | None = None
    gear_rating: GearRatingOptions = field(default_factory=GearRatingOptions)
    bearing_life: BearingLifeOptions = field(default_factory=BearingLifeOptions)
    allow_implausible: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        src = self.source
        object.__setattr__(self, "base_parameters", FrozenMap(dict(self.base_parameters)))
        if not isinstance(self.name, str) or not NAME_PATTERN.match(self.name):
            raise LoadCaseError("name", self.name, "a name of letters, digits, '_' or '-'", src)
        if self.length_s is not None and not (math.isfinite(self.length_s) and self.length_s > 0):
            raise LoadCaseError("runs.length", self.length_s, "a run length > 0 s", src)
        if self.transient_s is not None and not (math.isfinite(self.transient_s) and self.transient_s >= 0):
            raise LoadCaseError("runs.transient", self.transient_s, "a transient >= 0 s", src)
        if not self.seeds:
            raise LoadCaseError("runs.seeds", list(self.seeds), "at least one seed", src)
        if len(self.seeds) > MAX_SEEDS:
            raise LoadCaseError("runs.seeds", len(self.seeds), f"at most {MAX_SEEDS} seeds per bin", src)
        if len(set(self.seeds)) != len(self.seeds):
            raise LoadCaseError("runs.seeds", list(self.seeds), "distinct seeds", src)
        edges = np.asarray(self.edges_m_s, dtype=float)
        if edges.size < 2 or np.any(np.diff(edges) <= 0) or edges[0] < 0:
            raise LoadCaseError("bins.edges", list(self.edges_m_s), "at least two increasing wind speeds >= 0 m/s", src)
        for i, row in enumerate(self.rows):
            if not self.edges_m_s[0] <= row.wind_speed_m_s < self.edges_m_s[-1]:
                raise LoadCaseError(f"operating_points[{i}].wind_speed", row.wind_speed_m_s,
                                    f"a wind speed inside the bins [{self.edges_m_s[0]:g}, {self.edges_m_s[-1]:g}) m/s", src)
        if self.n_runs > MAX_RUNS:
            raise LoadCaseError("runs.seeds", len(self.seeds), f"at most {MAX_RUNS} runs in a set ({len(edges) - 1} "
                                f"bins x {len(self.seeds)} seeds = {self.n_runs})", src)
        taken: dict[int, int] = {}
        for i, row in enumerate(self.rows):
            b = self.bin_of(row.wind_speed_m_s)
            if b in taken:
                raise LoadCaseError(f"operating_points[{i}].wind_speed", row.wind_speed_m_s,
                                    f"a bin of its own (operating_points[{taken[b]}] is in the same bin "
                                    f"[{self.edges_m_s[b]:g}, {self.edges_m_s[b + 1]:g}) m/s)", src)
            taken[b] = i
        self.bins  # every bin has an operating point

    def with_allowed(self, *keys: str) -> "LoadCaseSet":
        """Copy that keeps these ``"component.parameter"`` values although implausible (``--allow-implausible``)."""
        return replace(self, allow_implausible=self.allow_implausible + tuple(keys))

    # ---------------------------------------------------------------- bins
    def bin_of(self, wind_speed_m_s: float) -> int:
        """Index of the bin ``[lo, hi)`` containing a wind speed."""
        return int(np.searchsorted(np.asarray(self.edges_m_s), wind_speed_m_s, side="right") - 1)

    @property
    def bins(self) -> tuple[LoadBin, ...]:
        """Every bin with its probability and operating point."""
        edges = np.asarray(self.edges_m_s, dtype=float)
        probs = bin_probabilities(self.wind, edges)
        rows = {self.bin_of(r.wind_speed_m_s): i for i, r in enumerate(self.rows)}
        out = []
        for b in range(edges.size - 1):
            centre = 0.5 * (edges[b] + edges[b + 1])
            row = self.rows[rows[b]] if b in rows else None
            if self.law is not None:
                point = self.law.at(centre) if centre > 0 else OperatingPoint(centre)
            elif row is not None:
                point = OperatingPoint(centre)
            else:
                raise LoadCaseError("operating_points", f"bin [{edges[b]:g}, {edges[b + 1]:g}) m/s",
                                    "an [[operating_points]] row for every bin, or an [operating_law]", self.source)
            params: Mapping[str, ParameterValue] = {}
            if row is not None:
                given = {k: getattr(row, k) for k in ("rotor_speed_rad_s", "generator_torque_nm", "sigma_rad_s",
                                                      "spectrum_level") if getattr(row, k) is not None}
                point = OperatingPoint(centre, **{k: getattr(point, k) for k in ("rotor_speed_rad_s",
                                       "generator_torque_nm", "sigma_rad_s", "spectrum_level")} | given,
                                       region="table" if self.law is None or given else point.region)
                params = row.parameters
            out.append(LoadBin(b, float(edges[b]), float(edges[b + 1]), float(probs[b]), point, params, rows.get(b)))
        return tuple(out)

    def base_origins(self) -> dict[str, Origin]:
        """Where each fixed value of the base was given (``base.parameters.<name>``)."""
        return {p: Origin(self.source, f"base.parameters.{p}", error=LoadCaseError) for p in self.base_parameters}

    def row_origin(self, b: LoadBin, name: str, run: str, field: tuple[str, str] | None = None) -> Origin:
        """Where bin ``b``'s value of ``name`` was given for ``run``: its ``[[operating_points]]`` row, else the law.

        ``field``: the operating-point value's attribute (``generator_torque_nm``) and key in the file
        (``generator_torque``); None: one of the row's ``parameters``.
        """
        if field is None:
            return Origin(self.source, f"operating_points[{b.row}].parameters.{name}", run, LoadCaseError)
        attr, key = field
        if b.row is not None and getattr(self.rows[b.row], attr) is not None:
            return Origin(self.source, f"operating_points[{b.row}].{key} ({name})", run, LoadCaseError)
        return Origin(self.source, f"operating_law ({name} at {b.centre_m_s:g} m/s)", run, LoadCaseError)

    @property
    def operating_share(self) -> float:
        """Share of the time the mean wind speed is inside the bins, ``F(cut_out) - F(cut_in)``."""
        return float(bin_probabilities(self.wind, np.asarray(self.edges_m_s)).sum())

    @property
    def n_runs(self) -> int:
        """Bins x seeds."""
        return (len(self.edges_m_s) - 1) * len(self.seeds)

    def settled(self, settling_s: float | None, settling_text: str, base_stop_s: float) -> tuple["LoadCaseSet", list[str]]:
        """The set with its transient and length in seconds, and warnings about its window.

        ``settling_s``: the base drivetrain's settling time (None: no dtcosim drivetrain, no settling
        time known); ``settling_text`` says where it comes from; ``base_stop_s``: the base scenario's
        stop (for ``length = "to_stop"``).

        Raises
        ------
        LoadCaseError
            ``transient = "settled"`` without a settling time; ``length = "to_stop"`` with nothing left.
        """
        src, notes = self.source, []
        transient = self.transient_s
        if transient is None:
            if settling_s is None:
                raise LoadCaseError("runs.transient", SETTLED, "a transient in seconds (the base scenario has no "
                                    "dtcosim drivetrain whose settling time could be derived)", src)
            transient = math.ceil(settling_s * 10.0 - 1e-9) / 10.0
        elif settling_s is not None and transient + 1e-9 < settling_s:
            notes.append(f"runs.transient = {transient:g} s is shorter than the drivetrain's settling time "
                         f"{settling_text}: every run's analysed window includes what is left of its start-up; "
                         f'runs.transient = "settled" derives it')
        length = self.length_s
        if length is None:
            length = base_stop_s - transient
            if not length > 0:
                raise LoadCaseError("runs.length", TO_STOP, f"a base scenario that runs past the transient "
                                    f"{transient:g} s (it stops at {base_stop_s:g} s)", src)
        return replace(self, transient_s=float(transient), length_s=float(length)), notes

    def time_grid(self) -> SimulationOverrides:
        """The runs' ``[simulation]``: start 0, stop ``transient + length``, window after the transient."""
        if self.transient_s is None or self.length_s is None:
            raise LoadCaseError("runs", "settled", "a set whose transient and length are known (settled())", self.source)
        stop = self.transient_s + self.length_s
        s = self.simulation
        return SimulationOverrides(start_s=0.0, stop_s=stop, step_s=s.step_s, output_interval_s=s.output_interval_s,
                                   window_s=(self.transient_s, stop), algorithm=s.algorithm,
                                   extrapolation=s.extrapolation)
