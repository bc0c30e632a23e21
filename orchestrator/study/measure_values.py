"""The numbers behind a study's measures (:mod:`orchestrator.inputs.measures`): statistics, DELs, rates."""

from __future__ import annotations

import numpy as np

from components.reference.results import window_mask

from ..inputs.measures import STATISTICS, MeasureError, wohler_exponent_of


def statistic(values: np.ndarray, name: str) -> float:
    """One of :data:`STATISTICS` of a sample vector (NaN for no samples)."""
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return float("nan")
    if name == "mean":
        return float(x.mean())
    if name == "std":
        return float(x.std())
    if name == "min":
        return float(x.min())
    if name == "max":
        return float(x.max())
    if name == "absmax":
        return float(np.abs(x).max())
    if name == "rms":
        return float(np.sqrt(np.mean(x * x)))
    raise MeasureError(name, "one of " + ", ".join(STATISTICS))


def window_statistic(time_s: np.ndarray, values: np.ndarray, window: tuple[float, float], name: str) -> float:
    """A statistic (:data:`STATISTICS` or ``del<m>``) of ``values`` over ``window`` [s].

    Samples with ``window[0] <= t <= window[1]`` (:func:`components.reference.results.window_mask`);
    NaN without samples (a DEL needs two).
    """
    t = np.asarray(time_s, dtype=float)
    inside = window_mask(t, window)
    x = np.asarray(values, dtype=float)[inside]
    m = wohler_exponent_of(name)
    if m is None:
        return statistic(x, name)
    if x.size < 2:
        return float("nan")
    from components.analysis.fatigue import FatigueSettings, fatigue_loads

    return float(fatigue_loads(t[inside], x, FatigueSettings(wohler_exponents=(m,))).del_by_exponent[m])


def window_load_sharing(time_s: np.ndarray, forces: list[np.ndarray], window: tuple[float, float]) -> float:
    """The load-sharing factor (:func:`components.analysis.load_sharing.load_sharing`) of planet forces over ``window``."""
    from components.analysis.load_sharing import load_sharing

    inside = window_mask(np.asarray(time_s, dtype=float), window)
    if not inside.any():
        return float("nan")
    return load_sharing("stage", np.column_stack([np.asarray(f, dtype=float)[inside] for f in forces])).factor


def max_abs_rate(time_s: np.ndarray, values: np.ndarray) -> float:
    """Largest ``|dx/dt|`` between consecutive samples [unit of x per s].

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Strictly increasing times [s], N >= 2.
    values : ndarray, shape (N,)
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(values, dtype=float)
    if t.size < 2:
        return float("nan")
    return float(np.max(np.abs(np.diff(x) / np.diff(t))))
