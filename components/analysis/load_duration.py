"""Load duration distributions (LDD): the time, and the revolutions, a signal spends in each load bin.

Time spent in each load bin: every sample carries the time ``(t_{k+1} - t_{k-1}) / 2``
(half an interval at the ends), so the bins sum to the analysed time ``t_end -
t_start`` exactly. Bins are given as a number of equal bins over the signal's range
(default 64) or as explicit edges. With a speed signal the same weights times
``|omega| / 2 pi`` give the load *revolution* distribution (revolutions at each load
level, the input of gear rating per ISO 6336-6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import ParameterError
from ..reference.results import select_window


@dataclass(frozen=True)
class LoadDurationDistribution:
    """Time (and optionally revolutions) spent in each load bin.

    Attributes
    ----------
    name : str
        Signal name.
    unit : str
        Unit of the load.
    edges : ndarray, shape (B + 1,)
        Bin edges [unit]; the last bin includes its right edge.
    time_s : ndarray, shape (B,)
        Time in each bin [s]; sums to the analysed time (loads outside explicit edges
        are reported in ``time_outside_s``).
    revolutions : ndarray or None, shape (B,)
        Revolutions in each bin (with a speed signal).
    analysed_time_s : float
        Analysed time [s].
    time_outside_s : float
        Time with the load outside explicit edges [s].
    """

    name: str
    unit: str
    edges: np.ndarray
    time_s: np.ndarray
    revolutions: np.ndarray | None
    analysed_time_s: float
    time_outside_s: float = 0.0

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {
            "unit": self.unit,
            "edges": [float(x) for x in self.edges],
            "time_s": [float(x) for x in self.time_s],
            "revolutions": None if self.revolutions is None else [float(x) for x in self.revolutions],
            "analysed_time_s": self.analysed_time_s,
            "time_outside_s": self.time_outside_s,
        }


def sample_durations(time_s: np.ndarray) -> np.ndarray:
    """Time each sample represents: ``(t_{k+1} - t_{k-1}) / 2``, half intervals at the ends [s].

    The durations sum to ``t[-1] - t[0]`` exactly.
    """
    t = np.asarray(time_s, dtype=float)
    d = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    return w


def load_duration_distribution(
    time_s: np.ndarray,
    values: np.ndarray,
    bins: int | Sequence[float] = 64,
    window: tuple[float, float] | None = None,
    speed_rad_s: np.ndarray | None = None,
    name: str = "",
    unit: str = "",
) -> LoadDurationDistribution:
    """Load duration distribution of one signal.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Sample times [s].
    values : ndarray, shape (N,)
        Load [unit].
    bins : int or sequence of float
        Number of equal bins over ``[min, max]`` or explicit increasing edges [unit].
    window : (float, float), optional
        Analysed window [s].
    speed_rad_s : ndarray, shape (N,), optional
        Speed of the shaft carrying the load [rad/s]: adds revolutions per bin.
    name, unit : str
        Signal name and its unit as declared (default ``""``: not declared; never read from the name).

    Returns
    -------
    LoadDurationDistribution
    """
    t_all = np.asarray(time_s, dtype=float)
    t, y = select_window(t_all, values, window)
    w = sample_durations(t)
    if isinstance(bins, (int, np.integer)) and not isinstance(bins, bool):
        if bins < 1:
            raise ParameterError("bins", bins, ">= 1")
        lo, hi = float(y.min()), float(y.max())
        if hi == lo:
            lo, hi = lo - 0.5 * max(abs(lo), 1.0), hi + 0.5 * max(abs(hi), 1.0)
        edges = np.linspace(lo, hi, int(bins) + 1)
    else:
        edges = np.asarray(bins, dtype=float)
        if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0.0):
            raise ParameterError("bins", bins, "a bin count or >= 2 increasing edges")
    time_in, _ = np.histogram(y, bins=edges, weights=w)
    revs = None
    if speed_rad_s is not None:
        _, sp = select_window(t_all, speed_rad_s, window)
        revs, _ = np.histogram(y, bins=edges, weights=w * np.abs(sp) / (2.0 * math.pi))
    outside = float(w.sum() - time_in.sum())
    return LoadDurationDistribution(
        name=name,
        unit=unit,
        edges=edges,
        time_s=time_in,
        revolutions=revs,
        analysed_time_s=float(t[-1] - t[0]),
        time_outside_s=max(outside, 0.0) if abs(outside) > 1e-12 * max(1.0, float(w.sum())) else 0.0,
    )
