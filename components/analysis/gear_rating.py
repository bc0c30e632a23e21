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
(:func:`components.analysis.gear_mesh.root_form_factors`: the critical section where the fillet's tangent makes 30 deg
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
from ..validation import in_range, positive
from .gear_mesh import MeshGeometry

#: what the life factor does beyond its knee (module docstring)
BEYOND_KNEE = ("decline", "endurance")

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
