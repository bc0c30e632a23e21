"""S-N (Woehler) curves in load terms, the Goodman mean-load correction and Palmgren-Miner damage.

Ranges, not amplitudes
----------------------
Every level here is a cycle *range* ``S`` (peak to valley) in the unit of the
load channel (N for a contact force, N m for a torque), the quantity rainflow
counting gives (:mod:`components.analysis.fatigue`) and damage-equivalent loads
are stated in.

S-N curve
---------
One slope ``m`` through a reference point ``(N_ref, S_ref)``::

    N(S) = N_ref (S_ref / S)^m                              (S >= S_D)

Given an *ultimate* level instead, the curve passes through ``(1, S_u)``
(``N_ref = 1``, ``S_ref = S_u``: the "S-intercept" convention of pCrunch and
MLife). With a knee at ``N_D`` cycles (range ``S_D = S_ref (N_ref / N_D)^(1/m)``)
the curve continues below ``S_D`` either with a second slope ``m2``::

    N(S) = N_D (S_D / S)^m2                                 (S < S_D)

or, without ``m2``, as an endurance limit: cycles below ``S_D`` do no damage.

Goodman
-------
With the Goodman option a cycle of range ``S`` about the mean ``S_m`` counts as
the zero-mean range ``S / (1 - |S_m| / S_u)`` (``S_u`` the ultimate load; the
correction is linear, so it applies to ranges and amplitudes alike). The mean's
magnitude is used: a shaft in torsion or a tooth flank does not benefit from a
load of the other sign (fatpack's ``find_goodman_equivalent_stress``, used by
pCrunch, takes the signed mean; both agree for positive means). A cycle whose
``|S_m| >= S_u`` has failed statically: :func:`equivalent_ranges` raises.

Miner damage
------------
``D = sum_i n_i / N(S_i)`` with the counts ``n_i`` (1 or 1/2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..validation import positive


@dataclass(frozen=True)
class SNCurve:
    """An S-N curve of load ranges, optionally with a knee and the Goodman correction.

    Parameters
    ----------
    slope : float
        Woehler exponent m (> 0) above the knee.
    reference_range : float
        S_ref [unit of the load], a range on the curve at ``reference_cycles``.
    reference_cycles : float
        N_ref (> 0); 1 when ``reference_range`` is the ultimate (intercept) level.
    knee_cycles : float or None
        N_D: cycles at the knee (None: one slope everywhere).
    slope_after_knee : float or None
        m2 (> 0) below the knee range; None with a knee: an endurance limit (no damage
        below the knee range).
    ultimate_load : float or None
        S_u [unit] for the Goodman correction.
    goodman : bool
        Apply the Goodman mean-load correction (needs ``ultimate_load``).
    """

    slope: float
    reference_range: float
    reference_cycles: float = 1.0
    knee_cycles: float | None = None
    slope_after_knee: float | None = None
    ultimate_load: float | None = None
    goodman: bool = False

    def __post_init__(self) -> None:
        positive("sn_curve.slope", self.slope)
        positive("sn_curve.reference_range", self.reference_range)
        positive("sn_curve.reference_cycles", self.reference_cycles)
        if self.knee_cycles is not None:
            positive("sn_curve.knee_cycles", self.knee_cycles)
        if self.slope_after_knee is not None:
            positive("sn_curve.slope_after_knee", self.slope_after_knee)
            if self.knee_cycles is None:
                raise ParameterError("sn_curve.slope_after_knee", self.slope_after_knee, "knee_cycles as well")
        if self.ultimate_load is not None:
            positive("sn_curve.ultimate_load", self.ultimate_load)
        if self.goodman and self.ultimate_load is None:
            raise ParameterError("sn_curve.goodman", True, "an ultimate load for the Goodman correction")

    @classmethod
    def from_ultimate(cls, slope: float, ultimate_load: float, **kwargs) -> "SNCurve":
        """The curve through ``(1 cycle, S_u)``; ``S_u`` is also the Goodman ultimate load."""
        return cls(slope, ultimate_load, 1.0, ultimate_load=ultimate_load, **kwargs)

    @property
    def knee_range(self) -> float | None:
        """S_D [unit] (None without a knee)."""
        if self.knee_cycles is None:
            return None
        return self.reference_range * (self.reference_cycles / self.knee_cycles) ** (1.0 / self.slope)

    def cycles_to_failure(self, ranges: np.ndarray) -> np.ndarray:
        """N(S) for zero-mean ranges S [unit] (inf for S = 0 and below an endurance limit)."""
        s = np.asarray(ranges, dtype=float)
        with np.errstate(divide="ignore"):
            n = self.reference_cycles * (self.reference_range / s) ** self.slope
            knee = self.knee_range
            if knee is not None:
                below = s < knee
                if self.slope_after_knee is None:
                    n = np.where(below, np.inf, n)
                else:
                    n = np.where(below, self.knee_cycles * (knee / s) ** self.slope_after_knee, n)
        return n

    def equivalent_ranges(self, ranges: np.ndarray, means: np.ndarray) -> np.ndarray:
        """Goodman zero-mean ranges ``S / (1 - |S_m| / S_u)`` (the ranges themselves without Goodman)."""
        s = np.asarray(ranges, dtype=float)
        if not self.goodman:
            return s
        ratio = np.abs(np.asarray(means, dtype=float)) / self.ultimate_load
        if np.any(ratio >= 1.0):
            worst = float(np.max(np.abs(means)))
            raise ParameterError("sn_curve.ultimate_load", self.ultimate_load,
                                 f"> the largest cycle mean |S_m| = {worst:g} for the Goodman correction")
        return s / (1.0 - ratio)

    def cycle_damage(self, ranges: np.ndarray, means: np.ndarray, counts: np.ndarray) -> np.ndarray:
        """Each counted cycle's Palmgren-Miner damage ``n_i / N(S_eq,i)`` [-]."""
        s = self.equivalent_ranges(ranges, means)
        if s.size == 0:
            return np.zeros(0)
        inverse = np.where(s > 0.0, 1.0 / self.cycles_to_failure(np.where(s > 0.0, s, 1.0)), 0.0)
        return np.asarray(counts, dtype=float) * inverse

    def damage(self, ranges: np.ndarray, means: np.ndarray, counts: np.ndarray) -> float:
        """Palmgren-Miner damage ``sum n_i / N(S_eq,i)`` of counted cycles [-]."""
        return float(np.sum(self.cycle_damage(ranges, means, counts)))

    def describe(self) -> str:
        """One line for reports."""
        if self.reference_cycles == 1.0:
            text = f"m = {self.slope:g}, S(N=1) = {self.reference_range:g}"
        else:
            text = f"m = {self.slope:g}, S = {self.reference_range:g} at N = {self.reference_cycles:g}"
        if self.knee_cycles is not None:
            tail = f"m2 = {self.slope_after_knee:g}" if self.slope_after_knee is not None else "endurance limit"
            text += f", knee at N = {self.knee_cycles:g} ({tail})"
        if self.goodman:
            text += f", Goodman (S_u = {self.ultimate_load:g})"
        return text

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {"slope": self.slope, "reference_range": self.reference_range, "reference_cycles": self.reference_cycles,
                "knee_cycles": self.knee_cycles, "slope_after_knee": self.slope_after_knee,
                "ultimate_load": self.ultimate_load, "goodman": self.goodman, "description": self.describe()}
