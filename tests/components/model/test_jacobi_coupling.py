"""The Jacobi coupling of the gearbox - generator cut (issue 31.3): the Gearbox's ``inertia_own`` interface and a
generator that follows it, against the Gauss-Seidel cut they stand in for."""

from __future__ import annotations

import numpy as np
import pytest

from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor, ShaftTorquePrediction
from components.model.presets import table6_gearbox
from components.model.wind import RotorSpeedProcess, WindParameters

H, STEPS = 0.02, 100


def test_the_prediction_holds_then_extrapolates_and_is_exact_for_a_quadratic_torque():
    torque = lambda t: 3.0 + 2.0 * t - 0.5 * t * t  # noqa: E731
    mean = lambda a, b: (3.0 * (b - a) + (b * b - a * a) - (b ** 3 - a ** 3) / 6.0) / (b - a)  # noqa: E731
    p = ShaftTorquePrediction()
    assert p.predict(0.0, H, torque(0.0)) == torque(0.0)  # one value: held
    errors = [p.predict(k * H, H, mean((k - 1) * H, k * H)) - mean(k * H, (k + 1) * H) for k in range(1, 8)]
    assert abs(errors[0]) > 1e-4  # linear through the start value and one mean
    assert max(abs(e) for e in errors[2:]) < 1e-12  # three means: exact
    state = p.get_state()
    q = ShaftTorquePrediction()
    q.set_state(state)
    assert q.predict(8 * H, H, 1.0) == p.predict(8 * H, H, 1.0)


def _run(jacobi: bool):
    drivetrain = table6_gearbox()
    wind = RotorSpeedProcess(WindParameters())
    gearbox = GearboxModel(drivetrain, generator_interface="inertia_own" if jacobi else "inertia",
                           rotor_derivatives=True)
    w0, p0 = wind.speed_and_angle(0.0)
    generator = GeneratorRotor(drivetrain.generator, gearbox.ratio * w0, 0.0)
    torque_c = drivetrain.generator.counter_torque_nm
    gearbox.initialize(0.0, w0, p0, generator.speed_rad_s, 0.0, torque_c)
    names = gearbox.output_names
    i_torque, i_speed = names.index("shaft_torque"), names.index("omega_generator")
    prediction = ShaftTorquePrediction()
    out, speeds = [gearbox.output_vector()], [generator.speed_rad_s]
    for k in range(STEPS):
        t = k * H
        before = out[-1]
        w, p = wind.speed_and_angle(t)
        gearbox.step(t, H, w, p, generator.speed_rad_s, generator.angle_rad, torque_c, float(wind.acceleration(t)),
                     float(wind.jerk(t)))
        if jacobi:  # the generator gets the gearbox's values of t, not of t + h
            generator.speed_rad_s = before[i_speed]
            generator.step(t, H, prediction.predict(t, H, before[i_torque]))
        else:
            generator.step(t, H, gearbox.shaft_torque_nm)
        out.append(gearbox.output_vector())
        speeds.append(generator.speed_rad_s)
    return np.array(out), np.array(speeds), names


@pytest.fixture(scope="module")
def runs():
    return _run(False), _run(True)


def test_inertia_own_under_jacobi_gives_the_gauss_seidel_gearbox(runs):
    (gs, gs_speed, names), (jac, _, _) = runs
    forces = [i for i, n in enumerate(names) if ".F_" in n]
    scale = np.max(np.abs(gs[:, forces]))
    assert np.max(np.abs(jac[:, forces] - gs[:, forces])) < 1e-9 * scale
    # omega_generator is the generator's impulse balance: the Gauss-Seidel generator's speed
    np.testing.assert_allclose(gs[:, names.index("omega_generator")], gs_speed, rtol=1e-12)


def test_the_following_generator_is_within_second_order_of_the_gauss_seidel_one(runs):
    (_, gs_speed, _), (_, jac_speed, _) = runs
    lag = np.max(np.abs(np.diff(gs_speed)))  # what a one-step lag would cost
    assert np.max(np.abs(jac_speed - gs_speed)) < 1e-2 * lag
