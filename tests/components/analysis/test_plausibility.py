"""Plausibility by physics: ISO 6336-1 tooth stiffness and every rule's bound against hand values (issue 30.2)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from components import units
from components.analysis.gear_mesh import MeshGeometry
from components.analysis.plausibility import Rating, implausible, judge, judge_operation
from components.model.presets import sensitivity_variant, table6_gearbox, with_stage

ALPHA = math.radians(20.0)
TABLE6 = table6_gearbox()
#: the paper's rated point: 16 rpm, 25.4 kN m on the generator
RATED = Rating(units.rpm(16.0), 25.4e3)


def test_iso_6336_1_stiffness_of_the_table6_stage1_meshes_by_hand():
    # q' = 0.04723 + 0.15551 / 20 + 0.25791 / 80 = 0.05822938 mm um/N -> c'_th = 17.1735 N/(mm um)
    # c' = c'_th C_M C_B = 17.1735 x 0.8 x [1 + 0.5 (1.2 - 1.25)] [1 - 0.02 (20 - 20)] = 17.1735 x 0.8 x 0.975 = 13.3953
    # c_gamma_alpha = c' (0.75 eps_alpha + 0.25) = 13.3953 x (0.75 x 1.6913 + 0.25) = 20.340
    sun_planet = MeshGeometry(20, 80, 0.010, 0.050, ALPHA)
    assert sun_planet.theoretical_single_stiffness / 1e9 == pytest.approx(17.1735, abs=1e-4)
    assert sun_planet.single_stiffness() / 1e9 == pytest.approx(13.3953, abs=1e-4)
    assert sun_planet.mesh_stiffness() / 1e9 == pytest.approx(20.340, abs=1e-3)
    # ISO 6336-1's average values of solid steel spur gears (method C): c' = 14, c_gamma = 20 N/(mm um)
    assert sun_planet.single_stiffness() / 1e9 == pytest.approx(14.0, rel=0.1)
    assert sun_planet.mesh_stiffness() / 1e9 == pytest.approx(20.0, rel=0.1)
    # an internal wheel counts as z_2 = infinity: q' = 0.04723 + 0.15551 / 80 -> c'_th = 20.3361
    assert MeshGeometry(80, -180, 0.010, 0.050, ALPHA).theoretical_single_stiffness / 1e9 == pytest.approx(20.3361,
                                                                                                         abs=1e-4)
    # below 100 N/mm: c' x (w / 100)^0.25 -> 13.3953 x 0.5^0.25 = 11.2641 at 50 N/mm
    assert sun_planet.single_stiffness(5.0e4) / 1e9 == pytest.approx(11.2641, abs=1e-4)
    # a 25 deg rack: C_B = 0.975 x [1 - 0.02 (20 - 25)] = 1.0725
    wide = MeshGeometry(20, 80, 0.010, 0.050, math.radians(25.0))
    assert wide.single_stiffness() / wide.theoretical_single_stiffness == pytest.approx(0.8 * 1.0725, rel=1e-12)


def test_every_table6_value_is_plausible_but_the_stage2_ones_the_paper_prints():
    failed = {j.key for j in implausible(judge(TABLE6, RATED))}
    # stage 2's 5 mm face width: half a module; its sun is a 50 mm disc; its mesh 3.1 x stiffer per mm than ISO's
    assert failed == {"stage2.width", "stage2.sun_mass", "stage2.sun_inertia", "stage2.k0"}


def _stage1(**changes):
    return with_stage(TABLE6, 0, **changes)


def _mesh(**changes):
    st = TABLE6.stages[0]
    return _stage1(sun_mesh=replace(st.sun_mesh, **changes), ring_mesh=replace(st.ring_mesh, **changes))


#: (what, drivetrain, judged key, value, low, high) - bounds by hand for Table 6 stage 1 (module 10 mm, 20 deg,
#: sun r = 100 mm, planet 400 mm, ring 900 mm, width 50 mm)
CASES = [
    # 0.1 pi m cos(alpha) = 0.1 x pi x 10 mm x cos 20 = 2.9521 mm: the 0.3 m (meant in mm)
    ("backlash of 0.3 m", _mesh(backlash_normal_m=0.3), "stage1.backlash", 0.3, 0.0, 2.9521e-3),
    # teeth between 8 and 1000: m >= 2 x 900 mm / 1000 = 1.8 mm and m <= 2 x 100 mm / 8 = 25 mm
    ("module of 1 mm (200 sun teeth, 1800 ring teeth)", _stage1(module_m=0.001), "stage1.module", 0.001, 1.8e-3, 0.025),
    ("module of 30 mm (6.7 sun teeth)", _stage1(module_m=0.03), "stage1.module", 0.03, 1.8e-3, 0.025),
    # at least 2.25 m = 22.5 mm, at most 2 x the sun's 200 mm
    ("face width of 5 mm", _stage1(width_m=0.005, sun_mass_kg=1.225, sun_inertia_kgm2=0.006125,
                                   planet_mass_kg=19.6, planet_inertia_kgm2=1.568), "stage1.width", 0.005, 0.0225, 0.4),
    # sun disc 7800 pi 0.1^2 0.05 = 12.252 kg: 0.1 to 5 discs
    ("sun of 12.25 t (kg read as g)", _stage1(sun_mass_kg=12250.0), "stage1.sun_mass", 12250.0, 1.2252, 61.261),
    # planet disc J = 0.5 x 196.04 x 0.4^2 = 15.683 kg m^2; and m r_a^2 = 196.06 x 0.41^2 = 32.958
    ("planet inertia in kg mm^2 read as kg m^2", _stage1(planet_inertia_kgm2=1.56e7), "stage1.planet_inertia",
     1.56e7, 1.5683, 32.958),
    # ring disc J = 0.5 x 7800 pi 0.9^2 0.05 x 0.9^2 = 401.91 kg m^2: an extra carrier inertia of at most 5 discs
    ("carrier inertia in kg mm^2", _stage1(carrier_inertia_kgm2=1.0e6), "stage1.carrier_inertia", 1.0e6, 0.0, 2009.6),
]


@pytest.mark.parametrize("what, drivetrain, key, value, low, high", CASES, ids=[c[0] for c in CASES])
def test_an_implausible_value_fails_its_rule_with_the_bound_by_hand(what, drivetrain, key, value, low, high):
    failed = [j for j in implausible(judge(drivetrain, RATED)) if j.key == key]
    assert failed, what
    j = failed[0]
    assert j.value == pytest.approx(value) and j.low == pytest.approx(low, rel=1e-4, abs=1e-12)
    assert j.high == pytest.approx(high, rel=1e-4)
    assert j.expected.startswith(f"a plausible value within [{low:.4g}, {high:.4g}]") and j.reason in j.expected


def test_a_radius_of_gyration_beyond_the_tip_is_implausible():
    # Sec. 4.1 at R1 = 6 keeps Table 6's 196.06 kg, 15.6 kg m^2 planet, now of pitch radius 200 mm: J <= m r_a^2 =
    # 196.06 x 0.21^2 = 8.6462 kg m^2 (the disc's 5 x 0.5 x 7800 pi 0.2^3 0.05 x 0.2^2 = 4.9009 is lower: it binds)
    [j] = [j for j in implausible(judge(sensitivity_variant(6.0, 600.0), Rating(units.rpm(5.0), 1000.0)))
           if j.key == "stage1.planet_inertia"]
    assert j.high == pytest.approx(4.9009, rel=1e-4) and "m r_a^2 = 8.646 kg m^2" in j.reason


def test_a_linear_mesh_stiffness_is_judged_per_face_width_against_iso():
    # e = 1: k0 is the stiffness [N/m]; ISO c_gamma_alpha of the 20/80 mesh 20.340 N/(mm um) x 50 mm = 1.0170e9 N/m,
    # within a factor 3 either way
    low, high = 20.340e9 * 0.05 / 3.0, 3.0 * 20.340e9 * 0.05
    ok = [j for j in judge(_mesh(exponent=1.0, stiffness=1.0e9), RATED) if j.rule == "mesh_stiffness"]
    assert ok[0].low == pytest.approx(low, rel=1e-4) and ok[0].high == pytest.approx(high, rel=1e-4) and ok[0].passed
    soft = implausible(judge(_mesh(exponent=1.0, stiffness=1.0e6), RATED))  # N/mm read as N/m
    assert [j.key for j in soft if j.key.startswith("stage1")] == ["stage1.k0", "stage1.k0"]  # sun- and ring-planet


def test_a_hertzian_mesh_is_judged_by_its_secant_at_the_rated_force():
    # Table 6 stage 1: F = 9.0100e5 N per planet; k0 = 5e5 N/mm^1.5 = 1.5811e10 N/m^1.5 deflects (F / k0)^(2/3)
    # = 1.4806 mm, c = F / (d b) = 12.171 N/(mm um); the sun-planet bound on k0: (c_iso b / 3)^1.5 / F^0.5
    j = judge(TABLE6, RATED)
    sun_planet = next(x for x in j if x.rule == "mesh_stiffness")
    f, b, c_iso = 9.0100e5, 0.05, 20.340e9
    assert sun_planet.low == pytest.approx((c_iso * b / 3.0) ** 1.5 / f**0.5, rel=2e-3)
    assert "12.2 N/(mm um)" in sun_planet.reason and sun_planet.passed


def test_without_a_rated_load_a_hertzian_mesh_is_not_judged():
    assert not [j for j in judge(TABLE6, Rating(RATED.rotor_speed_rad_s, 0.0)) if j.rule == "mesh_stiffness"]


@pytest.mark.parametrize("speeds, torques, factors, key", [
    ({"wind.omega0": units.rpm(25.0)}, {}, {}, "wind.omega0"),           # 1.5 x 16 rpm = 24 rpm
    ({}, {"generator.counter_torque": -80e3}, {}, "generator.counter_torque"),   # 3 x 25.4 = 76.2 kN m
    ({}, {}, {"generator.event1.factor": (3.5, 25.4e3)}, "generator.event1.factor"),
])
def test_speeds_and_torques_beyond_the_rating_are_implausible(speeds, torques, factors, key):
    assert [j.key for j in implausible(judge_operation(RATED, speeds, torques, factors))] == [key]
    ok = judge_operation(RATED, {"w": units.rpm(23.9)}, {"t": -76.1e3}, {"f": (2.9, 25.4e3)})
    assert all(j.passed for j in ok) and len(ok) == 3


def test_allowed_and_inherited_failures_are_not_reported():
    changed = _stage1(width_m=0.004)
    found = judge(changed, RATED)
    base = judge(TABLE6, RATED)
    # a 4 mm face: narrower than a tooth is high, the 50 mm bodies too heavy for it, the mesh too stiff per mm
    introduced = {"stage1.width", "stage1.sun_mass", "stage1.sun_inertia", "stage1.planet_mass",
                  "stage1.planet_inertia", "stage1.k0"}
    assert {j.key for j in implausible(found, base=base, given=())} == introduced
    assert not implausible(found, allow=sorted(introduced), base=base)
    # Table 6's own stage-2 failures are inherited unless the stage-2 value is given
    stage2 = with_stage(TABLE6, 1, width_m=0.006)
    assert {j.key for j in implausible(judge(stage2, RATED), base=base, given=())} == set()
    assert {j.key for j in implausible(judge(stage2, RATED), base=base, given=["stage2.width"])} == {"stage2.width"}
