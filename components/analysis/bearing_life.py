"""Rolling-bearing life by ISO 281: basic rating life L10 and modified life L_nm from a load spectrum.

All quantities SI (loads in N, speeds in rad/s); lives in millions of revolutions
(``[1e6 rev]``, the unit of ISO 281) or hours.

Basic rating life (ISO 281:2007, 7.1), 90 % reliability::

    L10 = (C / P)^p        [1e6 rev],   p = 3 (ball bearings), 10/3 (roller bearings)

Variable load (ISO 281, the load spectrum over the revolutions): a bearing that
runs ``dN_i`` revolutions at the radial load ``P_i`` has the equivalent dynamic
load::

    P = ( sum_i P_i^p dN_i / sum_i dN_i )^(1/p)

(:func:`equivalent_load`); here ``dN_i = |omega_i| dt_i / 2 pi`` from the speed of the
inner ring relative to the outer ring (:func:`sample_revolutions`), or the revolutions at each
load level of a load revolution distribution. The life in hours is the life in revolutions over
the revolutions per hour of the duty (:func:`life_hours`).

Modified rating life (ISO 281:2007, 9)::

    L_nm = a1 a_ISO L10

with ``a1`` the reliability factor of ISO 281 Table 12 (:data:`RELIABILITY_FACTORS`) and
``a_ISO`` either given or computed (:func:`a_iso`) from the viscosity ratio ``kappa``, the
contamination factor ``e_C``, the fatigue load limit ``C_u`` and the load ``P`` by the
equations of ISO 281:2007 9.3.3 for radial bearings:

* radial ball bearings::

      a_ISO = 0.1 [1 - (2.5671 - b1 / kappa^b2)^0.83 (e_C C_u / P)^(1/3)]^(-9.3)

* radial roller bearings::

      a_ISO = 0.1 [1 - (1.5859 - b1 / kappa^b2) (e_C C_u / P)^0.4]^(-9.185)

with ``(b1, b2)`` = (2.2649, 0.054381) ball / (1.3993, 0.054381) roller for 0.1 <= kappa < 0.4,
(1.9987, 0.19087) / (1.2348, 0.19087) for 0.4 <= kappa < 1 and (1.9987, 0.071739) /
(1.2348, 0.071739) for 1 <= kappa <= 4; kappa above 4 counts as 4, below 0.1 the equations do
not apply (refused); ``a_ISO`` is at most 50 (also where the bracket is not positive).
Under a load spectrum ``a_ISO`` depends on each level's load, so the modified life is the
Palmgren-Miner combination of the levels' lives (ISO 281's approach for varying conditions)::

    1 / L_nm = sum_i q_i / (a1 a_ISO(P_i) L10(P_i)),    q_i = dN_i / sum dN

which with a constant ``a_ISO`` is ``a1 a_ISO L10`` of the equivalent load exactly
(:func:`modified_life_mrev`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import ParameterError
from ..validation import finite_series, in_range, positive
from .load_duration import sample_durations

#: ISO 281 life exponent p per bearing type
LIFE_EXPONENTS: Mapping[str, float] = {"ball": 3.0, "roller": 10.0 / 3.0}
#: revolutions in the unit of ISO 281 lives
MILLION = 1.0e6
#: ISO 281:2007 Table 12: reliability [%] -> life modification factor a1 (L_nm: n = 100 - reliability)
RELIABILITY_FACTORS: Mapping[float, float] = {
    90.0: 1.0, 95.0: 0.64, 96.0: 0.55, 97.0: 0.47, 98.0: 0.37, 99.0: 0.25, 99.2: 0.22, 99.4: 0.19,
    99.6: 0.16, 99.8: 0.12, 99.9: 0.093, 99.92: 0.087, 99.94: 0.080, 99.95: 0.077,
}
#: ISO 281:2007 9.3.3: a_ISO is limited to this
A_ISO_MAX = 50.0
#: a bearing whose equivalent load is at most this fraction of C carries the round-off of the model's forces, not a
#: load (a symmetric planetary's sun, a carrier bearing without gravity or errors: ~1e-9 N against C ~1e6 N; a real
#: light load is above 1e-4 C): its lives are infinite, not the (C/P)^p of a round-off (~1e53 h)
UNLOADED_BELOW = 1e-9
#: the range of the viscosity ratio kappa of the a_ISO equations (above the maximum it counts as the maximum)
KAPPA_MIN, KAPPA_MAX = 0.1, 4.0

# (constant, (b1, b2) for kappa < 0.4, for 0.4 <= kappa < 1, for kappa >= 1, exponent of the bracket's
# (e_C C_u / P) term, exponent applied to the kappa term, exponent of the bracket) of ISO 281:2007 9.3.3
_A_ISO = {
    "ball": (2.5671, ((2.2649, 0.054381), (1.9987, 0.19087), (1.9987, 0.071739)), 1.0 / 3.0, 0.83, -9.3),
    "roller": (1.5859, ((1.3993, 0.054381), (1.2348, 0.19087), (1.2348, 0.071739)), 0.4, 1.0, -9.185),
}


def life_exponent(bearing_type: str) -> float:
    """p of ISO 281: 3 for ``"ball"``, 10/3 for ``"roller"``."""
    if bearing_type not in LIFE_EXPONENTS:
        raise ParameterError("bearing.type", bearing_type, '"ball" or "roller"')
    return LIFE_EXPONENTS[bearing_type]


def reliability_factor(reliability_percent: float) -> float:
    """a1 of ISO 281 Table 12 for a reliability [%] listed there (90 ... 99.95)."""
    r = float(reliability_percent)
    for listed, a1 in RELIABILITY_FACTORS.items():
        if abs(r - listed) < 1e-9:
            return a1
    raise ParameterError("reliability", reliability_percent,
                         "one of the reliabilities of ISO 281 Table 12: " + ", ".join(f"{k:g}" for k in RELIABILITY_FACTORS))


def sample_revolutions(time_s: np.ndarray, speed_rad_s: np.ndarray) -> np.ndarray:
    """Revolutions ``|omega| dt / 2 pi`` of each sample (``dt`` the sample's share of the time, as the LDD's)."""
    t = finite_series("time_s", time_s, 2)
    w = finite_series("speed_rad_s", speed_rad_s, t.size)
    if w.size != t.size:
        raise ParameterError("speed_rad_s", w.shape, f"one speed per time ({t.size})")
    return sample_durations(t) * np.abs(w) / (2.0 * math.pi)


def equivalent_load(loads_n: np.ndarray, revolutions: np.ndarray, exponent: float) -> float:
    """ISO 281's equivalent load ``(sum P_i^p dN_i / sum dN_i)^(1/p)`` [N] of a load spectrum.

    Parameters
    ----------
    loads_n : ndarray, shape (L,)
        Radial loads P_i [N] (their magnitude is used).
    revolutions : ndarray, shape (L,)
        Revolutions dN_i >= 0 at each load.
    exponent : float
        p (3 or 10/3).
    """
    p = positive("exponent", exponent)
    loads = np.abs(np.asarray(loads_n, dtype=float))
    n = np.asarray(revolutions, dtype=float)
    if loads.shape != n.shape:
        raise ParameterError("revolutions", n.shape, f"one value per load ({loads.shape})")
    if np.any(n < 0.0) or not np.all(np.isfinite(n)) or not np.all(np.isfinite(loads)):
        raise ParameterError("revolutions", "negative or not finite", "finite revolutions >= 0 and finite loads")
    total = float(n.sum())
    if total <= 0.0:
        raise ParameterError("revolutions", total, "> 0 revolutions in the spectrum (the bearing turned)")
    scale = float(loads.max())
    if scale == 0.0:
        return 0.0
    return scale * float(np.sum(n * (loads / scale) ** p) / total) ** (1.0 / p)  # scaled: no overflow


def round_off_load(load_n: float, dynamic_load_rating_n: float) -> bool:
    """Whether ``load_n`` is the round-off of the model's forces rather than a load: at most :data:`UNLOADED_BELOW` C."""
    return load_n <= UNLOADED_BELOW * dynamic_load_rating_n


def basic_rating_life_mrev(dynamic_load_rating_n: float, load_n: float, exponent: float) -> float:
    """L10 = (C / P)^p [1e6 rev] (inf for P = 0)."""
    c = positive("dynamic_load_rating", dynamic_load_rating_n)
    p = positive("exponent", exponent)
    load = abs(float(load_n))
    return math.inf if load == 0.0 else (c / load) ** p


def life_hours(life_mrev: float, revolutions_per_hour: float) -> float:
    """A life in [1e6 rev] as hours of the duty turning ``revolutions_per_hour``."""
    rate = positive("revolutions_per_hour", revolutions_per_hour)
    return life_mrev * MILLION / rate


def constant_speed_life_hours(dynamic_load_rating_n: float, load_n: float, exponent: float, speed_rpm: float) -> float:
    """``L10h = (C/P)^p 1e6 / (60 n)`` [h] at a constant speed ``n`` [rpm] (ISO 281's hours)."""
    return life_hours(basic_rating_life_mrev(dynamic_load_rating_n, load_n, exponent), 60.0 * positive("speed_rpm", speed_rpm))


def a_iso(bearing_type: str, viscosity_ratio: float, contamination_load_ratio: float) -> float:
    """a_ISO of a radial bearing (ISO 281:2007 9.3.3, module docstring).

    Parameters
    ----------
    bearing_type : {"ball", "roller"}
    viscosity_ratio : float
        kappa = nu / nu_1 (>= 0.1; above 4 it counts as 4).
    contamination_load_ratio : float
        ``e_C C_u / P`` (>= 0).
    """
    life_exponent(bearing_type)
    kappa = float(viscosity_ratio)
    if not (math.isfinite(kappa) and kappa >= KAPPA_MIN):
        raise ParameterError("kappa", viscosity_ratio, f">= {KAPPA_MIN:g} (ISO 281's a_ISO equations start there)")
    ratio = float(contamination_load_ratio)
    if not (math.isfinite(ratio) and ratio >= 0.0):
        raise ParameterError("e_C C_u / P", contamination_load_ratio, "a finite number >= 0")
    k = min(kappa, KAPPA_MAX)
    const, branches, load_exp, kappa_exp, outer = _A_ISO[bearing_type]
    b1, b2 = branches[0] if k < 0.4 else branches[1] if k < 1.0 else branches[2]
    bracket = 1.0 - max(const - b1 / k**b2, 0.0) ** kappa_exp * ratio**load_exp
    if bracket <= 0.0:
        return A_ISO_MAX
    return min(0.1 * bracket**outer, A_ISO_MAX)


@dataclass(frozen=True)
class LifeModification:
    """How L_nm is formed: the reliability and a_ISO (given, or from kappa, e_C and C_u).

    Parameters
    ----------
    reliability_percent : float
        A reliability of ISO 281 Table 12 (90: a1 = 1).
    a_iso : float or None
        a_ISO given (> 0, at most 50); with neither it nor kappa, e_C, C_u, a_ISO = 1 (``L_n = a1 L10``).
    viscosity_ratio, contamination_factor, fatigue_load_limit_n : float or None
        kappa, e_C (in [0, 1]) and C_u [N]: a_ISO computed per load level (all three, and no ``a_iso``).
    """

    reliability_percent: float = 90.0
    a_iso: float | None = None
    viscosity_ratio: float | None = None
    contamination_factor: float | None = None
    fatigue_load_limit_n: float | None = None

    def __post_init__(self) -> None:
        reliability_factor(self.reliability_percent)
        computed = (self.viscosity_ratio, self.contamination_factor, self.fatigue_load_limit_n)
        if self.a_iso is not None:
            in_range("a_iso", self.a_iso, 0.0, A_ISO_MAX)
            positive("a_iso", self.a_iso)
            if any(v is not None for v in computed):
                raise ParameterError("a_iso", self.a_iso, "either a_iso or kappa, e_C and C_u, not both")
        elif any(v is not None for v in computed):
            if any(v is None for v in computed):
                raise ParameterError("kappa, e_C, C_u", list(computed), "all three to compute a_ISO (or a_iso given)")
            if not self.viscosity_ratio >= KAPPA_MIN:
                raise ParameterError("kappa", self.viscosity_ratio, f">= {KAPPA_MIN:g} (ISO 281's a_ISO equations)")
            in_range("e_C", self.contamination_factor, 0.0, 1.0)
            positive("C_u", self.fatigue_load_limit_n)

    @property
    def a1(self) -> float:
        """ISO 281 Table 12 factor of the reliability."""
        return reliability_factor(self.reliability_percent)

    @property
    def given(self) -> bool:
        """Whether a modified life is asked for (a_ISO given or computable, or a reliability other than 90 %)."""
        return self.a_iso is not None or self.viscosity_ratio is not None or self.a1 != 1.0

    def a_iso_at(self, bearing_type: str, loads_n: np.ndarray) -> np.ndarray:
        """a_ISO at each load [N] (the given one everywhere, else ISO 281's equation with e_C C_u / P)."""
        loads = np.abs(np.asarray(loads_n, dtype=float))
        if self.a_iso is not None or self.viscosity_ratio is None:  # given, or none (a_ISO = 1: L_n = a1 L10)
            return np.full(loads.shape, 1.0 if self.a_iso is None else float(self.a_iso))
        ec_cu = self.contamination_factor * self.fatigue_load_limit_n
        return np.array([A_ISO_MAX if p == 0.0 else a_iso(bearing_type, self.viscosity_ratio, ec_cu / p) for p in loads])

    def describe(self) -> str:
        """One line for reports."""
        text = f"reliability {self.reliability_percent:g} % (a1 = {self.a1:g})"
        if self.a_iso is not None:
            return text + f", a_ISO = {self.a_iso:g} (given)"
        if self.viscosity_ratio is not None:
            return (text + f", a_ISO from kappa = {self.viscosity_ratio:g}, e_C = {self.contamination_factor:g}, "
                    f"C_u = {self.fatigue_load_limit_n:g} N (ISO 281 9.3.3, per load level)")
        return text + ", a_ISO = 1 (none given)"


def modified_life_mrev(bearing_type: str, dynamic_load_rating_n: float, loads_n: np.ndarray, revolutions: np.ndarray,
                       modification: LifeModification) -> float:
    """L_nm [1e6 rev] of a load spectrum: ``1 / sum_i q_i / (a1 a_ISO(P_i) (C/P_i)^p)`` (module docstring)."""
    p = life_exponent(bearing_type)
    c = positive("dynamic_load_rating", dynamic_load_rating_n)
    loads = np.abs(np.asarray(loads_n, dtype=float))
    n = np.asarray(revolutions, dtype=float)
    total = float(n.sum())
    if loads.shape != n.shape or total <= 0.0:
        raise ParameterError("revolutions", total, "one revolution count per load, > 0 in all")
    a = modification.a_iso_at(bearing_type, loads)
    damage_rate = float(np.sum((n / total) * (loads / c) ** p / a))  # 1 / L per 1e6 rev, each level's share
    return math.inf if damage_rate == 0.0 else modification.a1 / damage_rate


@dataclass(frozen=True)
class BearingLife:
    """ISO 281 lives of one bearing over a duty.

    Attributes
    ----------
    name, bearing_type : str
    dynamic_load_rating_n : float
        C [N].
    exponent : float
        p.
    equivalent_load_n : float
        P [N] over the duty's revolutions.
    revolutions : float
        Revolutions of the duty (e.g. the design life's).
    duty_hours : float
        Hours of the duty (operating hours).
    l10_mrev, l10_h : float
        Basic rating life [1e6 rev] and in hours of the duty's revolutions per hour.
    lnm_mrev, lnm_h : float or None
        Modified life, where asked for.
    modification : LifeModification
    """

    name: str
    bearing_type: str
    dynamic_load_rating_n: float
    exponent: float
    equivalent_load_n: float
    revolutions: float
    duty_hours: float
    l10_mrev: float
    l10_h: float
    lnm_mrev: float | None
    lnm_h: float | None
    modification: LifeModification

    @property
    def life_h(self) -> float:
        """The life compared with the duty: L_nm where asked for, else L10 [h]."""
        return self.lnm_h if self.lnm_h is not None else self.l10_h

    @property
    def unloaded(self) -> bool:
        """Whether the equivalent load is only round-off (:func:`round_off_load`): the lives are infinite."""
        return round_off_load(self.equivalent_load_n, self.dynamic_load_rating_n)

    @property
    def met(self) -> bool:
        """Whether the life covers the duty (L [h] >= duty hours)."""
        return self.life_h >= self.duty_hours

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready; inf as None)."""
        fin = lambda x: None if x is None or not math.isfinite(x) else float(x)  # noqa: E731
        return {"name": self.name, "type": self.bearing_type, "C_n": self.dynamic_load_rating_n,
                "exponent": self.exponent, "P_eq_n": self.equivalent_load_n, "revolutions": self.revolutions,
                "duty_h": self.duty_hours, "L10_mrev": fin(self.l10_mrev), "L10_h": fin(self.l10_h),
                "Lnm_mrev": fin(self.lnm_mrev), "Lnm_h": fin(self.lnm_h), "met": self.met, "unloaded": self.unloaded,
                "modification": self.modification.describe()}


def bearing_life(name: str, bearing_type: str, dynamic_load_rating_n: float, loads_n: np.ndarray,
                 revolutions: np.ndarray, duty_hours: float,
                 modification: LifeModification | None = None) -> BearingLife:
    """ISO 281 L10 (and L_nm) of a bearing from its load spectrum over a duty.

    An equivalent load of at most :data:`UNLOADED_BELOW` C is round-off: the lives are infinite
    (:attr:`BearingLife.unloaded`).

    Parameters
    ----------
    name : str
    bearing_type : {"ball", "roller"}
    dynamic_load_rating_n : float
        C [N].
    loads_n, revolutions : ndarray, shape (L,)
        The spectrum: radial load P_i [N] and revolutions at it (over the whole duty).
    duty_hours : float
        Hours the duty's revolutions take (> 0); the lives in hours are at this duty's
        revolutions per hour.
    modification : LifeModification, optional
        Reliability and a_ISO (default: none, only L10).
    """
    p = life_exponent(bearing_type)
    mod = modification or LifeModification()
    hours = positive("duty_hours", duty_hours)
    p_eq = equivalent_load(loads_n, revolutions, p)
    total = float(np.sum(revolutions))
    per_hour = total / hours
    if round_off_load(p_eq, positive("dynamic_load_rating", dynamic_load_rating_n)):
        l10, lnm = math.inf, (math.inf if mod.given else None)
    else:
        l10 = basic_rating_life_mrev(dynamic_load_rating_n, p_eq, p)
        lnm = modified_life_mrev(bearing_type, dynamic_load_rating_n, loads_n, revolutions, mod) if mod.given else None
    to_h = lambda life: math.inf if math.isinf(life) else life_hours(life, per_hour)  # noqa: E731
    return BearingLife(name, bearing_type, float(dynamic_load_rating_n), p, p_eq, total, hours, l10, to_h(l10),
                       lnm, None if lnm is None else to_h(lnm), mod)
