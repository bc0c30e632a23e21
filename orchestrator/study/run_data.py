"""What a load-case run hands back besides its measures: cycles and level histograms per load channel.

Computed in the worker right after the co-simulation
(:func:`orchestrator.study.engine.run_point` with a payload whose ``run_data``
is a :class:`RunDataSpec`), so the time series never leave the worker. For
every channel over the analysed window (the transient discarded):

* the rainflow cycles (ranges, means, counts: fatpack's four-point rainflow on
  exact turning points with a hysteresis gate,
  :func:`components.analysis.fatigue.rainflow`), exact, not binned, so that
  lifetime DELs and the Miner damage for any S-N curve can be computed later
  without running again;
* the time at each load level and, for each gear the load acts on, the
  revolutions at each level, on the power-of-two lattice of
  :mod:`components.analysis.load_spectrum` (exact merging over runs);
* mean, standard deviation, minimum and maximum.

Sizes: a 600 s run of the paper's drivetrain has a few hundred cycles per
channel and at most ~2000 occupied levels, i.e. tens of kB per channel, against
~5 MB per channel for the samples themselves at 1 ms.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np


@dataclass(frozen=True)
class Channel:
    """A load channel of a load-case set.

    Attributes
    ----------
    column : str
        Recorded ``component.variable``.
    unit : str
        Its unit (from the FMU's model description).
    kind : str
        Declared signal kind (``shaft_torque``, ``contact_force``, ``rotor_torque``), or ``recorded``
        for a channel chosen in the set file.
    info : mapping of str -> str
        The declared details (stage, mesh, planet; shaft, upstream, downstream).
    gears : tuple of (str, str)
        ``(gear, speed column)`` of each gear the load acts on (load revolution distribution).
    speed_factors : tuple of float
        Empty (every factor 1), or one per gear: the gear's revolutions (or load cycles) per
        revolution of its speed column, e.g. a planet's revolutions relative to the carrier from the
        planet's absolute speed (:mod:`orchestrator.study.ratings`).
    """

    column: str
    unit: str
    kind: str
    info: Mapping[str, str] = field(default_factory=dict)
    gears: tuple[tuple[str, str], ...] = ()
    speed_factors: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.speed_factors and len(self.speed_factors) != len(self.gears):
            raise ValueError(f"{self.column}: one speed factor per gear ({len(self.gears)}), not {len(self.speed_factors)}")

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        out = {"column": self.column, "unit": self.unit, "kind": self.kind, "info": dict(self.info),
               "gears": [list(g) for g in self.gears]}
        if self.speed_factors:
            out["speed_factors"] = [float(f) for f in self.speed_factors]
        return out


@dataclass(frozen=True)
class RunDataSpec:
    """What to extract from each run.

    Attributes
    ----------
    channels : tuple of Channel
    window_s : (float, float)
        Analysed window [s] (after the transient).
    gate_fraction : float
        Rainflow hysteresis gate as a fraction of each channel's range in the run.
    residue : {"half", "repeat"}
        Rainflow residue counting.
    """

    channels: tuple[Channel, ...]
    window_s: tuple[float, float]
    gate_fraction: float = 1e-3
    residue: str = "half"

    def identity(self) -> dict:
        """What the extracted data depend on (part of the point keys)."""
        return {"channels": [c.as_dict() for c in self.channels], "window_s": list(self.window_s),
                "gate_fraction": self.gate_fraction, "residue": self.residue}


def collect_run_data(spec: RunDataSpec, time_s: np.ndarray, column: Callable[[str], np.ndarray]) -> dict[str, Any]:
    """Cycles, level histograms and statistics of every channel of one run.

    Parameters
    ----------
    spec : RunDataSpec
    time_s : ndarray, shape (N,)
        Sample times of the run [s].
    column : callable(str) -> ndarray
        Samples of a recorded ``component.variable``.

    Returns
    -------
    dict
        ``analysed_time_s``, ``window_s`` and ``channels``: column -> ``{"ranges",
        "means", "counts", "levels" (LevelHistogram arrays), "mean", "std", "min", "max"}``.
    """
    from components.analysis.fatigue import rainflow
    from components.analysis.load_spectrum import level_histogram
    from components.reference.results import window_mask

    t_all = np.asarray(time_s, dtype=float)
    inside = window_mask(t_all, spec.window_s)
    t = t_all[inside]
    out: dict[str, Any] = {"analysed_time_s": float(t[-1] - t[0]), "window_s": [float(t[0]), float(t[-1])],
                           "channels": {}}
    for ch in spec.channels:
        y = np.asarray(column(ch.column), dtype=float)[inside]
        span = float(y.max() - y.min())
        cycles = rainflow(y, spec.gate_fraction * span, spec.residue)
        factors = ch.speed_factors or (1.0,) * len(ch.gears)
        speeds = {gear: f * np.asarray(column(speed), dtype=float)[inside] for (gear, speed), f in zip(ch.gears, factors)}
        levels = level_histogram(t, y, speeds)
        out["channels"][ch.column] = {
            "ranges": cycles.ranges, "means": cycles.means, "counts": cycles.counts,
            "levels": levels.as_arrays(),
            "mean": float(y.mean()), "std": float(y.std()), "min": float(y.min()), "max": float(y.max()),
        }
    return out
