"""The torque-driven rotor: exact rigid steps, the main shaft's static twist and momentum."""

from __future__ import annotations

import pytest

from components.errors import ParameterError
from components.model.rotor import Rotor, RotorParameters


def test_rigid_rotor_step_is_exact():
    r = Rotor(RotorParameters(inertia_kgm2=4.0e7), 1.2, 0.5)
    r.step(0.01, 4.0e6, 3.6e6)  # net 4e5 N m -> 0.01 rad/s^2
    assert r.speed_rad_s == pytest.approx(1.2 + 0.01 * 0.01, rel=1e-15)
    assert r.angle_rad == pytest.approx(0.5 + 1.2 * 0.01 + 0.5 * 0.01 * 1e-4, rel=1e-15)


def test_main_shaft_keeps_momentum_and_its_initial_twist_carries_the_torque():
    p = RotorParameters(inertia_kgm2=4.0e7, shaft_stiffness_nm_rad=8.7e8, shaft_damping_nms_rad=6.2e6,
                        carrier_inertia_kgm2=5.0e6)
    r = Rotor(p, 1.2, 0.0, initial_shaft_torque_nm=4.0e6)
    assert r.shaft_torque_nm == pytest.approx(4.0e6)
    for _ in range(200):  # balanced: T_aero = T_gearbox = shaft torque -> steady
        r.step(0.005, 4.0e6, 4.0e6)
    assert r.rotor_speed_rad_s == pytest.approx(1.2, rel=1e-9)
    assert r.speed_rad_s == pytest.approx(1.2, rel=1e-9)
    assert r.shaft_torque_nm == pytest.approx(4.0e6, rel=1e-9)
    r.step(1.0, 5.0e6, 4.0e6)  # net 1e6 N m for 1 s on both inertias: total momentum exact
    momentum = p.inertia_kgm2 * r.rotor_speed_rad_s + p.carrier_inertia_kgm2 * r.speed_rad_s
    assert momentum == pytest.approx((4.0e7 + 5.0e6) * 1.2 + 1.0e6, rel=1e-10)


def test_a_shaft_needs_a_carrier_inertia():
    with pytest.raises(ParameterError, match="carrier_inertia"):
        RotorParameters(shaft_stiffness_nm_rad=1e8)
