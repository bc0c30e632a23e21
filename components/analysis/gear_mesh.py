"""Spur-gear mesh geometry for ISO 6336: contact ratio, zone and single-contact factors, method B form factors, stiffness.

SI (lengths in m), spur gears (helix angle 0) cut by the basic rack of ISO 53 profile A (addendum
1 m, dedendum 1.25 m, root radius 0.38 m), profile shifts ``x``. A mesh is a pinion (``teeth_1 >
0``, the gear of fewer teeth) and a wheel (``teeth_2 < 0`` for an internal gear, the ring).
The rating that uses these is :mod:`components.analysis.gear_rating` (formulas there).

* contact ratio ``eps_alpha = [g_a1 + s g_a2 - s a_w sin(alpha_w)] / p_b`` (``g_a = sqrt(r_a^2 -
  r_b^2)``, ``s = +1`` external, ``-1`` internal), working pressure angle ``inv(alpha_w) = inv(alpha)
  + 2 tan(alpha) (x_1 + x_2) / (z_1 + z_2)``;
* ``Z_H = sqrt(2 cos(alpha_w) / (cos^2(alpha) sin(alpha_w)))``, ``Z_eps = sqrt((4 - eps_alpha) / 3)``;
* ``Z_B``, ``Z_D``: ``sqrt(rho_C1 rho_C2 / (rho_1 rho_2))`` of the flank curvature radii at the pitch
  point and at the gear's inner point of single pair contact (one base pitch in from its tip
  contact), at least 1; an internal wheel has ``Z_D = 1`` (ISO 6336-2);
* ``Y_F``, ``Y_S`` by ISO 6336-3 method B (:func:`root_form_factors`); an internal gear gets the
  basic rack's (the rack limit of the external equations, a stated simplification, see
  :mod:`components.analysis.gear_rating`);
* the tooth stiffness of ISO 6336-1 method B (:meth:`MeshGeometry.single_stiffness`,
  :meth:`MeshGeometry.mesh_stiffness`): the theoretical single stiffness ``c'_th = 1 / q'`` of a solid
  steel pair, ``q' = C1 + C2 / z_1 + C3 / z_2 + C4 x_1 + C5 x_1 / z_1 + C6 x_2 + C7 x_2 / z_2 + C8 x_1^2
  + C9 x_2^2`` [mm um / N] (an internal wheel counts as ``z_2 = infinity``), the single stiffness ``c' =
  c'_th C_M C_R C_B`` (spur: ``cos(beta) = 1``; ``C_M = 0.8``; ``C_R = 1``, a solid blank; ``C_B = (1 +
  0.5 (1.2 - h_fP / m)) (1 - 0.02 (20 deg - alpha))`` of the basic rack), times ``(w / 100 N/mm)^0.25``
  below a line load ``w`` of 100 N/mm, and the mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha +
  0.25)``; all per unit face width [N/m^2 in SI; 1 N/(mm um) = 1e9 N/m^2].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError
from ..validation import finite, in_range, positive

#: ISO 53 profile A basic rack, in modules: addendum of the gear, dedendum (cutter addendum), root radius
RACK_ADDENDUM, RACK_DEDENDUM, RACK_ROOT_RADIUS = 1.0, 1.25, 0.38
#: the smallest b/h in K_Fbeta's exponent N_F (ISO 6336-1)
MIN_WIDTH_TO_HEIGHT = 3.0
#: tooth count standing for the rack in the external gear's root equations (Y_F Y_S converged to 1e-4 from 1e4 on)
RACK_TEETH = 1.0e5
#: C1 ... C9 of ISO 6336-1 method B's q' of a solid spur pair [mm um / N]
SINGLE_STIFFNESS_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
#: C_M of ISO 6336-1: the measured single stiffness of solid gears over the theoretical one
STIFFNESS_CORRECTION = 0.8
#: the line load [N/m] (100 N/mm) below which ISO 6336-1 reduces c' by (w / 100 N/mm)^0.25
STIFFNESS_FULL_LINE_LOAD = 1.0e5
#: N/(mm um) in SI [N/m^2]
N_PER_MM_UM = 1.0e9


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

    @property
    def theoretical_single_stiffness(self) -> float:
        """c'_th = 1 / q' of ISO 6336-1 method B [N/m^2] (an internal wheel: z_2 = infinity)."""
        c1, c2, c3, c4, c5, c6, c7, c8, c9 = SINGLE_STIFFNESS_COEFFICIENTS
        z1, x1, x2 = self.teeth_1, self.profile_shift_1, self.profile_shift_2
        inv_z2 = 0.0 if self.internal else 1.0 / self.teeth_2
        q = c1 + c2 / z1 + c3 * inv_z2 + c4 * x1 + c5 * x1 / z1 + c6 * x2 + c7 * x2 * inv_z2 + c8 * x1 * x1 \
            + c9 * x2 * x2
        return N_PER_MM_UM / q

    def single_stiffness(self, line_load_n_per_m: float = STIFFNESS_FULL_LINE_LOAD) -> float:
        """c' = c'_th C_M C_R C_B [N/m^2] of a solid blank (C_R = 1), reduced below 100 N/mm (module docstring)."""
        rack = (1.0 + 0.5 * (1.2 - RACK_DEDENDUM)) * (1.0 - 0.02 * (20.0 - math.degrees(self.pressure_angle_rad)))
        load = min(1.0, max(line_load_n_per_m, 0.0) / STIFFNESS_FULL_LINE_LOAD) ** 0.25
        return self.theoretical_single_stiffness * STIFFNESS_CORRECTION * rack * load

    def mesh_stiffness(self, line_load_n_per_m: float = STIFFNESS_FULL_LINE_LOAD) -> float:
        """c_gamma_alpha = c' (0.75 eps_alpha + 0.25) [N/m^2]: the mean stiffness of the mesh per face width."""
        return self.single_stiffness(line_load_n_per_m) * (0.75 * self.contact_ratio + 0.25)

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
