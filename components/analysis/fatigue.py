"""Fatigue loads: rainflow counting, damage-equivalent loads and a run's fatigue report.

Rainflow counting
-----------------
Turning points (reversals) are taken from the samples exactly (no load classes), then
filtered with a hysteresis gate: a reversal counts only once the signal has moved
back from it by at least ``gate`` (default 0.1 % of the signal's range), which
removes solver-noise cycles without quantising the ranges. The cycles are
extracted by fatpack's four-point rainflow algorithm (``fatpack.find_rainflow_cycles``).
What is left over (the *residue*) is counted either

* ``"half"`` (default): as half cycles between successive residue reversals, as in
  ASTM E1049-85 (5.4.4), or
* ``"repeat"``: by closing it on itself as if the record repeated
  (``fatpack.concatenate_reversals(residue, residue)``), which suits a record taken
  as one period of a stationary process.

Damage-equivalent load
----------------------
For a Woehler (S-N) exponent ``m`` the damage-equivalent load is the range of the
constant-amplitude cycle that, repeated ``N_ref`` times, gives the same Palmgren-Miner
damage as the counted cycles:

    DEL_m = ( sum_i n_i S_i^m / N_ref )^(1/m)

with ``n_i`` the cycle counts (1 or 1/2) and ``S_i`` the ranges. The reference cycle
count is ``N_ref = f_ref T``, ``T`` the analysed time and ``f_ref = 1 Hz`` by default
(the "1 Hz-equivalent" load common in wind-turbine load analysis); an explicit
``N_ref`` may be given instead. Default exponents 3, 5, 8, 10 (welded steel / shafts
/ gear tooth root and flank).

Load duration distribution (LDD)
--------------------------------
Time spent in each load bin: :mod:`components.analysis.load_duration`; the run-level
report below gives one per shaft torque.

Kinds and units
---------------
:func:`fatigue_report` is told which signals are loads, which of them are shaft
torques (those get an LDD) and their units, as the caller knows them from the
declarations (the FMU's record, its modelDescription units, the scenario's role
and signals: :mod:`orchestrator.run.analyses`). Without ``names`` it takes them from
what a monolithic result declares of its series
(:attr:`components.reference.results.SimulationResult.signals`); a name never says
what a series is or its unit.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import fatpack
import numpy as np

from ..errors import ParameterError
from ..model.signals import CONTACT_FORCE, SHAFT_TORQUE
from ..reference.results import SimulationResult, select_window, series_and_time
from ..validation import finite_series, non_negative, one_of, positive
from .load_duration import LoadDurationDistribution, load_duration_distribution

#: Default Woehler exponents (welded steel 3, shafts 5, gear teeth 8 and 10).
DEFAULT_WOHLER_EXPONENTS = (3.0, 5.0, 8.0, 10.0)
#: Default reference frequency of the damage-equivalent load [Hz].
DEFAULT_REFERENCE_FREQUENCY_HZ = 1.0
#: Default hysteresis gate as a fraction of the signal range [-].
DEFAULT_GATE_FRACTION = 1e-3
RESIDUE_METHODS = ("half", "repeat")


# --------------------------------------------------------------------------- rainflow
def reversals(signal: np.ndarray, gate: float = 0.0) -> np.ndarray:
    """Turning points of a signal with a hysteresis gate (first and last sample included).

    Parameters
    ----------
    signal : ndarray, shape (N,)
        Load history.
    gate : float
        A turning point is confirmed only when the signal has moved back from it by
        at least ``gate`` [unit of the signal]; 0 keeps every turning point.

    Returns
    -------
    ndarray
        Alternating peaks and valleys, starting with the first sample and ending
        with the last one (unless it is not a turning point of the gated sequence).
    """
    y = finite_series("signal", signal, 2)
    g = non_negative("gate", gate)
    # exact turning points: drop repeated values, keep sign changes of the slope
    keep = np.concatenate(([True], np.diff(y) != 0.0))
    z = y[keep]
    if z.size < 2:
        return z[:1]
    d = np.sign(np.diff(z))
    turn = np.concatenate(([True], d[1:] != d[:-1], [True]))
    z = z[turn]
    if g == 0.0 or z.size < 3:
        return z
    # hysteresis filter on the (short) turning-point sequence
    out = [z[0]]
    cand = None  # current extreme candidate
    direction = 0  # +1 rising, -1 falling, 0 undecided
    for x in z[1:]:
        if direction == 0:
            if abs(x - out[-1]) >= g:
                direction = 1 if x > out[-1] else -1
                cand = x
            continue
        if (x - cand) * direction >= 0.0:
            cand = x  # extends the current excursion
        elif abs(cand - x) >= g:
            out.append(cand)  # confirmed turning point
            direction = -direction
            cand = x
    if cand is not None:
        out.append(cand)
    return np.asarray(out)


@dataclass(frozen=True)
class RainflowCycles:
    """Rainflow-counted cycles of one signal.

    Attributes
    ----------
    ranges : ndarray, shape (K,)
        Cycle ranges ``|S|`` [unit of the signal].
    means : ndarray, shape (K,)
        Cycle means [unit of the signal].
    counts : ndarray, shape (K,)
        1 for a full cycle, 0.5 for a half cycle.
    """

    ranges: np.ndarray
    means: np.ndarray
    counts: np.ndarray

    @property
    def total_cycles(self) -> float:
        """Number of cycles (half cycles count 1/2)."""
        return float(self.counts.sum())


def _cycles_of(pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pairs = np.asarray(pairs, dtype=float)
    if pairs.ndim != 2 or pairs.size == 0:
        return np.zeros(0), np.zeros(0)
    return np.abs(pairs[:, 1] - pairs[:, 0]), 0.5 * (pairs[:, 0] + pairs[:, 1])


def rainflow(signal: np.ndarray, gate: float | None = None, residue: str = "half") -> RainflowCycles:
    """Rainflow-count a load history (fatpack's rainflow algorithm on exact turning points).

    Parameters
    ----------
    signal : ndarray, shape (N,)
        Load history (any unit, e.g. N or N m).
    gate : float, optional
        Hysteresis gate [unit of the signal]; default ``DEFAULT_GATE_FRACTION`` x range.
    residue : {"half", "repeat"}
        Counting of the residue (module docstring).

    Returns
    -------
    RainflowCycles
    """
    method = one_of("residue", residue, RESIDUE_METHODS)
    y = finite_series("signal", signal, 2)
    span = float(y.max() - y.min())
    g = DEFAULT_GATE_FRACTION * span if gate is None else non_negative("gate", gate)
    rev = reversals(y, g)
    empty = RainflowCycles(np.zeros(0), np.zeros(0), np.zeros(0))
    if rev.size < 2:
        return empty
    if rev.size == 2:
        res = rev
        full_r, full_m = np.zeros(0), np.zeros(0)
    else:
        cycles, res = fatpack.find_rainflow_cycles(rev)
        full_r, full_m = _cycles_of(cycles)
    res = np.asarray(res, dtype=float)
    if method == "half":
        half_r = np.abs(np.diff(res))
        half_m = 0.5 * (res[1:] + res[:-1])
        ranges = np.concatenate([full_r, half_r])
        means = np.concatenate([full_m, half_m])
        counts = np.concatenate([np.ones(full_r.size), np.full(half_r.size, 0.5)])
    else:
        if res.size >= 2:
            closed = fatpack.concatenate_reversals(res, res)
            cyc_res, _ = fatpack.find_rainflow_cycles(closed) if closed.size >= 3 else (np.zeros((0, 2)), closed)
            r2, m2 = _cycles_of(cyc_res)
        else:
            r2, m2 = np.zeros(0), np.zeros(0)
        ranges = np.concatenate([full_r, r2])
        means = np.concatenate([full_m, m2])
        counts = np.ones(ranges.size)
    keep = ranges > 0.0
    return RainflowCycles(ranges[keep], means[keep], counts[keep])


# --------------------------------------------------------------------------- DEL
def damage_equivalent_load(
    cycles: RainflowCycles, wohler_exponent: float, reference_cycles: float
) -> float:
    """``(sum n_i S_i^m / N_ref)^(1/m)`` [unit of the signal].

    Parameters
    ----------
    cycles : RainflowCycles
    wohler_exponent : float
        S-N slope m (> 0).
    reference_cycles : float
        N_ref (> 0).
    """
    m = positive("wohler_exponent", wohler_exponent)
    n_ref = positive("reference_cycles", reference_cycles)
    if cycles.ranges.size == 0:
        return 0.0
    smax = float(cycles.ranges.max())
    # scale by the largest range so that S^m cannot overflow for large loads and m
    damage = float(np.sum(cycles.counts * (cycles.ranges / smax) ** m))
    return smax * (damage / n_ref) ** (1.0 / m)


@dataclass(frozen=True)
class FatigueSettings:
    """How fatigue loads are computed.

    Parameters
    ----------
    wohler_exponents : tuple of float
        S-N exponents m for the damage-equivalent loads (default 3, 5, 8, 10).
    reference_frequency_hz : float
        f_ref of the reference cycle count ``N_ref = f_ref T`` [Hz] (default 1 Hz).
    reference_cycles : float or None
        An explicit N_ref instead of ``f_ref T``.
    residue : {"half", "repeat"}
        Residue counting (module docstring).
    gate_fraction : float
        Hysteresis gate as a fraction of each signal's range [-] (default 1e-3).
    ldd_bins : int or sequence of float
        LDD bins: a number of equal bins over the signal's range, or explicit edges.
    """

    wohler_exponents: tuple[float, ...] = DEFAULT_WOHLER_EXPONENTS
    reference_frequency_hz: float = DEFAULT_REFERENCE_FREQUENCY_HZ
    reference_cycles: float | None = None
    residue: str = "half"
    gate_fraction: float = DEFAULT_GATE_FRACTION
    ldd_bins: int | tuple[float, ...] = 64

    def __post_init__(self) -> None:
        exps = tuple(float(positive("wohler_exponents", m)) for m in self.wohler_exponents)
        if not exps:
            raise ParameterError("wohler_exponents", self.wohler_exponents, "at least one exponent")
        object.__setattr__(self, "wohler_exponents", exps)
        positive("reference_frequency_hz", self.reference_frequency_hz)
        if self.reference_cycles is not None:
            positive("reference_cycles", self.reference_cycles)
        one_of("residue", self.residue, RESIDUE_METHODS)
        non_negative("gate_fraction", self.gate_fraction)
        if isinstance(self.ldd_bins, (int, np.integer)) and not isinstance(self.ldd_bins, bool):
            if self.ldd_bins < 1:
                raise ParameterError("ldd_bins", self.ldd_bins, ">= 1 bin")
        else:
            edges = tuple(float(x) for x in self.ldd_bins)
            if len(edges) < 2 or np.any(np.diff(edges) <= 0.0) or not np.all(np.isfinite(edges)):
                raise ParameterError("ldd_bins", self.ldd_bins, "a bin count or >= 2 increasing finite edges")
            object.__setattr__(self, "ldd_bins", edges)

    def reference_cycles_for(self, analysed_time_s: float) -> float:
        """N_ref for an analysed time [s]."""
        if self.reference_cycles is not None:
            return float(self.reference_cycles)
        return self.reference_frequency_hz * positive("analysed_time_s", analysed_time_s)


@dataclass(frozen=True)
class FatigueLoads:
    """Damage-equivalent loads and rainflow summary of one signal.

    Attributes
    ----------
    name : str
        Signal name (e.g. ``"shaft1.torque"``).
    unit : str
        Unit of the signal (``N``, ``N.m``).
    analysed_time_s : float
        Analysed time T [s].
    reference_cycles : float
        N_ref [-].
    reference_frequency_hz : float or None
        f_ref [Hz] (None if N_ref was given explicitly).
    del_by_exponent : dict of float -> float
        DEL_m [unit].
    cycles : float
        Counted cycles (half cycles count 1/2).
    max_range : float
        Largest range [unit].
    mean, minimum, maximum : float
        Of the signal over T [unit].
    residue : str
        Residue counting used.
    """

    name: str
    unit: str
    analysed_time_s: float
    reference_cycles: float
    reference_frequency_hz: float | None
    del_by_exponent: dict[float, float]
    cycles: float
    max_range: float
    mean: float
    minimum: float
    maximum: float
    residue: str

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready; DEL keys ``"m=3"``, ...)."""
        return {
            "unit": self.unit,
            "analysed_time_s": self.analysed_time_s,
            "reference_cycles": self.reference_cycles,
            "reference_frequency_hz": self.reference_frequency_hz,
            "del": {f"m={m:g}": v for m, v in self.del_by_exponent.items()},
            "cycles": self.cycles,
            "max_range": self.max_range,
            "mean": self.mean,
            "min": self.minimum,
            "max": self.maximum,
            "residue": self.residue,
        }


def fatigue_loads(
    time_s: np.ndarray,
    values: np.ndarray,
    settings: FatigueSettings | None = None,
    window: tuple[float, float] | None = None,
    name: str = "",
    unit: str = "",
) -> FatigueLoads:
    """Rainflow count and damage-equivalent loads of one load signal.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Sample times [s].
    values : ndarray, shape (N,)
        Load (contact force [N], shaft torque [N m], ...).
    settings : FatigueSettings, optional
    window : (float, float), optional
        Analysed window [s]; default the whole record.
    name : str
        Signal name.
    unit : str, optional
        Unit as declared; default ``""`` (not declared: never read from the name).

    Returns
    -------
    FatigueLoads
    """
    s = settings or FatigueSettings()
    t, y = select_window(time_s, values, window)
    span_t = float(t[-1] - t[0])
    cyc = rainflow(y, s.gate_fraction * float(y.max() - y.min()), s.residue)
    n_ref = s.reference_cycles_for(span_t)
    dels = {m: damage_equivalent_load(cyc, m, n_ref) for m in s.wohler_exponents}
    return FatigueLoads(
        name=name,
        unit=unit,
        analysed_time_s=span_t,
        reference_cycles=n_ref,
        reference_frequency_hz=None if s.reference_cycles is not None else s.reference_frequency_hz,
        del_by_exponent=dels,
        cycles=cyc.total_cycles,
        max_range=float(cyc.ranges.max()) if cyc.ranges.size else 0.0,
        mean=float(y.mean()),
        minimum=float(y.min()),
        maximum=float(y.max()),
        residue=s.residue,
    )


# --------------------------------------------------------------------------- run level
@dataclass
class FatigueReport:
    """Fatigue loads of a run: DELs of every load signal and the LDD of every shaft torque.

    Attributes
    ----------
    loads : dict of str -> FatigueLoads
    ldd : dict of str -> LoadDurationDistribution
    settings : FatigueSettings
    window : (float, float) or None
    """

    loads: dict[str, FatigueLoads]
    ldd: dict[str, LoadDurationDistribution]
    settings: FatigueSettings
    window: tuple[float, float] | None = None
    notes: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        """Plain dict for ``summary.json``."""
        s = self.settings
        return {
            "definition": "DEL_m = (sum n_i S_i^m / N_ref)^(1/m), N_ref = f_ref * T; rainflow with "
            f"{s.residue!r} residue; LDD: time per load bin",
            "wohler_exponents": list(s.wohler_exponents),
            "reference_frequency_hz": None if s.reference_cycles is not None else s.reference_frequency_hz,
            "reference_cycles": s.reference_cycles,
            "window_s": None if self.window is None else list(self.window),
            "del": {n: v.as_dict() for n, v in self.loads.items()},
            "ldd": {n: v.as_dict() for n, v in self.ldd.items()},
        }


def fatigue_report(
    result: SimulationResult | Mapping[str, np.ndarray],
    settings: FatigueSettings | None = None,
    window: tuple[float, float] | None = None,
    names: list[str] | None = None,
    time_s: np.ndarray | None = None,
    speeds: Mapping[str, str] | None = None,
    torques: Sequence[str] | None = None,
    units: Mapping[str, str] | None = None,
) -> FatigueReport:
    """DELs of every load signal and the LDD of every shaft torque.

    Parameters
    ----------
    result : SimulationResult or mapping name -> ndarray
        A run (or plain series with ``time_s``).
    settings : FatigueSettings, optional
    window : (float, float), optional
        Analysed window [s] (e.g. the statistics window [5, 60] s).
    names : list of str, optional
        Load signals, as declared (contact forces and shaft torques). Default: the
        series a :class:`SimulationResult` declares as contact forces or shaft torques
        (a plain mapping declares none: give them).
    time_s : ndarray, optional
        Sample times for a plain mapping.
    speeds : mapping of str -> str, optional
        Speed series per shaft-torque name for load revolution distributions, e.g.
        ``{"shaft3.torque": "omega_gen"}``.
    torques : sequence of str, optional
        Which of ``names`` are shaft torques (an LDD each). Default: with ``names``
        none; without, the series the result declares as shaft torques.
    units : mapping of str -> str, optional
        Unit of each signal as declared (its FMU's modelDescription). Default: with
        ``names`` "" (not declared); without, the units the result declares.

    Returns
    -------
    FatigueReport

    Raises
    ------
    ParameterError
        ``names`` missing for a plain mapping, naming series it does not hold, or
        ``torques`` not among them.
    """
    s = settings or FatigueSettings()
    series, t = series_and_time(result, time_s)
    if names is None:  # a monolithic result declares what its series are
        if not isinstance(result, SimulationResult):
            raise ParameterError("names", None, "the load signals of a plain mapping of series, as declared (a "
                                 "mapping declares no kinds; a SimulationResult does)")
        names = result.names_of(CONTACT_FORCE, SHAFT_TORQUE)
        torques = result.names_of(SHAFT_TORQUE) if torques is None else torques
        units = result.units if units is None else units
    names = list(names)
    torques = list(torques or ())
    units = dict(units or {})
    missing = [n for n in names if n not in series]
    if missing:
        raise ParameterError("names", missing, "recorded load signals")
    stray = [n for n in torques if n not in names]
    if stray:
        raise ParameterError("torques", stray, "a subset of the load signals (names)")
    loads = {n: fatigue_loads(t, series[n], s, window, n, units.get(n, "")) for n in names}
    speeds = speeds or {}
    ldd = {
        n: load_duration_distribution(
            t, series[n], s.ldd_bins, window, series[speeds[n]] if n in speeds else None, n, units.get(n, "")
        )
        for n in torques
    }
    return FatigueReport(loads, ldd, s, window)


def write_del_csv(path: str | Path, report: FatigueReport) -> Path:
    """One row per signal and Woehler exponent: ``variable, unit, m, del, ...``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["variable", "unit", "wohler_exponent", "del", "reference_cycles", "analysed_time_s", "cycles", "max_range", "mean"])
        for name, fl in report.loads.items():
            for m, val in fl.del_by_exponent.items():
                w.writerow([name, fl.unit, m, val, fl.reference_cycles, fl.analysed_time_s, fl.cycles, fl.max_range, fl.mean])
    return path


def write_ldd_csv(path: str | Path, report: FatigueReport) -> Path:
    """One row per shaft and load bin: ``variable, unit, bin_low, bin_high, time_s[, revolutions]``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["variable", "unit", "bin_low", "bin_high", "time_s", "revolutions"])
        for name, ld in report.ldd.items():
            for i in range(ld.time_s.size):
                rev = "" if ld.revolutions is None else ld.revolutions[i]
                w.writerow([name, ld.unit, ld.edges[i], ld.edges[i + 1], ld.time_s[i], rev])
    return path
