"""Long-term distribution of the hub-height mean wind speed and the probability of each wind-speed bin.

Weibull distribution with shape ``k`` and scale ``A`` [m/s]::

    F(V) = 1 - exp(-(V / A)^k),        V_ave = A Gamma(1 + 1/k)

The Rayleigh distribution of IEC 61400-1 (ed. 4, eq. 8) is the Weibull with
``k = 2`` and ``A = 2 V_ave / sqrt(pi)``::

    P_R(V) = 1 - exp(-pi (V / (2 V_ave))^2)

with the annual mean wind speed ``V_ave = 0.2 V_ref`` of the turbine class
(Table 1: class I 10 m/s, II 8.5 m/s, III 7.5 m/s).

The probability of a wind-speed bin is the difference of the CDF at its edges,
``P_b = F(V_hi) - F(V_lo)`` (not the density at the bin centre times the width,
and not renormalised over the bins: the time below cut-in and above cut-out is
not in any bin; :func:`bin_probabilities`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..validation import finite_series, one_of, positive

#: annual mean wind speed at hub height V_ave [m/s] of the IEC 61400-1 turbine classes (0.2 V_ref, Table 1)
IEC_CLASS_MEAN_SPEED_M_S = {"I": 10.0, "II": 8.5, "III": 7.5}
DISTRIBUTIONS = ("weibull", "rayleigh")


@dataclass(frozen=True)
class WindDistribution:
    """A Weibull distribution of the 10-minute mean wind speed.

    Parameters
    ----------
    shape_k : float
        Weibull shape k [-] (> 0; 2 for Rayleigh).
    scale_m_s : float
        Weibull scale A [m/s] (> 0).
    kind : {"weibull", "rayleigh"}
        How it was given (for reports; a Rayleigh has k = 2).
    iec_class : str
        The IEC turbine class it was derived from (``""`` if none).
    """

    shape_k: float
    scale_m_s: float
    kind: str = "weibull"
    iec_class: str = ""

    def __post_init__(self) -> None:
        positive("wind.k", self.shape_k)
        positive("wind.A", self.scale_m_s)
        one_of("wind.distribution", self.kind, DISTRIBUTIONS)
        if self.kind == "rayleigh" and self.shape_k != 2.0:
            raise ParameterError("wind.k", self.shape_k, "2 for a Rayleigh distribution")

    @classmethod
    def weibull(cls, shape_k: float, scale_m_s: float) -> "WindDistribution":
        """Weibull with shape k and scale A [m/s]."""
        return cls(float(shape_k), float(scale_m_s))

    @classmethod
    def rayleigh(cls, mean_speed_m_s: float, iec_class: str = "") -> "WindDistribution":
        """Rayleigh (k = 2) with annual mean speed V_ave [m/s]: ``A = 2 V_ave / sqrt(pi)``."""
        v = positive("wind.mean_speed", mean_speed_m_s)
        return cls(2.0, 2.0 * v / math.sqrt(math.pi), "rayleigh", iec_class)

    @classmethod
    def iec(cls, turbine_class: str) -> "WindDistribution":
        """Rayleigh of an IEC 61400-1 class (``"I"``, ``"II"``, ``"III"``: V_ave 10, 8.5, 7.5 m/s)."""
        name = one_of("wind.iec_class", turbine_class, tuple(IEC_CLASS_MEAN_SPEED_M_S))
        return cls.rayleigh(IEC_CLASS_MEAN_SPEED_M_S[name], name)

    @property
    def mean_speed_m_s(self) -> float:
        """V_ave = A Gamma(1 + 1/k) [m/s]."""
        return self.scale_m_s * math.gamma(1.0 + 1.0 / self.shape_k)

    def cdf(self, speed_m_s: float | np.ndarray) -> np.ndarray:
        """``F(V) = 1 - exp(-(V/A)^k)`` (0 for V <= 0)."""
        v = np.maximum(np.asarray(speed_m_s, dtype=float), 0.0)
        return -np.expm1(-((v / self.scale_m_s) ** self.shape_k))

    def pdf(self, speed_m_s: float | np.ndarray) -> np.ndarray:
        """Density ``dF/dV`` [s/m]."""
        v = np.maximum(np.asarray(speed_m_s, dtype=float), 0.0)
        k, a = self.shape_k, self.scale_m_s
        return (k / a) * (v / a) ** (k - 1.0) * np.exp(-((v / a) ** k))

    def describe(self) -> str:
        """One line for reports."""
        if self.kind == "rayleigh":
            cls_text = f"IEC class {self.iec_class}, " if self.iec_class else ""
            return f"Rayleigh ({cls_text}V_ave = {self.mean_speed_m_s:.4g} m/s)"
        return f"Weibull (k = {self.shape_k:g}, A = {self.scale_m_s:g} m/s, V_ave = {self.mean_speed_m_s:.4g} m/s)"

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {"distribution": self.kind, "k": self.shape_k, "A_m_s": self.scale_m_s,
                "mean_speed_m_s": self.mean_speed_m_s, "iec_class": self.iec_class or None}


def bin_probabilities(distribution: WindDistribution, edges_m_s: np.ndarray) -> np.ndarray:
    """Probability of each wind-speed bin ``[edges[i], edges[i+1])``: ``F(hi) - F(lo)``.

    Parameters
    ----------
    distribution : WindDistribution
    edges_m_s : ndarray, shape (B + 1,)
        Increasing bin edges [m/s] (>= 0).

    Returns
    -------
    ndarray, shape (B,)
        Probabilities; their sum is ``F(edges[-1]) - F(edges[0])``, the share of time
        the mean wind speed is inside the bins.
    """
    e = finite_series("bin edges", edges_m_s, 2)
    if np.any(np.diff(e) <= 0.0) or e[0] < 0.0:
        raise ParameterError("bin edges", e.tolist(), "increasing wind speeds >= 0 m/s")
    return np.diff(distribution.cdf(e))
