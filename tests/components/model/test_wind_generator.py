"""Rotor-speed process (eq. 13-14) and generator rotor."""

import numpy as np
import pytest

from components import units
from components.errors import ParameterError
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
    a = proc.acceleration(t)
    np.testing.assert_allclose(proc.jerk(t[1:-1]), (a[2:] - a[:-2]) / (t[2:] - t[:-2]), atol=1e-5)
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


def _wind_kernels() -> list:
    """Both forms of the phasor step; the compiled one skipped where it cannot load."""
    from components.compile.choice import compiled_module
    from components.model.kernel import WIND

    reason = compiled_module(WIND)[1]
    return ["numpy", pytest.param("compiled", marks=pytest.mark.skipif(reason is not None, reason=str(reason)))]


@pytest.mark.parametrize("kernel", _wind_kernels())
def test_phasor_stepper_follows_the_closed_form(kernel):
    from components.model.wind import PhasorStepper

    process = RotorSpeedProcess(WindParameters())
    stepper = PhasorStepper(process, kernel)
    assert stepper.kernel == kernel and stepper.kernel_note is None
    h = 1e-3
    n = 2 * PhasorStepper.REANCHOR_STEPS + 100  # across two re-anchorings
    got = np.empty((n, 2))
    for k in range(n):
        stepper.advance(k * h, h)  # the master's t = k h, not a running sum
        got[k] = stepper.speed_and_angle()
    t = (np.arange(n) + 1) * h
    angle, speed, _ = process.kinematics(t)
    np.testing.assert_allclose(got[:, 0], speed, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[:, 1], angle, rtol=1e-14, atol=1e-12)
    assert stepper.steps_since_anchor < PhasorStepper.REANCHOR_STEPS
    # the derivatives the Gearbox's rotor_derivatives extrapolation reads, from the same phasors
    alpha, jerk = stepper.acceleration_and_jerk()
    assert alpha == pytest.approx(process.acceleration(t[-1]), rel=0, abs=1e-12)
    assert jerk == pytest.approx(process.jerk(t[-1]), rel=0, abs=1e-11)


@pytest.mark.parametrize("kernel", _wind_kernels())
def test_phasor_stepper_state_continues_bit_identically_and_jumps_are_exact(kernel):
    import json

    from components.model.wind import PhasorStepper

    process = RotorSpeedProcess(WindParameters(seed=4))
    a = PhasorStepper(process, kernel)
    for k in range(500):
        a.advance(k * 2e-3, 2e-3)
    state = json.loads(json.dumps(a.get_state()))
    b = PhasorStepper(process, kernel)
    b.set_state(state)
    for k in range(500, 800):
        a.advance(k * 2e-3, 2e-3)
        b.advance(k * 2e-3, 2e-3)
        assert a.speed_and_angle() == b.speed_and_angle()
    b.advance(10.0, 1e-3)  # not where the phasors are: closed form at 10.001 s
    assert b.speed_and_angle() == pytest.approx((process.speed(10.001), process.angle(10.001)), abs=1e-12)
    with pytest.raises(ParameterError, match="phasors"):
        b.set_state({**state, "re": state["re"][:3]})


@pytest.mark.parametrize("kernel", _wind_kernels()[1:])
def test_compiled_phasor_step_agrees_with_the_numpy_path_to_round_off(kernel):
    """The compiled loop sums in index order, BLAS in its own: the same signal to the last bits, and the
    closed-form re-anchoring keeps it so (1.5 x REANCHOR_STEPS steps)."""
    from components.model.wind import PhasorStepper

    process = RotorSpeedProcess(WindParameters(seed=3))
    numpy_path, compiled_path = PhasorStepper(process, "numpy"), PhasorStepper(process, kernel)
    assert numpy_path.speed_and_angle() == pytest.approx(compiled_path.speed_and_angle(), rel=1e-15, abs=1e-14)
    for k in range(3 * PhasorStepper.REANCHOR_STEPS // 2):
        numpy_path.advance(k * 5e-3, 5e-3)
        compiled_path.advance(k * 5e-3, 5e-3)
        (w_a, phi_a), (w_b, phi_b) = numpy_path.speed_and_angle(), compiled_path.speed_and_angle()
        assert abs(w_a - w_b) <= 1e-13 and abs(phi_a - phi_b) <= 1e-13 * max(1.0, abs(phi_a)), k
    # the rotations too may round differently (numpy's complex multiply may be fused): |z| = 1 to 1e-14
    np.testing.assert_allclose(numpy_path.get_state()["re"], compiled_path.get_state()["re"], rtol=0, atol=1e-14)


def test_phasor_stepper_without_numba_falls_back_or_refuses(monkeypatch):
    from components.compile import choice
    from components.model.wind import PhasorStepper

    monkeypatch.setattr(choice, "compiled_module",
                        lambda *args, **kwargs: (None, "ModuleNotFoundError: No module named 'numba'"))
    process = RotorSpeedProcess(WindParameters())
    stepper = PhasorStepper(process, "auto")
    assert stepper.kernel == "numpy"
    assert stepper.kernel_note == ("compiled wind step unavailable (ModuleNotFoundError: No module named 'numba'); "
                                   "running it interpreted (numpy)")
    assert PhasorStepper(process, "numpy").kernel_note is None
    with pytest.raises(ParameterError, match=r"kernel = 'compiled'.*a compiled kernel: .*numba \(ModuleNotFoundError"):
        PhasorStepper(process, "compiled")
    with pytest.raises(ParameterError, match="kernel = 'fast'.*one of auto, numpy, compiled"):
        PhasorStepper(process, "fast")
