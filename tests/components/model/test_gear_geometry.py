"""Gear geometry, the checks of a planetary stage and the design table, against hand-computed values."""

from __future__ import annotations

import math

import pytest

from components.errors import ParameterError
from components.model.design_table import design_table
from components.model.gear_geometry import (
    assembly_check,
    clearance_check,
    disc_body,
    planet_clearance_m,
    ring_teeth_check,
)
from components.model.parameter_map import flatten, unflatten
from components.model.presets import table6_gearbox, with_stage
from components.model.stages import PlanetaryStage


def test_disc_bodies_by_hand():
    solid = disc_body(0.1, 0.05, 7800.0)
    assert solid.mass_kg == pytest.approx(12.2522, rel=1e-5)  # Table 6's sun: 12.25 kg
    assert solid.inertia_kgm2 == pytest.approx(0.5 * 12.2522 * 0.01, rel=1e-5)  # 6.12e4 kg mm^2
    bored = disc_body(0.2, 0.1, 7800.0, 0.05)
    m = 7800.0 * math.pi * (0.04 - 0.0025) * 0.1
    assert bored.mass_kg == pytest.approx(m) and bored.inertia_kgm2 == pytest.approx(0.5 * m * 0.0425)
    with pytest.raises(ParameterError, match="bore_diameter"):
        disc_body(0.1, 0.05, 7800.0, 0.1)


def test_planetary_checks():
    assert ring_teeth_check(21, 39, 99).passed and not ring_teeth_check(21, 39, 100).passed
    assert assembly_check(21, 99, 3).passed and not assembly_check(20, 180, 3).passed
    assert assembly_check(20, 100, 4).passed
    # unequal spacing: (Z_s + Z_r) psi / 2 pi whole for every planet
    assert assembly_check(24, 72, 4, [0.0, math.radians(86.25), math.pi, math.radians(266.25)]).passed
    assert not assembly_check(24, 72, 4, [0.0, math.radians(87.0), math.pi, math.radians(266.25)]).passed


def test_planet_clearance_by_hand():
    # Table 6 stage 1 with 4 planets: centres 2 x 0.5 m x sin 45 deg apart, tip diameter 2 (0.4 + 0.01) m
    gap = planet_clearance_m(0.1, 0.4, 0.01, [0.0, math.pi / 2, math.pi, 1.5 * math.pi])
    assert gap == pytest.approx(2 * 0.5 * math.sin(math.pi / 4) - 0.82)
    assert gap < 0 and not clearance_check(0.1, 0.4, 0.01, [0.0, math.pi / 2, math.pi, 1.5 * math.pi]).passed
    assert clearance_check(0.1, 0.4, 0.01, [0.0, 2 * math.pi / 3, 4 * math.pi / 3]).passed
    assert planet_clearance_m(0.1, 0.4, 0.01, [0.0]) == math.inf


def test_design_table_of_table6_by_hand():
    dt = table6_gearbox()
    table = design_table(dt, 16 * 2 * math.pi / 60)
    t_rotor = 25400.0 * 100.0
    assert table.input_torque_nm == pytest.approx(t_rotor) and table.ratio == pytest.approx(100.0)
    s1, s2, s3 = table.stages
    cos20 = math.cos(math.radians(20.0))
    assert s1.meshes[0].static_force_n == pytest.approx(t_rotor / 10 / (3 * 0.1 * cos20), rel=1e-12)
    assert s1.meshes[1].static_force_n == pytest.approx(s1.meshes[0].static_force_n, rel=1e-12)
    assert s2.meshes[0].static_force_n == pytest.approx(t_rotor / 80 / (3 * 0.1 * cos20), rel=1e-12)
    assert s3.meshes[0].static_force_n == pytest.approx(t_rotor / 80 / (0.1 * cos20), rel=1e-12)
    assert s1.centre_distance_m == pytest.approx(0.5) and s3.centre_distance_m == pytest.approx(0.18)
    # mesh frequencies: Z_ring x carrier speed (ring fixed), Z_drive x drive speed
    assert s1.mesh_frequency_hz == pytest.approx(180 * 16 / 60)
    assert s2.mesh_frequency_hz == pytest.approx(140 * 160 / 60)
    assert s3.mesh_frequency_hz == pytest.approx(20 * 1280 / 60)
    assert table.generator["speed_rad_s"] == pytest.approx(1600 * 2 * math.pi / 60)


def test_planet_angles_are_validated_and_kept_out_of_the_flat_parameters():
    dt = table6_gearbox()
    angled = with_stage(dt, 0, planet_angles_rad=(0.0, 2.0, 4.0))
    assert angled.stages[0].planet_positions_rad == (0.0, 2.0, 4.0)
    assert set(flatten(angled)) == set(flatten(dt))
    assert unflatten(angled, {"stage1.k0": 2e10}).stages[0].planet_angles_rad == (0.0, 2.0, 4.0)
    with pytest.raises(ParameterError, match="stage1.planet_angles_rad"):
        with_stage(dt, 0, planet_angles_rad=(0.0, 2.0))
    with pytest.raises(ParameterError, match="strictly increasing"):
        with_stage(dt, 0, planet_angles_rad=(0.0, 4.0, 2.0))
    assert dt.stages[0].planet_positions_rad == pytest.approx((0.0, 2 * math.pi / 3, 4 * math.pi / 3))


def test_separate_sun_and_ring_meshes_have_their_own_flat_names():
    from dataclasses import replace

    dt = table6_gearbox()
    st = dt.stages[0]
    split = with_stage(dt, 0, ring_mesh=replace(st.ring_mesh, stiffness=2 * st.ring_mesh.stiffness))
    names = flatten(split)
    assert "stage1.k0" not in names and names["stage1.ring_mesh.k0"] == 2 * names["stage1.sun_mesh.k0"]
    assert "stage2.k0" in names  # an unchanged stage keeps the presets' shared names
    back = unflatten(split, {"stage1.sun_mesh.c0": 1.0e9})
    assert back.stages[0].sun_mesh.damping == 1.0e9 and back.stages[0].ring_mesh.damping == st.ring_mesh.damping
    assert unflatten(split, flatten(split)) == split
    assert isinstance(back.stages[0], PlanetaryStage)


def test_planet_angles_travel_in_the_fmu_record_description():
    from components.model.description import build, describe

    dt = with_stage(table6_gearbox(), 0, planet_angles_rad=(0.0, 2.0, 4.0))
    data = describe(dt)
    assert data["stages"][0]["planet_angles_rad"] == [0.0, 2.0, 4.0]
    assert build(data) == dt
    assert build(describe(table6_gearbox())) == table6_gearbox()  # None: equally spaced
