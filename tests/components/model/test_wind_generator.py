"""Rotor-speed process (eq. 13-14) and generator rotor."""

import numpy as np
import pytest

from components import units
from components.model.generator import (
    GeneratorParameters,
    GeneratorRotor,
    LoadEvent,
    TorqueSchedule,
)
from components.model.wind import RotorSpeedProcess, WindParameters


def test_paper_defaults_in_si():
    p = WindParameters.from_paper()
    assert p.mean_speed_rad_s == pytest.approx(16 * 2 * np.pi / 60)
    assert p.sigma_rad_s == pytest.approx(0.12 * 2 * np.pi / 60)
    assert p.decay_s_per_rad == pytest.approx(0.02 / 0.12**2)  # a / sigma^2 is unit-invariant
    assert WindParameters() == p


def test_seeded_and_reproducible():
    a = RotorSpeedProcess(WindParameters(seed=7))
    b = RotorSpeedProcess(WindParameters(seed=7))
    c = RotorSpeedProcess(WindParameters(seed=8))
    t = np.linspace(0, 60, 101)
    np.testing.assert_array_equal(a.speed(t), b.speed(t))
    assert np.abs(a.speed(t) - c.speed(t)).max() > 1e-4


def test_variance_preserving_amplitude_gives_sigma():
    proc = RotorSpeedProcess(WindParameters())
    p = proc.params
    expected = p.sigma_rad_s**2 * (1 - np.exp(-p.decay_s_per_rad * p.f_max_rad_s))  # integral of S over [0, f_max]
    assert 0.5 * np.sum(proc.amplitudes_rad_s**2) == pytest.approx(expected, rel=1e-4)
    t = np.linspace(0.0, 2000.0, 400_001)
    assert proc.speed(t).std() == pytest.approx(np.sqrt(expected), rel=0.1)


def test_paper_literal_amplitude_is_tiny():
    lit = RotorSpeedProcess(WindParameters(amplitude="paper"))
    std_rpm = units.rad_per_s_to_rpm(np.sqrt(0.5 * np.sum(lit.amplitudes_rad_s**2)))
    assert 1e-4 < std_rpm < 1e-2  # ~0.001 rpm, about 100 x below sigma = 0.12 rpm


def test_angle_and_acceleration_are_consistent_with_speed():
    proc = RotorSpeedProcess(WindParameters(n_harmonics=64))
    t = np.linspace(0.0, 30.0, 30_001)
    w = proc.speed(t)
    phi = proc.angle(t)
    assert proc.angle(0.0) == pytest.approx(0.0, abs=1e-14)
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    np.testing.assert_allclose(phi, integral, atol=1e-8)
    np.testing.assert_allclose(proc.acceleration(t[1:-1]), (w[2:] - w[:-2]) / (t[2:] - t[:-2]), atol=1e-6)
    assert proc.speed(1.234) == pytest.approx(proc.speed(np.array([1.234]))[0])


def test_generator_exact_for_constant_torques():
    gen = GeneratorRotor(GeneratorParameters(inertia_kgm2=2.0, counter_torque_nm=10.0), initial_speed_rad_s=5.0)
    for k in range(10):
        gen.step(0.1 * k, 0.1, shaft_torque_nm=16.0)
    assert gen.speed_rad_s == pytest.approx(5.0 + 3.0 * 1.0)  # (16 - 10) / 2 rad/s^2 for 1 s
    assert gen.angle_rad == pytest.approx(5.0 + 0.5 * 3.0)


def test_events_schedule():
    base = 100.0
    sched = TorqueSchedule.from_events(
        base,
        (
            LoadEvent("torque_step", 1.0, factor=1.5),
            LoadEvent("grid_fault", 2.0, 0.5),
            LoadEvent("emergency_stop", 4.0, 1.0, factor=0.8),
        ),
    )
    assert sched(0.5) == base and sched(1.5) == 150.0
    assert sched(2.2) == 0.0 and sched(3.0) == 150.0
    assert sched(4.5) == -80.0 and sched(6.0) == 150.0
    impulse, moment = sched.integrals(1.8, 2.6)
    assert impulse == pytest.approx(150.0 * 0.2 + 0.0 * 0.5 + 150.0 * 0.1)
    assert moment == pytest.approx(150.0 * 0.5 * (0.8**2 - 0.6**2) + 150.0 * 0.5 * 0.1**2)


def test_generator_integrates_through_an_event_exactly():
    params = GeneratorParameters(inertia_kgm2=1.0, counter_torque_nm=10.0, events=(LoadEvent("grid_fault", 0.25, 0.5),))
    gen = GeneratorRotor(params, initial_speed_rad_s=0.0)
    gen.step(0.0, 1.0, shaft_torque_nm=10.0)  # net torque 10 only during the fault
    assert gen.speed_rad_s == pytest.approx(5.0)
    assert gen.angle_rad == pytest.approx(10.0 * 0.5 * (0.75**2 - 0.25**2))
