"""Lifetime fatigue from a set of load cases: run weights, lifetime DELs, Miner damage, damage by bin.

A load-case set runs each wind-speed bin ``b`` with several seeds; run ``r`` of
bin ``b`` is analysed over ``T_r`` seconds. Over the design life ``T_life`` the
turbine operates ``availability x P_b x T_life`` seconds in bin ``b``
(``P_b`` from the wind distribution,
:func:`components.analysis.wind_distribution.bin_probabilities`), and the runs
of a bin are pooled samples of it, so each cycle counted in run ``r`` stands
for ::

    w_r = availability P_b T_life / sum_{r' in b} T_r'

cycles in the life (:func:`run_weights`). Then

* lifetime damage-equivalent load at ``N_eq`` equivalent cycles, for the
  Woehler exponent ``m``::

      DEL_life,m = ( sum_r w_r sum_i n_ri S_ri^m / N_eq )^(1/m)

* lifetime Miner damage for an S-N curve (:class:`components.analysis.sn_curve.SNCurve`)::

      D_life = sum_r w_r D_r,    D_r = sum_i n_ri / N(S_ri)

  and the share of bin ``b``: ``sum_{r in b} w_r D_r / D_life``;

* the lifetime load duration and load revolution distributions: the runs'
  level histograms (:mod:`components.analysis.load_spectrum`) summed with the
  weights ``w_r``.

A year is the Julian year, 365.25 days (:data:`SECONDS_PER_YEAR`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import ParameterError
from ..validation import in_range, positive
from .fatigue import RainflowCycles
from .sn_curve import SNCurve

#: seconds in a (Julian) year
SECONDS_PER_YEAR = 365.25 * 86400.0


@dataclass(frozen=True)
class DesignLife:
    """How long and how much of the time the turbine operates.

    Parameters
    ----------
    years : float
        Design life [years] (> 0; IEC 61400-1: at least 20).
    availability : float
        Share of the time in the wind-speed bins the turbine is producing, in (0, 1].
    """

    years: float = 20.0
    availability: float = 1.0

    def __post_init__(self) -> None:
        positive("life.design_life", self.years)
        in_range("life.availability", self.availability, 0.0, 1.0)
        if self.availability == 0.0:
            raise ParameterError("life.availability", self.availability, "within (0, 1]")

    @property
    def seconds(self) -> float:
        """T_life [s]."""
        return self.years * SECONDS_PER_YEAR


def run_weights(run_bins: Sequence[int], run_lengths_s: Sequence[float], bin_probabilities: Sequence[float],
                life: DesignLife) -> np.ndarray:
    """Lifetime repetitions ``w_r = availability P_b T_life / sum_{r' in b} T_r'`` of each run.

    Parameters
    ----------
    run_bins : sequence of int
        Bin index of each run.
    run_lengths_s : sequence of float
        Analysed length of each run [s].
    bin_probabilities : sequence of float
        P_b of each bin.
    life : DesignLife

    Returns
    -------
    ndarray, shape (R,)
        Each run's weight [-]; runs of a bin without probability weigh 0.
    """
    bins = np.asarray(run_bins, dtype=int)
    lengths = np.asarray(run_lengths_s, dtype=float)
    probs = np.asarray(bin_probabilities, dtype=float)
    if bins.shape != lengths.shape:
        raise ParameterError("run_lengths_s", lengths.shape, f"one length per run ({bins.size})")
    if bins.size and (bins.min() < 0 or bins.max() >= probs.size):
        raise ParameterError("run_bins", bins.tolist(), f"bin indices 0..{probs.size - 1}")
    if np.any(lengths <= 0.0):
        raise ParameterError("run_lengths_s", lengths.tolist(), "lengths > 0 s")
    pooled = np.bincount(bins, weights=lengths, minlength=probs.size)
    return life.availability * life.seconds * probs[bins] / pooled[bins]


def damage_sum(cycles: RainflowCycles, wohler_exponent: float, scale: float = 1.0) -> float:
    """``sum_i n_i (S_i / scale)^m``: the Miner sum of a unit S-N curve, in units of ``scale^m``."""
    m = positive("wohler_exponent", wohler_exponent)
    if cycles.ranges.size == 0:
        return 0.0
    return float(np.sum(cycles.counts * (cycles.ranges / scale) ** m))


def lifetime_del(cycles_per_run: Sequence[RainflowCycles], weights: Sequence[float], wohler_exponent: float,
                 equivalent_cycles: float) -> float:
    """``(sum_r w_r sum_i n_ri S_ri^m / N_eq)^(1/m)`` [unit of the load].

    Parameters
    ----------
    cycles_per_run : sequence of RainflowCycles
    weights : sequence of float
        w_r of each run (:func:`run_weights`).
    wohler_exponent : float
        m (> 0).
    equivalent_cycles : float
        N_eq (> 0).
    """
    m = positive("wohler_exponent", wohler_exponent)
    n_eq = positive("equivalent_cycles", equivalent_cycles)
    ws = np.asarray(weights, dtype=float)
    if ws.size != len(cycles_per_run):
        raise ParameterError("weights", ws.size, f"one weight per run ({len(cycles_per_run)})")
    smax = max((float(c.ranges.max()) for c in cycles_per_run if c.ranges.size), default=0.0)
    if smax == 0.0:
        return 0.0
    # scaled by the largest range so that S^m cannot overflow for large loads and m
    total = sum(w * damage_sum(c, m, smax) for c, w in zip(cycles_per_run, ws))
    return smax * (total / n_eq) ** (1.0 / m)


@dataclass(frozen=True)
class LargestCycle:
    """The counted cycle that does the most of a lifetime damage: how far the figure rests on one event.

    With steep S-N curves (tooth loads m = 8.7, beyond a knee m = 16) and short records one cycle, often the
    half cycle of the residue that spans a record's slow drift, can carry most of D_life; the figure then
    changes with any window that cuts that cycle, and says little about the turbine's life.

    Attributes
    ----------
    share : float
        ``w_r d_ri / D_life`` [-] of that cycle.
    run : int
        Index of its run (in the order of ``cycles_per_run``).
    range : float
        Its range S [unit of the load].
    count : float
        1 (a full cycle) or 0.5 (a half cycle of the residue).
    """

    share: float
    run: int
    range: float
    count: float


#: above this share of D_life from one cycle, a lifetime damage is reported as resting on one event
ONE_EVENT_SHARE = 0.5


@dataclass(frozen=True)
class LifetimeDamage:
    """Miner damage of one load channel over the design life.

    Attributes
    ----------
    total : float
        D_life [-].
    per_run : ndarray, shape (R,)
        Each run's own damage D_r (over its analysed length).
    contribution : ndarray, shape (R,)
        ``w_r D_r``: each run's part of D_life.
    by_bin : ndarray, shape (B,)
        Sum of the contributions per bin.
    largest_cycle : LargestCycle or None
        The one counted cycle that does the most of D_life (None without damage).
    """

    total: float
    per_run: np.ndarray
    contribution: np.ndarray
    by_bin: np.ndarray
    largest_cycle: LargestCycle | None = None

    @property
    def share_by_bin(self) -> np.ndarray:
        """Share of D_life per bin (zeros when there is no damage)."""
        return self.by_bin / self.total if self.total > 0.0 else np.zeros_like(self.by_bin)


def lifetime_damage(cycles_per_run: Sequence[RainflowCycles], weights: Sequence[float], run_bins: Sequence[int],
                    n_bins: int, curve: SNCurve) -> LifetimeDamage:
    """Miner damage over the life and its split by wind-speed bin.

    Parameters
    ----------
    cycles_per_run : sequence of RainflowCycles
    weights : sequence of float
        w_r (:func:`run_weights`).
    run_bins : sequence of int
        Bin index of each run.
    n_bins : int
        Number of bins.
    curve : SNCurve
    """
    ws = np.asarray(weights, dtype=float)
    bins = np.asarray(run_bins, dtype=int)
    if ws.size != len(cycles_per_run) or bins.size != ws.size:
        raise ParameterError("weights", ws.size, f"one weight and bin per run ({len(cycles_per_run)})")
    per_cycle = [curve.cycle_damage(c.ranges, c.means, c.counts) for c in cycles_per_run]
    per_run = np.array([float(d.sum()) for d in per_cycle], dtype=float)
    contribution = ws * per_run
    by_bin = np.bincount(bins, weights=contribution, minlength=n_bins) if bins.size else np.zeros(n_bins)
    total = float(contribution.sum())
    largest = None
    if total > 0.0:
        run = max((r for r in range(len(per_cycle)) if per_cycle[r].size),
                  key=lambda r: ws[r] * float(per_cycle[r].max()))
        i = int(np.argmax(per_cycle[run]))
        c = cycles_per_run[run]
        largest = LargestCycle(float(ws[run] * per_cycle[run][i] / total), run, float(c.ranges[i]), float(c.counts[i]))
    return LifetimeDamage(total, per_run, contribution, by_bin, largest)
