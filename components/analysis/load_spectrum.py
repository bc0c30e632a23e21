"""Load duration and load revolution distributions on a power-of-two level lattice, merged over many runs.

A lifetime load spectrum adds the distributions of many runs (wind-speed bins
and seeds) with weights. Bins chosen per run (e.g. 64 equal bins over each
run's range, :func:`components.analysis.fatigue.load_duration_distribution`)
cannot be added; bins chosen before any run need the loads' scale. Here every
run's levels are cells of width ``w = 2^e`` in the load's unit (``e`` an integer
chosen per run so that its range spans between :data:`LATTICE_LEVELS` and twice
as many cells), cell ``i`` covering ``[i w, (i + 1) w)``. A cell of width ``2^e``
is exactly the union of two cells of width ``2^(e-1)``, so runs with different
``e`` merge exactly after coarsening to the largest ``e`` (integer division of
the indices; no value is re-binned), and a sum of weighted runs is independent
of the order of summation up to rounding.

Each sample carries the time ``(t_{k+1} - t_{k-1}) / 2`` (half an interval at
the ends, :func:`components.analysis.fatigue.sample_durations`), so a run's
times sum to its analysed length, and with a speed ``omega`` the revolutions
``time x |omega| / 2 pi``: their sum is the trapezoidal integral of ``|omega|``
over the run (the load revolution distribution per gear of ISO 6336-6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

import numpy as np

from ..errors import ParameterError
from ..validation import finite_series, integer_at_least
from .load_duration import sample_durations

#: a run's range spans at least this many (and fewer than twice as many) lattice cells
LATTICE_LEVELS = 1024


def lattice_exponent(values: np.ndarray, levels: int = LATTICE_LEVELS) -> int:
    """``e`` with ``levels <= span / 2^e < 2 levels`` (span = max - min; the magnitude if constant)."""
    y = np.asarray(values, dtype=float)
    span = float(y.max() - y.min())
    if span == 0.0:
        span = max(abs(float(y[0])), 1.0)
    return int(math.floor(math.log2(span / levels)))


@dataclass(frozen=True)
class LevelHistogram:
    """Time and revolutions per load level on the lattice of width ``2^exponent``.

    Attributes
    ----------
    exponent : int
        Cell width ``2^exponent`` [unit of the load].
    indices : ndarray of int64, shape (L,)
        Increasing occupied cells: cell ``i`` is ``[i w, (i + 1) w)``.
    time_s : ndarray, shape (L,)
        Time at each level [s].
    revolutions : mapping of str -> ndarray, shape (L,)
        Revolutions at each level per gear (name -> counts).
    """

    exponent: int
    indices: np.ndarray
    time_s: np.ndarray
    revolutions: Mapping[str, np.ndarray] = field(default_factory=dict)

    @property
    def width(self) -> float:
        """Cell width [unit]."""
        return math.ldexp(1.0, self.exponent)

    @property
    def lower(self) -> np.ndarray:
        """Lower edge of each occupied level [unit]."""
        return self.indices.astype(float) * self.width

    @property
    def upper(self) -> np.ndarray:
        """Upper edge of each occupied level [unit]."""
        return (self.indices.astype(float) + 1.0) * self.width

    @property
    def total_time_s(self) -> float:
        """Sum of the times [s]."""
        return float(self.time_s.sum())

    def total_revolutions(self, gear: str) -> float:
        """Sum of a gear's revolutions."""
        return float(self.revolutions[gear].sum())

    def dense(self) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        """Every cell from the lowest to the highest occupied one: ``(edges, time_s, revolutions)`` (zeros between)."""
        if self.indices.size == 0:
            return np.zeros(1), np.zeros(0), {g: np.zeros(0) for g in self.revolutions}
        first = int(self.indices[0])
        n = int(self.indices[-1]) - first + 1
        pos = self.indices - first
        edges = (first + np.arange(n + 1, dtype=float)) * self.width
        time = np.zeros(n)
        time[pos] = self.time_s
        revs = {}
        for g, r in self.revolutions.items():
            revs[g] = np.zeros(n)
            revs[g][pos] = r
        return edges, time, revs

    def coarsened(self, exponent: int) -> "LevelHistogram":
        """The same distribution on the coarser lattice ``2^exponent`` (>= this one's)."""
        if exponent < self.exponent:
            raise ParameterError("exponent", exponent, f">= the histogram's own {self.exponent}")
        if exponent == self.exponent:
            return self
        shifted = self.indices >> (exponent - self.exponent)  # floor division by 2^(de), also for negative cells
        cells, inverse = np.unique(shifted, return_inverse=True)
        time = np.bincount(inverse, weights=self.time_s, minlength=cells.size)
        revs = {g: np.bincount(inverse, weights=r, minlength=cells.size) for g, r in self.revolutions.items()}
        return LevelHistogram(exponent, cells, time, revs)

    def with_at_most(self, levels: int) -> "LevelHistogram":
        """Coarsened until the occupied cells span at most ``levels`` cells (for tables and plots)."""
        n = integer_at_least("levels", levels, 1)
        h = self
        while h.indices.size and int(h.indices[-1] - h.indices[0]) + 1 > n:
            h = h.coarsened(h.exponent + 1)
        return h

    def scaled(self, factor: float) -> "LevelHistogram":
        """Times and revolutions multiplied by ``factor`` (e.g. lifetime hours per simulated second)."""
        return LevelHistogram(self.exponent, self.indices, self.time_s * factor,
                              {g: r * factor for g, r in self.revolutions.items()})

    def as_arrays(self) -> dict[str, np.ndarray]:
        """Flat arrays (for ``numpy.savez``): ``exponent``, ``indices``, ``time_s``, ``rev:<gear>``."""
        out = {"exponent": np.array(self.exponent), "indices": self.indices, "time_s": self.time_s}
        out.update({f"rev:{g}": r for g, r in self.revolutions.items()})
        return out

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> "LevelHistogram":
        """Inverse of :meth:`as_arrays`."""
        revs = {k[4:]: np.asarray(v, dtype=float) for k, v in arrays.items() if k.startswith("rev:")}
        return cls(int(arrays["exponent"]), np.asarray(arrays["indices"], dtype=np.int64),
                   np.asarray(arrays["time_s"], dtype=float), revs)


def level_histogram(time_s: np.ndarray, load: np.ndarray, speeds_rad_s: Mapping[str, np.ndarray] | None = None,
                    exponent: int | None = None) -> LevelHistogram:
    """Time (and revolutions per gear) at each load level of one run.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Sample times of the analysed window [s], increasing.
    load : ndarray, shape (N,)
        Load (torque [N m], force [N]).
    speeds_rad_s : mapping of str -> ndarray, shape (N,), optional
        Speed of each gear carrying the load [rad/s] -> revolutions at each level.
    exponent : int, optional
        Lattice exponent; default :func:`lattice_exponent` of the load.

    Returns
    -------
    LevelHistogram
    """
    t = finite_series("time_s", time_s, 2)
    y = finite_series("load", load, t.size)
    if y.size != t.size:
        raise ParameterError("load", y.shape, f"one sample per time ({t.size})")
    if np.any(np.diff(t) <= 0.0):
        raise ParameterError("time_s", "not increasing", "increasing sample times")
    e = lattice_exponent(y) if exponent is None else int(exponent)
    w = sample_durations(t)
    cells = np.floor(np.ldexp(y, -e)).astype(np.int64)  # y / 2^e is exact
    occupied, inverse = np.unique(cells, return_inverse=True)
    time = np.bincount(inverse, weights=w, minlength=occupied.size)
    revs = {}
    for gear, speed in (speeds_rad_s or {}).items():
        sp = finite_series(f"speed of {gear}", speed, t.size)
        if sp.size != t.size:
            raise ParameterError(f"speed of {gear}", sp.shape, f"one sample per time ({t.size})")
        revs[gear] = np.bincount(inverse, weights=w * np.abs(sp) / (2.0 * math.pi), minlength=occupied.size)
    return LevelHistogram(e, occupied, time, revs)


def merge_histograms(histograms: Sequence[LevelHistogram], weights: Iterable[float] | None = None) -> LevelHistogram:
    """Weighted sum of level histograms on the coarsest lattice among them.

    Parameters
    ----------
    histograms : sequence of LevelHistogram
        At least one; every one with the same gears.
    weights : iterable of float, optional
        Factor of each (default 1).
    """
    hs = list(histograms)
    if not hs:
        raise ParameterError("histograms", [], "at least one level histogram")
    ws = [1.0] * len(hs) if weights is None else [float(x) for x in weights]
    if len(ws) != len(hs):
        raise ParameterError("weights", len(ws), f"one weight per histogram ({len(hs)})")
    gears = set(hs[0].revolutions)
    for h in hs[1:]:
        if set(h.revolutions) != gears:
            raise ParameterError("histograms", sorted(h.revolutions), f"the same gears in every run ({sorted(gears)})")
    e = max(h.exponent for h in hs)
    coarse = [h.coarsened(e) for h in hs]
    cells = np.unique(np.concatenate([h.indices for h in coarse]))
    time = np.zeros(cells.size)
    revs = {g: np.zeros(cells.size) for g in sorted(gears)}
    for h, wt in zip(coarse, ws):
        pos = np.searchsorted(cells, h.indices)
        time[pos] += wt * h.time_s
        for g in revs:
            revs[g][pos] += wt * h.revolutions[g]
    return LevelHistogram(e, cells, time, revs)
