"""The kernel's ROS2(3) W-method and the co-simulation gearbox component."""

import json

import numpy as np
import pytest

from components.errors import SolverError
from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor
from components.model.integrators import StepControl
from components.model.presets import cosim_preset, table6_gearbox
from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.solver import simulate_monolithic


def _linear_stage():
    """The Table 3 parallel stage with a linear, undamped mesh spring and no backlash (a lightly damped mass-spring
    pair through shaft 3): the kernel's integrator sees a linear problem."""
    dt = cosim_preset("table3")
    return dt.with_meshes(exponent=1.0, damping=0.0, backlash_normal_m=0.0)


def _integrate(h, max_age, t_end=0.2):
    """Output of the linear stage, started at rest against a torque step, with a fixed internal step ``h``.

    Tolerances so loose that no step is rejected and the proposal grows: every internal step is cut to end
    on the communication point, so the internal step is the communication step ``h``.
    """
    dt = _linear_stage()
    control = StepControl(rtol=1e3, atol_q=1e3, atol_v=1e3, jacobian_max_age=max_age)
    model = GearboxModel(dt, control=control, generator_interface="inertia", start="rest")  # a load step to resolve
    w = 0.5
    model.initialize(0.0, w, 0.0, model.ratio * w, 0.0, 500.0)
    n = int(round(t_end / h))
    for k in range(n):
        t = k * h
        model.step(t, h, w, w * t, model.ratio * w + model.y[model.assembly.n_dof + model.generator_dof], 0.0, 500.0)
    return model.contact_force_n[0]


def test_second_order_convergence_on_a_stiff_problem():
    ref = _integrate(5e-6, 1)
    errors = [abs(_integrate(h, 1) - ref) for h in (2e-4, 1e-4, 5e-5)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(orders > 1.7), orders


def test_stale_jacobian_keeps_the_order():
    ref = _integrate(5e-6, 1)
    e1 = abs(_integrate(2e-4, 50) - ref)
    e2 = abs(_integrate(1e-4, 50) - ref)
    assert e1 / e2 > 3.0  # still second order with a Jacobian reused for 50 steps


def test_step_size_floor_raises_solver_error():
    dt = cosim_preset("table6")
    model = GearboxModel(dt, control=StepControl(h_min=1e-3))
    w = 1.6
    model.initialize(0.0, w, 0.0, model.ratio * w, 0.0)
    with pytest.raises(SolverError, match="below h_min"):  # the start-up impact needs far smaller steps
        model.step(0.0, 1e-2, w, 0.0, model.ratio * w + 5.0, 0.0)


def _paper_setup():
    dt = table6_gearbox()
    wind = RotorSpeedProcess(WindParameters())
    return dt, wind


def _cosim(dt, wind, t_end, h, model=None, gen=None, start=0):
    """The Gearbox and GeneratorRotor coupled by hand, started as the paper does (undeflected, the load a step: no
    counter torque at initialisation); the monolithic comparisons start at rest too."""
    model = model or GearboxModel(dt)
    gen = gen or GeneratorRotor(dt.generator, initial_speed_rad_s=dt.ratio * wind.speed(0.0))
    if start == 0:
        model.initialize(0.0, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s, gen.angle_rad)
    n = int(round(t_end / h))
    out = []
    for k in range(start, start + n):
        t = k * h
        model.step(t, h, wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
        gen.step(t, h, model.shaft_torque_nm)
        out.append((model.contact_force_n[0], model.contact_force_n[-1], gen.speed_rad_s, model.shaft_torque_nm))
    return np.array(out), model, gen


def test_cosimulated_gearbox_tracks_the_monolithic_reference():
    dt, wind = _paper_setup()
    h = 1e-3
    out, model, gen = _cosim(dt, wind, 3.5, h)
    ref = simulate_monolithic(dt, wind, 3.5, output_interval_s=h, start="rest")
    sel = slice(1000, None)  # after the first second
    for col, name in ((0, "stage1.F_sp[1]"), (1, "stage3.F_mesh"), (2, "omega_gen")):
        err = np.abs(out[sel, col] - ref[name][1:][sel]).max()
        assert err < 1e-3 * np.abs(ref[name]).max(), name
    # past the start-up transient: one internal step per communication step, Jacobian rarely refreshed
    before = (model.integrator.accepted, model.integrator.jacobians)
    _cosim(dt, wind, 0.5, h, model, gen, start=3500)
    assert model.integrator.accepted - before[0] == 500
    assert model.integrator.jacobians - before[1] <= 500 // 20 + 1


def test_state_round_trip_replays_bit_identically():
    dt, wind = _paper_setup()
    h = 1e-3
    _, model, gen = _cosim(dt, wind, 0.5, h)
    state = json.loads(json.dumps(model.get_state()))  # through JSON, as an FMU would serialise it
    gen_state = (gen.speed_rad_s, gen.angle_rad)
    first, _, _ = _cosim(dt, wind, 0.2, h, model, gen, start=500)
    fresh = GearboxModel(dt)
    fresh.set_state(state)
    gen.speed_rad_s, gen.angle_rad = gen_state
    second, _, _ = _cosim(dt, wind, 0.2, h, fresh, gen, start=500)
    np.testing.assert_array_equal(first, second)


def test_failed_step_leaves_state_untouched():
    dt, wind = _paper_setup()
    model = GearboxModel(dt, control=StepControl(max_steps=2))
    gen = GeneratorRotor(dt.generator, initial_speed_rad_s=dt.ratio * wind.speed(0.0))
    model.initialize(0.0, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s, gen.angle_rad)
    before = json.dumps(model.get_state())
    with pytest.raises(SolverError, match=r"more than 2 steps.*at t ="):
        model.step(0.0, 0.5, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s + 50.0, gen.angle_rad)
    assert json.dumps(model.get_state()) == before


def test_averaged_torque_conserves_the_exchanged_impulse():
    dt, wind = _paper_setup()
    h = 2e-3
    out, _, _ = _cosim(dt, wind, 1.0, h)
    ref = simulate_monolithic(dt, wind, 1.0, output_interval_s=1e-4, start="rest")
    t = ref.time_s
    torque = ref["shaft3.torque"]
    impulse_ref = np.trapezoid(torque, t)
    impulse_cosim = out[:, 3].sum() * h
    assert impulse_cosim == pytest.approx(impulse_ref, rel=2e-3)


def test_output_acceleration_and_its_running_peak():
    """``alpha_out`` is d omega_out/dt over the step; ``alpha_out_max`` is eq. 11 over every internal step."""
    from components.reference.acceleration import peak_output_acceleration

    dt, wind = _paper_setup()
    h = 1e-3
    model = GearboxModel(dt)
    gen = GeneratorRotor(dt.generator, initial_speed_rad_s=dt.ratio * wind.speed(0.0))
    model.initialize(0.0, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s, gen.angle_rad)
    assert model.alpha_out_max_rad_s2 == abs(model.alpha_out_average_rad_s2) == abs(model.output_acceleration_rad_s2)
    names = model.output_names
    speed, alpha, peak = [], [], []
    for k in range(500):
        t = k * h
        model.step(t, h, wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
        gen.step(t, h, model.shaft_torque_nm)
        out = dict(zip(names, model.output_vector()))
        speed.append(out["omega_out"]), alpha.append(out["alpha_out"]), peak.append(out["alpha_out_max"])
    speed, alpha, peak = map(np.array, (speed, alpha, peak))
    # alpha_out is the step average: the speed increment of each step over h
    np.testing.assert_allclose(alpha[1:], np.diff(speed) / h, rtol=1e-9, atol=1e-9)
    # ... and follows the monolithic model's step-averaged acceleration (trapezoid of its samples)
    mono = simulate_monolithic(dt, wind, 0.5, output_interval_s=h, start="rest")["alpha_out"]
    late = slice(300, None)
    diff = alpha[late] - 0.5 * (mono[:-1] + mono[1:])[late]
    scale = np.abs(mono[300:]).max()
    assert np.sqrt(np.mean(diff**2)) < 1e-2 * scale  # measured 0.6 % and np.abs(diff).max() < 0.05 * scale
    assert np.all(np.diff(peak) >= 0) and np.all(peak >= np.abs(alpha) * (1 - 1e-12))
    # the peak is a pulse far shorter than h: sampled alpha_out misses it, the running peak does not
    ref = peak_output_acceleration(dt, wind, 0.5).value_rad_s2
    assert np.abs(alpha).max() < 0.5 * ref
    assert peak[-1] == pytest.approx(ref, rel=5e-3)
    # a new initialisation starts the maximum afresh
    model.initialize(0.0, wind.speed(0.0), wind.angle(0.0), dt.ratio * wind.speed(0.0), 0.0)
    assert model.alpha_out_max_rad_s2 < 1e-6 * ref


def test_monolithic_wall_time_limit():
    """SolverSettings.wall_time_limit_s stops LSODA from inside the right-hand side."""
    from components.errors import ParameterError, WallTimeLimitError
    from components.reference.acceleration import peak_output_acceleration
    from components.reference.solver import SolverSettings

    dt, wind = _paper_setup()
    tiny = SolverSettings(wall_time_limit_s=1e-9)
    result = simulate_monolithic(dt, wind, 1.0, settings=tiny, start="rest")
    assert not result.complete
    assert result.message.startswith("wall-time limit of 1e-09 s reached (at t = ")
    assert result.time_s.size == 1  # one load segment: only the initial sample survives
    with pytest.raises(WallTimeLimitError, match=r"wall-time limit of 1e-09 s reached \(at t = "):
        simulate_monolithic(dt, wind, 1.0, settings=tiny, raise_on_failure=True, start="rest")
    with pytest.raises(WallTimeLimitError, match="wall-time limit"):
        peak_output_acceleration(dt, wind, 1.0, settings=tiny)
    with pytest.raises(ParameterError, match=r"wall_time_limit_s = -1\.0: expected >= 0"):
        SolverSettings(wall_time_limit_s=-1.0)
    assert simulate_monolithic(dt, wind, 0.05, settings=SolverSettings(wall_time_limit_s=60.0)).complete


@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
def test_step_average_torque_integrates_a_ringing_shaft_along_the_internal_steps(kernel):
    """The exchanged impulse of one 10 ms step matches 200 sub-steps along the same input motion.

    Constant input speeds (no extrapolation), the generator end 0.5 rad/s too fast: shaft 3 rings inside the
    step, so the plain trapezoid of the two end twists is visibly off; the twist integrated along the accepted
    internal steps is not.
    """
    if kernel == "compiled":
        pytest.importorskip("numba")
    dt, wind = _paper_setup()
    omega_r, h, n_sub = wind.speed(0.0), 1e-2, 200
    omega_g = dt.ratio * omega_r + 0.5

    def model():
        m = GearboxModel(dt, extrapolate=False, kernel=kernel)
        m.initialize(0.0, omega_r, 0.0, omega_g, 0.0)
        return m

    one = model()
    twist_start = one.output_twist_rad
    one.step(0.0, h, omega_r, 0.0, omega_g, 0.0)
    assert one.integrator.accepted > 3  # the ringing is resolved by several internal steps
    fine = model()
    averages = []
    for k in range(n_sub):
        t = k * h / n_sub
        fine.step(t, h / n_sub, omega_r, omega_r * t, omega_g, omega_g * t)
        averages.append(fine.shaft_torque_average_nm)
    exact = float(np.mean(averages))
    k3, c3 = dt.output_shaft.stiffness_nm_per_rad, dt.output_shaft.damping_nms_per_rad
    twist_end = one.output_twist_rad
    trapezoid = k3 * 0.5 * (twist_start + twist_end) + c3 * (twist_end - twist_start) / h
    assert abs(trapezoid - exact) > 5e-3 * abs(exact)  # measured 0.85 % (integrated: 0.018 %, 152 internal steps)
    assert abs(one.shaft_torque_average_nm - exact) < 0.05 * abs(trapezoid - exact)
