"""GeneratorRotor with a counter torque from an input and a high-speed-shaft brake."""

from __future__ import annotations

import pytest

from components.model.generator import GeneratorParameters, GeneratorRotor


def test_counter_torque_input_replaces_the_schedule():
    g = GeneratorRotor(GeneratorParameters(inertia_kgm2=500.0, counter_torque_nm=40000.0), 120.0)
    g.step(0.0, 0.01, 45000.0, counter_torque_nm=43000.0)
    assert g.speed_rad_s == pytest.approx(120.0 + 2000.0 * 0.01 / 500.0, rel=1e-15)


def test_brake_stops_the_rotor_and_holds_it():
    g = GeneratorRotor(GeneratorParameters(inertia_kgm2=500.0, counter_torque_nm=0.0), 1.0)
    g.step(0.0, 0.1, 0.0, counter_torque_nm=0.0, brake_torque_nm=10000.0)  # -20 rad/s^2: stops after 0.05 s
    assert g.speed_rad_s == 0.0
    assert g.angle_rad == pytest.approx(1.0 * 0.05 - 0.5 * 20.0 * 0.05 ** 2)
    g.step(0.1, 0.1, 5000.0, counter_torque_nm=0.0, brake_torque_nm=10000.0)  # the brake holds 5 kN m
    assert g.speed_rad_s == 0.0


def test_brake_slips_under_a_larger_torque():
    g = GeneratorRotor(GeneratorParameters(inertia_kgm2=500.0, counter_torque_nm=0.0), 0.0)
    g.step(0.0, 0.1, 15000.0, counter_torque_nm=0.0, brake_torque_nm=10000.0)
    assert g.speed_rad_s == pytest.approx(5000.0 / 500.0 * 0.1)
