"""Gear ratings by ISO 6336: contact stress (part 2), tooth-root stress (part 3), ISO 6336-5 S-N curves, Miner damage.

SI inside (N, m, Pa); the tables written from these results state MPa. Spur gears
(helix angle 0, as the drivetrain model), involute teeth cut by the basic rack of
ISO 53 profile A (addendum 1 m, dedendum 1.25 m, root radius 0.38 m), profile shifts
``x`` as inputs (default 0).

Forces
------
The drivetrain's mesh force ``F`` is the normal force along the line of action (its
moment arm is the base radius, paper eq. 5-7); the nominal tangential force at the
reference circle is ``F_t = F cos(alpha)`` (``T / r``).

Contact stress (ISO 6336-2)::

    sigma_H0 = Z_H Z_E Z_eps Z_beta sqrt( F_t / (d_1 b) (u + 1) / u )
    sigma_H  = Z_B (pinion) or Z_D (wheel)  x  sigma_H0 sqrt(K_A K_v K_Hbeta K_Halpha)

``u = z_2 / z_1`` (negative for an internal wheel, ``z_2 < 0``), ``d_1`` the pinion's
reference diameter. ``Z_H = sqrt(2 cos(alpha_w) / (cos^2(alpha) sin(alpha_w)))``,
``Z_E = sqrt(E / (2 pi (1 - nu^2)))`` (both gears of one material), ``Z_eps = sqrt((4 -
eps_alpha) / 3)`` (spur), ``Z_beta = 1`` (spur). ``Z_B``, ``Z_D``: the single pair tooth
contact factors, ``sqrt(rho_C1 rho_C2 / (rho_B1 rho_B2))`` (pinion, ISO's M_1) at the inner
point of single pair contact, if above 1 (the same with the wheel's point D, M_2); written
with the flank curvature radii along the line of action, so that it holds for an internal mesh
too (whose wheel has ``Z_D = 1``, ISO 6336-2).

Tooth-root stress (ISO 6336-3, method B)::

    sigma_F = F_t / (b m_n) Y_F Y_S Y_beta Y_B Y_DT K_A K_v K_Fbeta K_Falpha

with the form factor ``Y_F`` and the stress correction factor ``Y_S`` of method B
(:func:`root_form_factors`: the critical section where the fillet's tangent makes 30 deg
with the tooth's centre line, the load at the outer point of single pair contact),
``K_Fbeta = K_Hbeta^N_F``, ``N_F = (b/h)^2 / (1 + b/h + (b/h)^2)`` (``b/h`` at least 3,
ISO 6336-1), ``K_Falpha = K_Halpha``. **Internal gears** (the ring): ISO 6336-3 rates them
with a substitute basic rack; here ``Y_F`` and ``Y_S`` are the rack limit of the external gear's
equations (``z`` -> infinity, the 30 deg section, the load one ``(eps_alpha - 1)`` base pitch in from
the tip): a documented simplification, not ISO's internal-gear equations (which have a 60 deg
section and the ring's own fillet). It is the conservative side of the external gear with the
ring's tooth count (``Y_F Y_S`` 2.45 against 2.29 for 180 teeth at ``eps_alpha`` = 1.95), see
``docs/lifetime.md``.

Strength (ISO 6336-2, -3, -5)::

    sigma_HG(N) = sigma_Hlim Z_NT(N) Z_L Z_v Z_R Z_W Z_X,        S_H = sigma_HG / sigma_H
    sigma_FG(N) = sigma_Flim Y_ST Y_NT(N) Y_deltarelT Y_RrelT Y_X Y_M,  S_F = sigma_FG / sigma_F

and the permissible stresses ``sigma_HP = sigma_HG / S_Hmin``, ``sigma_FP = sigma_FG / S_Fmin``.
The life factors ``Z_NT``, ``Y_NT`` over the load cycles N are the S-N curves
(:class:`LifeFactorCurve`): case-carburised steel (ISO 6336-5 Eh, quality MQ: ``sigma_Hlim`` 1500
MPa, ``sigma_Flim`` 500 MPa, ``Y_ST = 2``): ``Z_NT`` 1.6 at N <= 1e5 (the static strength), 1.0 at
the knee 5e7, ``Y_NT`` 2.5 at N <= 1e3, 1.0 at the knee 3e6, straight in log-log between. Beyond
the knee (:data:`BEYOND_KNEE`): ``"decline"`` (default, ISO 6336-2/-3's curve without optimum
conditions) to 0.85 at 1e10, and stresses below that do no damage; or ``"endurance"`` (ISO's curve
for optimum lubrication, material, manufacturing and experience): 1.0 from the knee on, stresses
below the knee's do no damage. A stress above the static strength counts on the first segment
extended to fewer cycles (and shows as a safety factor below 1 at the largest load).

``Y_M``, the mean stress factor of ISO 6336-3: 1 for a pulsating root stress; a planet is an idler,
its two meshes (sun, ring) load the two sides of its teeth, the root sees alternating bending, and
its default is 0.7 (the 70 % of ISO 6336-5's pulsating values for fully reversed loading).

Miner damage (ISO 6336-6)::

    D = sum_i n_i / N(sigma_i)

over the load cycles ``n_i`` of each gear at each force level (a gear's tooth is loaded once per
revolution by each mesh it is in, relative to the carrier for planetary gears). The equivalent
stress is the constant stress with the same damage in the same cycles ``N_L = sum n_i``:
``sigma_eq = sigma_G(N_L / D)`` (none where ``D = 0``). The spectrum's safety factor
(:func:`spectrum_safety`, ISO 6336-6) is the factor ``S`` on every stress with ``D(S sigma_i) = 1``:
1 where ``D = 1``, above 1 where the life is reached with a margin, finite also where every stress
is below the endurance limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Mapping

import numpy as np

from ..errors import ParameterError
from ..validation import finite, in_range, positive

#: ISO 53 profile A basic rack, in modules: addendum of the gear, dedendum (cutter addendum), root radius
RACK_ADDENDUM, RACK_DEDENDUM, RACK_ROOT_RADIUS = 1.0, 1.25, 0.38
#: what the life factor does beyond its knee (module docstring)
BEYOND_KNEE = ("decline", "endurance")
#: the smallest b/h in K_Fbeta's exponent N_F (ISO 6336-1)
MIN_WIDTH_TO_HEIGHT = 3.0
#: tooth count standing for the rack in the external gear's root equations (Y_F Y_S converged to 1e-4 from 1e4 on)
RACK_TEETH = 1.0e5


def involute(angle_rad: float) -> float:
    """inv(alpha) = tan(alpha) - alpha."""
    return math.tan(angle_rad) - angle_rad


def inverse_involute(value: float) -> float:
    """alpha with inv(alpha) = value (Newton from a cubic-root start)."""
    if not value >= 0.0:
        raise ParameterError("involute", value, ">= 0")
    a = (3.0 * value) ** (1.0 / 3.0) if value > 0 else 0.0
    for _ in range(60):
        f = math.tan(a) - a - value
        if abs(f) < 1e-15:
            break
        a -= f / math.tan(a) ** 2 if a > 0 else 0.0
    return a


# ------------------------------------------------------------------ S-N curves
@dataclass(frozen=True)
class LifeFactorCurve:
    """A life factor (Z_NT or Y_NT) over the load cycles: the S-N curve in units of the reference strength.

    Parameters
    ----------
    name : str
        ``"Z_NT"`` or ``"Y_NT"``.
    points : tuple of (float, float)
        ``(N, factor)`` with N increasing and the factor decreasing; the first point is the
        static strength (the factor for fewer cycles), log-log straight between points, the
        last factor for more cycles (an endurance limit: a stress below it does no damage).
    """

    name: str
    points: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        pts = tuple((float(positive(f"{self.name}.cycles", n)), float(positive(f"{self.name}.factor", f)))
                    for n, f in self.points)
        if len(pts) < 2 or any(b[0] <= a[0] or b[1] >= a[1] for a, b in zip(pts, pts[1:])):
            raise ParameterError(f"{self.name}.points", list(pts),
                                 "at least two (cycles, factor) points, cycles increasing and factors decreasing")
        object.__setattr__(self, "points", pts)

    @property
    def static(self) -> float:
        """The factor at and below the first point's cycles (static strength)."""
        return self.points[0][1]

    @property
    def endurance(self) -> float:
        """The factor beyond the last point: stresses below it do no damage."""
        return self.points[-1][1]

    def factor(self, cycles: float) -> float:
        """The life factor at N cycles."""
        n = float(cycles)
        pts = self.points
        if n <= pts[0][0]:
            return pts[0][1]
        for (n0, f0), (n1, f1) in zip(pts, pts[1:]):
            if n <= n1:
                return f0 * (f1 / f0) ** (math.log(n / n0) / math.log(n1 / n0))
        return pts[-1][1]

    def strength_at(self, cycles: float) -> float:
        """The stress ratio that fails in N cycles: :meth:`factor`, with the first segment extended below its
        cycles (the inverse of :meth:`cycles_to_failure`; above the static factor for N below the first point)."""
        (n0, f0), (n1, f1) = self.points[0], self.points[1]
        n = positive("cycles", cycles)
        if n >= n0:
            return self.factor(n)
        return f0 * (f1 / f0) ** (math.log(n / n0) / math.log(n1 / n0))

    def slopes(self) -> tuple[float, ...]:
        """The Woehler exponent ``k`` of each segment (``N ~ sigma^-k``)."""
        return tuple(math.log(n1 / n0) / math.log(f0 / f1) for (n0, f0), (n1, f1) in zip(self.points, self.points[1:]))

    def cycles_to_failure(self, ratios: np.ndarray) -> np.ndarray:
        """N at stress ratios ``sigma / sigma_ref`` (inf at or below the endurance factor).

        Above the static factor the first segment continues to fewer cycles.
        """
        r = np.asarray(ratios, dtype=float)
        out = np.full(r.shape, np.inf)
        pts = self.points
        slopes = self.slopes()
        for k, ((n0, f0), (n1, f1)) in enumerate(zip(pts, pts[1:])):
            upper = np.inf if k == 0 else f0
            inside = (r > f1) & (r <= upper)
            with np.errstate(divide="ignore"):
                out = np.where(inside, n0 * (f0 / np.where(inside, r, 1.0)) ** slopes[k], out)
        return out

    def beyond_knee(self, mode: str) -> "LifeFactorCurve":
        """The curve with ``"decline"`` (as given) or ``"endurance"`` (flat from the point with factor 1)."""
        if mode not in BEYOND_KNEE:
            raise ParameterError("beyond_knee", mode, " or ".join(f'"{m}"' for m in BEYOND_KNEE))
        if mode == "decline":
            return self
        knee = next((i for i, (_, f) in enumerate(self.points) if abs(f - 1.0) < 1e-12), None)
        if knee is None or knee == 0:
            raise ParameterError(f"{self.name}.points", list(self.points), "a knee point with factor 1 for \"endurance\"")
        return LifeFactorCurve(self.name, self.points[:knee + 1])

    def describe(self) -> str:
        """``Z_NT: 1.6 at <= 1e5, 1 at 5e7, 0.85 at 1e10`` and what comes after."""
        text = ", ".join(f"{f:g} at {'<= ' if i == 0 else ''}{n:g}" for i, (n, f) in enumerate(self.points))
        return f"{self.name}: {text}, {self.endurance:g} beyond (no damage below it)"


#: ISO 6336-2 Z_NT of case-carburised steel (no pitting permitted), the ISO 6336-3 Y_NT
CASE_CARBURISED_Z_NT = ((1.0e5, 1.6), (5.0e7, 1.0), (1.0e10, 0.85))
CASE_CARBURISED_Y_NT = ((1.0e3, 2.5), (3.0e6, 1.0), (1.0e10, 0.85))


@dataclass(frozen=True)
class GearMaterial:
    """A gear material: ISO 6336-5 strength numbers, elasticity and life factor curves.

    Parameters
    ----------
    name : str
    sigma_hlim_pa, sigma_flim_pa : float
        Endurance limits for contact and root stress [Pa] (ISO 6336-5).
    youngs_modulus_pa, poisson_ratio : float
        For Z_E.
    contact_life, bending_life : tuple of (cycles, factor)
        Z_NT and Y_NT points (:class:`LifeFactorCurve`).
    stress_correction_test_gear : float
        Y_ST (2 for the ISO reference test gear).
    """

    name: str = "case-carburised steel (ISO 6336-5 Eh, MQ)"
    sigma_hlim_pa: float = 1500.0e6
    sigma_flim_pa: float = 500.0e6
    youngs_modulus_pa: float = 206.0e9
    poisson_ratio: float = 0.3
    contact_life: tuple[tuple[float, float], ...] = CASE_CARBURISED_Z_NT
    bending_life: tuple[tuple[float, float], ...] = CASE_CARBURISED_Y_NT
    stress_correction_test_gear: float = 2.0

    def __post_init__(self) -> None:
        positive("material.sigma_Hlim", self.sigma_hlim_pa)
        positive("material.sigma_Flim", self.sigma_flim_pa)
        positive("material.E", self.youngs_modulus_pa)
        in_range("material.nu", self.poisson_ratio, 0.0, 0.5)
        positive("material.Y_ST", self.stress_correction_test_gear)
        LifeFactorCurve("Z_NT", self.contact_life)
        LifeFactorCurve("Y_NT", self.bending_life)

    @property
    def elasticity_factor(self) -> float:
        """Z_E = sqrt(E / (2 pi (1 - nu^2))) [sqrt(Pa)] (both gears of this material)."""
        return math.sqrt(self.youngs_modulus_pa / (2.0 * math.pi * (1.0 - self.poisson_ratio**2)))


#: the named materials (the default first)
MATERIALS: Mapping[str, GearMaterial] = {"case-carburised": GearMaterial()}


# --------------------------------------------------------------------- factors
@dataclass(frozen=True)
class GearFactors:
    """The influence factors of ISO 6336; None: computed from the geometry (module docstring).

    Defaults: ``K_A = 1`` and ``K_v = 1`` (the simulated mesh forces already carry the
    external load variation and the dynamic mesh force), ``K_Hbeta = 1.15`` (the face load
    factor the torsional model cannot give; IEC 61400-4's least value), ``K_Halpha = 1``
    (accurate hardened gears), every other factor 1; ``S_Hmin = 1.25`` and ``S_Fmin = 1.56``
    (IEC 61400-4's least safety factors).
    """

    K_A: float = 1.0
    K_v: float = 1.0
    K_Hbeta: float = 1.15
    K_Halpha: float = 1.0
    K_Fbeta: float | None = None
    K_Falpha: float | None = None
    Z_E: float | None = None
    Z_H: float | None = None
    Z_eps: float | None = None
    Z_beta: float = 1.0
    Z_L: float = 1.0
    Z_v: float = 1.0
    Z_R: float = 1.0
    Z_W: float = 1.0
    Z_X: float = 1.0
    Y_beta: float = 1.0
    Y_DT: float = 1.0
    Y_deltarelT: float = 1.0
    Y_RrelT: float = 1.0
    Y_X: float = 1.0
    S_Hmin: float = 1.25
    S_Fmin: float = 1.56

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if v is not None:
                positive(f.name, v)

    def updated(self, **changes) -> "GearFactors":
        """A copy with factors changed (unknown names refused)."""
        known = {f.name for f in fields(self)}
        for k in changes:
            if k not in known:
                raise ParameterError(k, changes[k], "a factor of ISO 6336: " + ", ".join(sorted(known)))
        return replace(self, **changes)


@dataclass(frozen=True)
class GearInputs:
    """Inputs of one gear of a mesh; None: computed or the default.

    Parameters
    ----------
    profile_shift : float
        x [-] (default 0).
    Y_F, Y_S : float or None
        Form and stress correction factors (method B from the geometry).
    Y_B : float
        Rim thickness factor (1: a rim thick enough).
    Y_M : float or None
        Mean stress factor (None: 0.7 for an idler, 1 otherwise).
    Z_BD : float or None
        Its single pair tooth contact factor (Z_B of a pinion, Z_D of a wheel).
    """

    profile_shift: float = 0.0
    Y_F: float | None = None
    Y_S: float | None = None
    Y_B: float = 1.0
    Y_M: float | None = None
    Z_BD: float | None = None

    def __post_init__(self) -> None:
        in_range("profile_shift", self.profile_shift, -1.0, 2.0)
        for name in ("Y_F", "Y_S", "Y_B", "Y_M", "Z_BD"):
            v = getattr(self, name)
            if v is not None:
                positive(name, v)


# -------------------------------------------------------------------- geometry
@dataclass(frozen=True)
class MeshGeometry:
    """A spur mesh: a pinion (``teeth_1 > 0``) and a wheel (``teeth_2 < 0`` for an internal gear).

    Parameters
    ----------
    teeth_1, teeth_2 : float
        Tooth counts (real-valued where the radii do not come from teeth).
    module_m, face_width_m, pressure_angle_rad : float
    profile_shift_1, profile_shift_2 : float
        x of each gear.
    """

    teeth_1: float
    teeth_2: float
    module_m: float
    face_width_m: float
    pressure_angle_rad: float
    profile_shift_1: float = 0.0
    profile_shift_2: float = 0.0

    def __post_init__(self) -> None:
        positive("teeth_1", self.teeth_1)
        finite("teeth_2", self.teeth_2)
        if abs(self.teeth_2) < 1.0 or (self.teeth_2 < 0 and -self.teeth_2 <= self.teeth_1):
            raise ParameterError("teeth_2", self.teeth_2, "an external wheel (> 0) or an internal one (< 0) with more "
                                 "teeth than the pinion")
        positive("module", self.module_m)
        positive("face_width", self.face_width_m)
        in_range("pressure_angle", self.pressure_angle_rad, math.radians(10.0), math.radians(35.0))
        if self.contact_ratio < 1.0:
            raise ParameterError("contact_ratio", self.contact_ratio, ">= 1 (the teeth overlap too little to mesh)")

    @property
    def internal(self) -> bool:
        """The wheel is an internal gear."""
        return self.teeth_2 < 0

    @property
    def ratio(self) -> float:
        """u = z_2 / z_1 (negative for an internal mesh)."""
        return self.teeth_2 / self.teeth_1

    def reference_radius(self, k: int) -> float:
        """|r| = m |z| / 2 of gear 1 or 2 [m]."""
        return 0.5 * self.module_m * abs(self.teeth_1 if k == 1 else self.teeth_2)

    def base_radius(self, k: int) -> float:
        """r_b = |r| cos(alpha) [m]."""
        return self.reference_radius(k) * math.cos(self.pressure_angle_rad)

    def tip_radius(self, k: int) -> float:
        """|r_a|: ``r + m (1 + x)`` external, ``|r| - m (1 - x)``... as ``|m z / 2 + m (1 + x)|`` with z < 0 internal."""
        z, x = (self.teeth_1, self.profile_shift_1) if k == 1 else (self.teeth_2, self.profile_shift_2)
        return abs(0.5 * self.module_m * z + self.module_m * (RACK_ADDENDUM + x))

    @property
    def working_pressure_angle_rad(self) -> float:
        """alpha_w: ``inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x_1 + x_2) / (z_1 + z_2)``."""
        a = self.pressure_angle_rad
        value = involute(a) + 2.0 * math.tan(a) * (self.profile_shift_1 + self.profile_shift_2) / (self.teeth_1 + self.teeth_2)
        return inverse_involute(value)

    @property
    def centre_distance_m(self) -> float:
        """a_w = |r_1 + r_2| cos(alpha) / cos(alpha_w) (signed radii) [m]."""
        r = 0.5 * self.module_m * abs(self.teeth_1 + self.teeth_2)
        return r * math.cos(self.pressure_angle_rad) / math.cos(self.working_pressure_angle_rad)

    @property
    def base_pitch_m(self) -> float:
        """p_b = pi m cos(alpha) [m]."""
        return math.pi * self.module_m * math.cos(self.pressure_angle_rad)

    def _tip_roll(self, k: int) -> float:
        """sqrt(r_a^2 - r_b^2): the flank's curvature radius at the tip [m]."""
        return math.sqrt(max(self.tip_radius(k) ** 2 - self.base_radius(k) ** 2, 0.0))

    @property
    def _line(self) -> float:
        """a_w sin(alpha_w): the distance of the base circles' tangent points [m]."""
        return self.centre_distance_m * math.sin(self.working_pressure_angle_rad)

    @property
    def contact_ratio(self) -> float:
        """eps_alpha = [g_a1 + s g_a2 - s a_w sin(alpha_w)] / p_b, s = +1 external, -1 internal."""
        s = -1.0 if self.internal else 1.0
        return (self._tip_roll(1) + s * self._tip_roll(2) - s * self._line) / self.base_pitch_m

    def curvature_radius_of_mate(self, k: int, rho: float) -> float:
        """The other gear's flank curvature radius [m] where gear k's is ``rho`` (same line of action)."""
        if not self.internal:
            return self._line - rho
        return rho + self._line if k == 1 else rho - self._line

    def single_contact_factor(self, k: int) -> float:
        """Z_B (k = 1) or Z_D (k = 2): ``sqrt(rho_C1 rho_C2 / (rho_1 rho_2))`` at gear k's inner single-contact point, >= 1.

        An internal wheel has Z_D = 1 (ISO 6336-2).
        """
        if k == 2 and self.internal:
            return 1.0
        aw = self.working_pressure_angle_rad
        rho_c = self.base_radius(k) * math.tan(aw)
        rho = self._tip_roll(k) - self.base_pitch_m  # one base pitch in from gear k's tip contact
        mate, mate_c = self.curvature_radius_of_mate(k, rho), self.curvature_radius_of_mate(k, rho_c)
        if rho <= 0.0 or mate <= 0.0:
            raise ParameterError("geometry", rho, "an inner point of single contact on both involutes")
        return max(1.0, math.sqrt(rho_c * mate_c / (rho * mate)))

    @property
    def zone_factor(self) -> float:
        """Z_H = sqrt(2 cos(alpha_w) / (cos^2(alpha) sin(alpha_w))) (spur)."""
        a, aw = self.pressure_angle_rad, self.working_pressure_angle_rad
        return math.sqrt(2.0 * math.cos(aw) / (math.cos(a) ** 2 * math.sin(aw)))

    @property
    def contact_ratio_factor(self) -> float:
        """Z_eps = sqrt((4 - eps_alpha) / 3) (spur)."""
        return math.sqrt(max(4.0 - self.contact_ratio, 0.0) / 3.0)

    @property
    def face_factor_exponent(self) -> float:
        """N_F = (b/h)^2 / (1 + b/h + (b/h)^2), ``h = 2.25 m``, ``b/h >= 3`` (ISO 6336-1)."""
        bh = max(self.face_width_m / ((RACK_ADDENDUM + RACK_DEDENDUM) * self.module_m), MIN_WIDTH_TO_HEIGHT)
        return bh * bh / (1.0 + bh + bh * bh)

    def root_factors(self, k: int) -> tuple[float, float]:
        """(Y_F, Y_S) of gear k by method B (an internal gear: the basic rack's, module docstring)."""
        z, x = (self.teeth_1, self.profile_shift_1) if k == 1 else (self.teeth_2, self.profile_shift_2)
        if z < 0:
            z = RACK_TEETH  # the rack limit of the external gear's equations
        # the load at the outer point of single pair contact: one (eps - 1) base pitch in from the tip
        tip = 0.5 * self.module_m * abs(z) + self.module_m * (RACK_ADDENDUM + x)  # as an external gear
        base = 0.5 * self.module_m * abs(z) * math.cos(self.pressure_angle_rad)
        roll = math.sqrt(max(tip * tip - base * base, 0.0)) - (self.contact_ratio - 1.0) * self.base_pitch_m
        load_radius = math.hypot(roll, base)
        return root_form_factors(abs(z), x, self.pressure_angle_rad, load_radius / self.module_m)


def root_form_factors(teeth: float, profile_shift: float, pressure_angle_rad: float, load_radius_modules: float,
                      dedendum: float = RACK_DEDENDUM, root_radius: float = RACK_ROOT_RADIUS) -> tuple[float, float]:
    """ISO 6336-3 (Y_F, Y_S) of an external spur gear cut by a rack (no protuberance).

    Parameters
    ----------
    teeth : float
        z (> 0).
    profile_shift : float
        x.
    pressure_angle_rad : float
    load_radius_modules : float
        Radius of the load point in modules: method B's outer point of single pair contact
        ``d_en / (2 m)``; the tip ``d_a / (2 m)`` gives method C's Y_Fa, Y_Sa.
    dedendum, root_radius : float
        h_fP / m and rho_fP / m of the basic rack.

    Notes
    -----
    ``E = pi/4 - h_fP tan(a) - (1 - sin(a)) rho_fP / cos(a)``, ``G = rho_fP - h_fP + x``,
    ``H = 2 / z (pi/2 - E) - pi/3``, ``theta = 2 G / z tan(theta) - H`` (iterated from pi/6),
    ``s_Fn = z sin(pi/3 - theta) + sqrt(3) (G / cos(theta) - rho_fP)``,
    ``rho_F = rho_fP + 2 G^2 / (cos(theta) (z cos^2(theta) - 2 G))``,
    ``h_Fe = [(cos(g_e) - sin(g_e) tan(a_Fen)) d_en - z cos(pi/3 - theta) - G / cos(theta) + rho_fP] / 2``
    with ``a_en = acos(d_b / d_en)``, ``g_e = (pi/2 + 2 x tan(a)) / z + inv(a) - inv(a_en)``,
    ``a_Fen = a_en - g_e``; then ``Y_F = 6 h_Fe cos(a_Fen) / (s_Fn^2 cos(a))``,
    ``Y_S = (1.2 + 0.13 L) q_s^(1 / (1.21 + 2.3 / L))``, ``L = s_Fn / h_Fe``, ``q_s = s_Fn / (2 rho_F)``
    (all lengths in modules).
    """
    z = positive("teeth", teeth)
    a = pressure_angle_rad
    e = math.pi / 4.0 - dedendum * math.tan(a) - (1.0 - math.sin(a)) * root_radius / math.cos(a)
    g = root_radius - dedendum + profile_shift
    h = 2.0 / z * (math.pi / 2.0 - e) - math.pi / 3.0
    theta = math.pi / 6.0
    for _ in range(200):
        new = 2.0 * g / z * math.tan(theta) - h
        if abs(new - theta) < 1e-14:
            theta = new
            break
        theta = new
    else:
        raise ParameterError("teeth", teeth, "a gear whose root section (ISO 6336-3 theta) converges")
    s_fn = z * math.sin(math.pi / 3.0 - theta) + math.sqrt(3.0) * (g / math.cos(theta) - root_radius)
    rho_f = root_radius + 2.0 * g * g / (math.cos(theta) * (z * math.cos(theta) ** 2 - 2.0 * g))
    d_en = 2.0 * load_radius_modules
    d_b = z * math.cos(a)
    if not d_en >= d_b:
        raise ParameterError("load_radius", load_radius_modules, "a load point outside the base circle")
    a_en = math.acos(d_b / d_en)
    g_e = (0.5 * math.pi + 2.0 * profile_shift * math.tan(a)) / z + involute(a) - involute(a_en)
    a_fen = a_en - g_e
    h_fe = 0.5 * ((math.cos(g_e) - math.sin(g_e) * math.tan(a_fen)) * d_en - z * math.cos(math.pi / 3.0 - theta)
                  - g / math.cos(theta) + root_radius)
    y_f = 6.0 * h_fe * math.cos(a_fen) / (s_fn * s_fn * math.cos(a))
    ell = s_fn / h_fe
    q_s = s_fn / (2.0 * rho_f)
    y_s = (1.2 + 0.13 * ell) * q_s ** (1.0 / (1.21 + 2.3 / ell))
    return y_f, y_s


# ------------------------------------------------------------------- the rating
@dataclass(frozen=True)
class GearStress:
    """How one gear of a mesh turns its mesh force into stresses, and its strength.

    Attributes
    ----------
    gear : str
        The gear (body) name.
    role : {"pinion", "wheel"}
    teeth : float
        Signed tooth count (negative: internal).
    contact_per_sqrt_n : float
        sigma_H / sqrt(F) [Pa / sqrt(N)] (every factor in).
    root_per_n : float
        sigma_F / F [Pa / N].
    contact_reference_pa, root_reference_pa : float
        sigma_Hlim Z_L Z_v Z_R Z_W Z_X and sigma_Flim Y_ST Y_deltarelT Y_RrelT Y_X Y_M [Pa]: the strengths
        the life factors multiply.
    contact_curve, bending_curve : LifeFactorCurve
    factors : dict
        The values used (Z_H, Z_E, Z_eps, Z_BD, Y_F, Y_S, Y_M, K_Fbeta, eps_alpha, ...).
    """

    gear: str
    role: str
    teeth: float
    contact_per_sqrt_n: float
    root_per_n: float
    contact_reference_pa: float
    root_reference_pa: float
    contact_curve: LifeFactorCurve
    bending_curve: LifeFactorCurve
    factors: Mapping[str, float] = field(default_factory=dict)

    def contact_stress(self, force_n: np.ndarray | float) -> np.ndarray:
        """sigma_H [Pa] at mesh (normal) forces [N] (their magnitude)."""
        return self.contact_per_sqrt_n * np.sqrt(np.abs(np.asarray(force_n, dtype=float)))

    def root_stress(self, force_n: np.ndarray | float) -> np.ndarray:
        """sigma_F [Pa] at mesh forces [N] (their magnitude)."""
        return self.root_per_n * np.abs(np.asarray(force_n, dtype=float))


def mesh_stresses(geometry: MeshGeometry, names: tuple[str, str], material: GearMaterial, factors: GearFactors,
                  gears: tuple[GearInputs, GearInputs] = (GearInputs(), GearInputs()), idler: tuple[bool, bool] = (False, False),
                  beyond_knee: str = "decline") -> tuple[GearStress, GearStress]:
    """The stress laws of a mesh's pinion and wheel (module docstring).

    Parameters
    ----------
    geometry : MeshGeometry
        Its profile shifts are replaced by those of ``gears``.
    names : (str, str)
        Pinion and wheel names.
    material : GearMaterial
        Of both gears.
    factors : GearFactors
    gears : (GearInputs, GearInputs)
    idler : (bool, bool)
        Whether each gear is an idler (alternating bending: Y_M 0.7 unless given).
    beyond_knee : {"decline", "endurance"}
    """
    geo = replace(geometry, profile_shift_1=gears[0].profile_shift, profile_shift_2=gears[1].profile_shift)
    f = factors
    alpha = geo.pressure_angle_rad
    d1 = 2.0 * geo.reference_radius(1)
    u = geo.ratio
    z_h = f.Z_H if f.Z_H is not None else geo.zone_factor
    z_e = f.Z_E * 1.0e3 if f.Z_E is not None else material.elasticity_factor  # given in sqrt(N/mm^2) = 1e3 sqrt(Pa)
    z_eps = f.Z_eps if f.Z_eps is not None else geo.contact_ratio_factor
    k_h = f.K_A * f.K_v * f.K_Hbeta * f.K_Halpha
    k_fbeta = f.K_Fbeta if f.K_Fbeta is not None else f.K_Hbeta ** geo.face_factor_exponent
    k_falpha = f.K_Falpha if f.K_Falpha is not None else f.K_Halpha
    k_f = f.K_A * f.K_v * k_fbeta * k_falpha
    cos_a = math.cos(alpha)
    # sigma_H0 / sqrt(F): F_t = F cos(alpha)
    h0 = z_h * z_e * z_eps * f.Z_beta * math.sqrt(cos_a / (d1 * geo.face_width_m) * (u + 1.0) / u)
    contact_curve = LifeFactorCurve("Z_NT", material.contact_life).beyond_knee(beyond_knee)
    bending_curve = LifeFactorCurve("Y_NT", material.bending_life).beyond_knee(beyond_knee)
    out = []
    for k, (name, inp, is_idler) in enumerate(zip(names, gears, idler), start=1):
        z_bd = inp.Z_BD if inp.Z_BD is not None else geo.single_contact_factor(k)
        y_f, y_s = geo.root_factors(k) if inp.Y_F is None or inp.Y_S is None else (inp.Y_F, inp.Y_S)
        y_f = inp.Y_F if inp.Y_F is not None else y_f
        y_s = inp.Y_S if inp.Y_S is not None else y_s
        y_m = inp.Y_M if inp.Y_M is not None else (0.7 if is_idler else 1.0)
        contact = z_bd * h0 * math.sqrt(k_h)
        root = cos_a / (geo.face_width_m * geo.module_m) * y_f * y_s * f.Y_beta * inp.Y_B * f.Y_DT * k_f
        contact_ref = material.sigma_hlim_pa * f.Z_L * f.Z_v * f.Z_R * f.Z_W * f.Z_X
        root_ref = material.sigma_flim_pa * material.stress_correction_test_gear * f.Y_deltarelT * f.Y_RrelT * f.Y_X * y_m
        used = {"eps_alpha": geo.contact_ratio, "Z_H": z_h, "Z_E [sqrt(MPa)]": z_e * 1e-3, "Z_eps": z_eps,
                "Z_B" if k == 1 else "Z_D": z_bd, "Y_F": y_f, "Y_S": y_s, "Y_B": inp.Y_B, "Y_M": y_m,
                "K_Hbeta": f.K_Hbeta, "K_Fbeta": k_fbeta, "K_A": f.K_A, "K_v": f.K_v, "K_Halpha": f.K_Halpha,
                "K_Falpha": k_falpha, "x": inp.profile_shift}
        out.append(GearStress(name, "pinion" if k == 1 else "wheel", geo.teeth_1 if k == 1 else geo.teeth_2,
                              contact, root, contact_ref, root_ref, contact_curve, bending_curve, used))
    return out[0], out[1]


@dataclass(frozen=True)
class GearDamage:
    """A gear's rating over a load spectrum in one mesh.

    Attributes
    ----------
    cycles : float
        N_L: its load cycles in the spectrum.
    largest_force_n : float
    sigma_h_max_pa, sigma_f_max_pa : float
        At the largest force.
    contact_damage, bending_damage : float
        Miner sums against Z_NT and Y_NT.
    sigma_h_eq_pa, sigma_f_eq_pa : float or None
        Equivalent stresses (None: no damage, every stress below the endurance).
    force_eq_contact_n, force_eq_bending_n : float or None
        The constant mesh forces of those.
    sigma_hg_static_pa, sigma_hg_life_pa, sigma_fg_static_pa, sigma_fg_life_pa : float
        Strengths at the static point and at N_L.
    safety_contact_life, safety_bending_life : float
        The spectrum's safety factors (:func:`spectrum_safety`): the factor on every stress of the
        spectrum that makes its damage 1 (inf without cycles).
    """

    cycles: float
    largest_force_n: float
    sigma_h_max_pa: float
    sigma_f_max_pa: float
    contact_damage: float
    bending_damage: float
    sigma_h_eq_pa: float | None
    sigma_f_eq_pa: float | None
    force_eq_contact_n: float | None
    force_eq_bending_n: float | None
    sigma_hg_static_pa: float
    sigma_hg_life_pa: float
    sigma_fg_static_pa: float
    sigma_fg_life_pa: float
    safety_contact_life: float = math.inf
    safety_bending_life: float = math.inf

    @property
    def safety_contact_static(self) -> float:
        """S_H at the largest force against the static strength."""
        return self.sigma_hg_static_pa / self.sigma_h_max_pa if self.sigma_h_max_pa > 0 else math.inf

    @property
    def safety_bending_static(self) -> float:
        """S_F at the largest force against the static strength."""
        return self.sigma_fg_static_pa / self.sigma_f_max_pa if self.sigma_f_max_pa > 0 else math.inf



def miner_damage(stress_pa: np.ndarray, cycles: np.ndarray, reference_pa: float, curve: LifeFactorCurve) -> float:
    """``sum n_i / N(sigma_i / sigma_ref)`` [-] (ISO 6336-6)."""
    s = np.asarray(stress_pa, dtype=float)
    n = np.asarray(cycles, dtype=float)
    if s.shape != n.shape:
        raise ParameterError("cycles", n.shape, f"one count per stress ({s.shape})")
    life = curve.cycles_to_failure(s / positive("reference_strength", reference_pa))
    return float(np.sum(np.where(np.isfinite(life), n / np.where(np.isfinite(life), life, 1.0), 0.0)))


def spectrum_safety(stress_pa: np.ndarray, cycles: np.ndarray, reference_pa: float, curve: LifeFactorCurve) -> float:
    """The safety factor of a stress spectrum: the factor ``S`` on every stress with ``D(S sigma_i) = 1``.

    ISO 6336-6's safety factor under a load spectrum (with the stresses as the load); for a
    spectrum on one segment of the curve ``S = D^(-1/k)``, and ``S = 1`` where ``D = 1``. It is
    finite also where every stress is below the endurance limit (``D = 0``). inf without cycles.
    """
    s = np.asarray(stress_pa, dtype=float)
    n = np.asarray(cycles, dtype=float)
    keep = (n > 0) & (s > 0)
    if not keep.any():
        return math.inf
    s, n = s[keep], n[keep]

    def excess(log_factor: float) -> float:
        return miner_damage(s * math.exp(log_factor), n, reference_pa, curve) - 1.0

    lo, hi = -1.0, 1.0
    while excess(lo) > 0.0:
        lo *= 2.0
    while excess(hi) <= 0.0:
        hi *= 2.0
    for _ in range(200):  # bisection in log S: D is monotonic, with jumps at the endurance limit
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0.0:
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-13:
            break
    return math.exp(0.5 * (lo + hi))


def gear_damage(stress: GearStress, forces_n: np.ndarray, cycles: np.ndarray) -> GearDamage:
    """A gear's Miner damage, equivalent stresses and strengths over a spectrum of mesh forces and load cycles."""
    f = np.abs(np.asarray(forces_n, dtype=float))
    n = np.asarray(cycles, dtype=float)
    if f.shape != n.shape or np.any(n < 0) or not np.all(np.isfinite(n)):
        raise ParameterError("cycles", n.shape, f"finite counts >= 0, one per force ({f.shape})")
    occupied = n > 0
    total = float(n.sum())
    f_max = float(f[occupied].max()) if occupied.any() else 0.0
    sh, sf = stress.contact_stress(f), stress.root_stress(f)
    d_h = miner_damage(sh, n, stress.contact_reference_pa, stress.contact_curve)
    d_f = miner_damage(sf, n, stress.root_reference_pa, stress.bending_curve)

    def equivalent(damage: float, reference: float, curve: LifeFactorCurve) -> float | None:
        return reference * curve.strength_at(total / damage) if damage > 0.0 and total > 0.0 else None

    sh_eq = equivalent(d_h, stress.contact_reference_pa, stress.contact_curve)
    sf_eq = equivalent(d_f, stress.root_reference_pa, stress.bending_curve)
    c, b = stress.contact_curve, stress.bending_curve
    return GearDamage(
        total, f_max, float(stress.contact_stress(f_max)), float(stress.root_stress(f_max)), d_h, d_f, sh_eq, sf_eq,
        None if sh_eq is None else (sh_eq / stress.contact_per_sqrt_n) ** 2,
        None if sf_eq is None else sf_eq / stress.root_per_n,
        stress.contact_reference_pa * c.static, stress.contact_reference_pa * c.factor(max(total, 1.0)),
        stress.root_reference_pa * b.static, stress.root_reference_pa * b.factor(max(total, 1.0)),
        spectrum_safety(sh, n, stress.contact_reference_pa, c), spectrum_safety(sf, n, stress.root_reference_pa, b))
