"""ISO 6336 gear rating against hand values: the Table 6 stage-1 sun-planet mesh, form factors, S-N curves, Miner."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.analysis.gear_mesh import MeshGeometry, root_form_factors
from components.analysis.gear_rating import (
    GearFactors,
    GearInputs,
    GearMaterial,
    LifeFactorCurve,
    gear_damage,
    mesh_stresses,
    miner_damage,
    spectrum_safety,
)
from components.errors import ParameterError

ALPHA = math.radians(20.0)
#: Table 6 stage 1: module 10 mm, Z_sun 20, Z_planet 80, Z_ring 180, face width 50 mm, 20 deg
SUN_PLANET = MeshGeometry(20, 80, 0.010, 0.050, ALPHA)
RING_PLANET = MeshGeometry(80, -180, 0.010, 0.050, ALPHA)
#: the stage-1 planet mesh force at the paper's rated point (Table 7's mean, 9.0100e5 N)
F_RATED = 9.0100e5


@pytest.mark.parametrize("teeth, y_fa, y_sa", [(20, 2.80, 1.55), (40, 2.40, 1.67), (100, 2.18, 1.79), (1e5, 2.06, 1.97)])
def test_form_factors_at_the_tip_are_the_published_method_c_values(teeth, y_fa, y_sa):
    # the same equations with the load at the tip give the tabulated Y_Fa, Y_Sa of ISO 6336-3:1996 method C (as
    # gear textbooks reproduce them, two decimals, basic rack 20 deg, x = 0) within 1 %: a slip in any of the
    # method's equations moves them far more
    y_f, y_s = root_form_factors(teeth, 0.0, ALPHA, teeth / 2.0 + 1.0)
    assert y_f == pytest.approx(y_fa, rel=0.01)
    assert y_s == pytest.approx(y_sa, rel=0.01)


def test_table6_stage1_sun_planet_contact_stress_by_hand():
    # r_s = 100, r_bs = 93.969, r_as = 110; r_p = 400, r_bp = 375.877, r_ap = 410; a = 500 mm; p_b = 29.521 mm
    # eps_alpha = (sqrt(110^2 - 93.969^2) + sqrt(410^2 - 375.877^2) - 500 sin 20) / 29.521
    #           = (57.182 + 163.757 - 171.010) / 29.521 = 1.6913
    # Z_H = sqrt(2 / (cos 20 sin 20)) = 2.4946;  Z_E = sqrt(206000 / (2 pi 0.91)) = 189.81 sqrt(MPa)
    # Z_eps = sqrt((4 - 1.6913) / 3) = 0.87725
    # Z_B: rho_C = 34.202, 136.808 mm (r_b tan 20); inner single-contact point of the sun one base pitch in from its tip
    #      contact: rho_B1 = 57.182 - 29.521 = 27.661, rho_B2 = 171.010 - 27.661 = 143.349 mm
    #      Z_B = sqrt(34.202 x 136.808 / (27.661 x 143.349)) = 1.0863;  Z_D = 1 (the planet's M_2 < 1)
    # F_t = 9.01e5 cos 20 = 846 663 N; F_t / (d_1 b) (u + 1) / u = 846663 / (200 x 50) x 5/4 = 105.83 MPa
    # sigma_H0 = 2.4946 x 189.81 x 0.87725 x sqrt(105.83) = 4273.2 MPa
    # sigma_H(sun) = Z_B sigma_H0 sqrt(K_A K_v K_Hbeta K_Halpha) = 1.0863 x 4273.2 x sqrt(1.15) = 4978.0 MPa
    assert SUN_PLANET.contact_ratio == pytest.approx(1.6913, abs=1e-4)
    assert SUN_PLANET.zone_factor == pytest.approx(2.4946, abs=1e-4)
    assert GearMaterial().elasticity_factor / 1e3 == pytest.approx(189.81, abs=0.01)
    assert SUN_PLANET.contact_ratio_factor == pytest.approx(0.87725, abs=1e-5)
    assert SUN_PLANET.single_contact_factor(1) == pytest.approx(1.0863, abs=1e-4)
    assert SUN_PLANET.single_contact_factor(2) == 1.0
    sun, planet = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors())
    assert float(sun.contact_stress(F_RATED)) / 1e6 == pytest.approx(4978.0, rel=2e-5)
    assert float(planet.contact_stress(F_RATED)) / 1e6 == pytest.approx(4978.0 / 1.0863, rel=1e-4)


def test_table6_stage1_sun_root_stress_by_hand():
    # method B (ISO 6336-3), in modules: E = pi/4 - 1.25 tan 20 - (1 - sin 20) 0.38 / cos 20 = 0.064357,
    # G = 0.38 - 1.25 = -0.87, H = 2/20 (pi/2 - E) - pi/3 = -0.89655; theta = 2G/z tan(theta) - H -> 0.80591
    # s_Fn = 20 sin(pi/3 - theta) + sqrt(3) (G / cos(theta) - 0.38) = 1.9447
    # rho_F = 0.38 + 2 G^2 / (cos(theta) (20 cos^2(theta) - 2G)) = 0.57295
    # the load at the outer point of single contact, (eps - 1) p_b in from the tip: d_en = 20.182
    # a_en = acos(20 cos 20 / 20.182) = 21.372 deg, g_e = (pi/2) / 20 + inv 20 - inv a_en = 4.3042 deg, a_Fen = 17.068 deg
    # h_Fe = [(cos g_e - sin g_e tan a_Fen) d_en - 20 cos(pi/3 - theta) - G / cos(theta) + 0.38] / 2 = 0.93777
    # Y_F = 6 h_Fe cos a_Fen / (s_Fn^2 cos 20) = 1.5135;  L = s_Fn / h_Fe = 2.0738, q_s = s_Fn / (2 rho_F) = 1.6971
    # Y_S = (1.2 + 0.13 L) q_s^(1 / (1.21 + 2.3 / L)) = 1.8461
    # K_Fbeta = 1.15^N_F, b/h = 50/22.5 -> 3 (the least), N_F = 9/13: K_Fbeta = 1.1016
    # sigma_F = F_t / (b m) Y_F Y_S K_Fbeta = 846663 / (50 x 10) x 1.5135 x 1.8461 x 1.1016 = 5211.8 MPa
    y_f, y_s = SUN_PLANET.root_factors(1)
    assert (y_f, y_s) == (pytest.approx(1.5135, abs=1e-4), pytest.approx(1.8461, abs=1e-4))
    sun, _ = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors())
    assert sun.factors["K_Fbeta"] == pytest.approx(1.1016, abs=1e-4)
    assert float(sun.root_stress(F_RATED)) / 1e6 == pytest.approx(5211.8, rel=2e-5)


def test_the_paper_gearbox_is_far_beyond_iso_6336_strength():
    # 846 kN on 50 mm of face width: every safety factor at the rated force is below 1 (Table 6 is a dynamic
    # model, not a rated gearbox), which the rating says instead of hiding it
    sun, _ = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors())
    d = gear_damage(sun, np.array([F_RATED]), np.array([1.0e6]))
    assert d.safety_contact_static == pytest.approx(1500 * 1.6 / 4978.0, rel=1e-4) and d.safety_contact_static < 1
    assert d.safety_bending_static == pytest.approx(500 * 2 * 2.5 / 5211.8, rel=1e-4)


def test_the_ring_is_rated_with_its_internal_mesh():
    # internal: eps = (g_a,planet - g_a,ring + a sin 20) / p_b with the ring's tip inside (890 mm), Z_D = 1,
    # (u + 1) / u = (1 - 2.25) / -2.25 = 0.5556
    g = RING_PLANET
    ga1 = math.sqrt(410**2 - (400 * math.cos(ALPHA)) ** 2)
    ga2 = math.sqrt(890**2 - (900 * math.cos(ALPHA)) ** 2)
    assert g.contact_ratio == pytest.approx((ga1 - ga2 + 500 * math.sin(ALPHA)) / (math.pi * 10 * math.cos(ALPHA)))
    planet, ring = mesh_stresses(g, ("planet", "ring"), GearMaterial(), GearFactors())
    assert ring.factors["Z_D"] == 1.0
    h0 = 2.4946 * 189.81e3 * math.sqrt((4 - g.contact_ratio) / 3) * math.sqrt(F_RATED * math.cos(ALPHA) / (0.8 * 0.05)
                                                                               * (1.25 / 2.25))
    assert float(ring.contact_stress(F_RATED)) == pytest.approx(h0 * math.sqrt(1.15), rel=1e-4)
    # the ring's root: the basic rack's factors, loaded one (eps - 1) base pitch in from its tip
    y_f, y_s = g.root_factors(2)
    assert y_f * y_s == pytest.approx(2.45, abs=0.01)


def test_the_planet_is_an_idler_with_alternating_bending():
    _, planet = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors(), idler=(False, True))
    assert planet.factors["Y_M"] == 0.7 and planet.root_reference_pa == pytest.approx(0.7 * 500e6 * 2.0)
    _, given = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors(),
                             (GearInputs(), GearInputs(Y_M=0.8)), idler=(False, True))
    assert given.root_reference_pa == pytest.approx(0.8 * 1000e6)


def test_the_life_factor_curves_are_iso_6336_5s():
    z_nt = LifeFactorCurve("Z_NT", GearMaterial().contact_life)
    assert z_nt.factor(1e4) == 1.6 and z_nt.factor(5e7) == pytest.approx(1.0) and z_nt.factor(1e10) == 0.85
    assert z_nt.factor(1e11) == 0.85
    # log-log straight: k = log(5e7 / 1e5) / log(1.6) = 13.22 (N ~ sigma^-13.2, sigma_H ~ F^1/2: N ~ F^-6.6)
    assert z_nt.slopes()[0] == pytest.approx(math.log(500) / math.log(1.6))
    y_nt = LifeFactorCurve("Y_NT", GearMaterial().bending_life)
    assert y_nt.slopes()[0] == pytest.approx(8.737, abs=1e-3)  # the m = 8.7 of the former illustrative curves
    n = y_nt.cycles_to_failure(np.array([3.0, 2.5, 1.0, 0.9, 0.85, 0.5]))
    assert n[1] == pytest.approx(1e3) and n[2] == pytest.approx(3e6)
    assert n[0] == pytest.approx(1e3 * (2.5 / 3.0) ** y_nt.slopes()[0])  # beyond the static strength: extended
    assert 3e6 < n[3] < 1e10 and math.isinf(n[4]) and math.isinf(n[5])
    flat = y_nt.beyond_knee("endurance")
    assert math.isinf(flat.cycles_to_failure(np.array([0.99]))[0]) and flat.endurance == 1.0
    assert flat.strength_at(1e2) == pytest.approx(2.5 * (1e2 / 1e3) ** (-1 / y_nt.slopes()[0]))


def test_miner_damage_and_the_equivalent_stress_by_hand():
    # two levels on the bending curve: 1e5 cycles at 2x the reference strength, 1e6 at 1.2x
    curve = LifeFactorCurve("Y_NT", GearMaterial().bending_life)
    k = curve.slopes()[0]
    n1, n2 = 1e3 * (2.5 / 2.0) ** k, 1e3 * (2.5 / 1.2) ** k  # cycles to failure
    d = miner_damage(np.array([2.0, 1.2]) * 1e9, np.array([1e5, 1e6]), 1e9, curve)
    assert d == pytest.approx(1e5 / n1 + 1e6 / n2, rel=1e-12)
    # a constant stress at D = 1: its equivalent is itself, S_life = 1
    sun, _ = mesh_stresses(SUN_PLANET, ("sun", "planet"), GearMaterial(), GearFactors())
    f = 2.0e5
    n_fail = float(sun.bending_curve.cycles_to_failure(np.array([float(sun.root_stress(f)) / sun.root_reference_pa]))[0])
    dmg = gear_damage(sun, np.array([f]), np.array([n_fail]))
    assert dmg.bending_damage == pytest.approx(1.0, rel=1e-12)
    assert dmg.force_eq_bending_n == pytest.approx(f, rel=1e-9) and dmg.safety_bending_life == pytest.approx(1.0, rel=1e-9)
    # a tenth of those cycles on the same segment: D = 0.1, and the stress factor to D = 1 is 0.1^(-1/k)
    tenth = gear_damage(sun, np.array([f]), np.array([0.1 * n_fail]))
    k = sun.bending_curve.slopes()[1] if n_fail > 3e6 else sun.bending_curve.slopes()[0]
    assert tenth.bending_damage == pytest.approx(0.1, rel=1e-12)
    assert tenth.safety_bending_life == pytest.approx(0.1 ** (-1.0 / k), rel=1e-9)


def test_the_spectrum_safety_factor_is_finite_below_the_endurance_limit():
    # every stress below the endurance limit (0.85 at 1e10): D = 0, and S is the factor that lifts the
    # largest stress to where its cycles do damage 1 (here to the limit itself: 1e10 cycles there)
    curve = LifeFactorCurve("Y_NT", GearMaterial().bending_life)
    s = spectrum_safety(np.array([0.5, 0.4]), np.array([2e10, 1e9]), 1.0, curve)
    assert miner_damage(np.array([0.5, 0.4]), np.array([2e10, 1e9]), 1.0, curve) == 0.0
    assert s == pytest.approx(0.85 / 0.5, rel=1e-9)


@pytest.mark.parametrize("kwargs, match", [
    (dict(teeth_1=20, teeth_2=-15, module_m=0.01, face_width_m=0.05, pressure_angle_rad=ALPHA), "teeth_2"),
    (dict(teeth_1=20, teeth_2=40, module_m=0.01, face_width_m=0.05, pressure_angle_rad=math.radians(50)),
     "pressure_angle"),
])
def test_a_mesh_that_cannot_be_rated_is_refused(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        MeshGeometry(**kwargs)


def test_an_unknown_factor_is_refused():
    with pytest.raises(ParameterError, match="K_Hbeta"):
        GearFactors().updated(K_Hbeat=1.2)
