"""Each FMU alone under ``fmpy.simulate_fmu`` gives the numbers of its component called directly."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from fmpy import simulate_fmu

from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorParameters, GeneratorRotor, LoadEvent
from components.model.presets import cosim_preset, with_stage
from components.model.wind import RotorSpeedProcess, WindParameters
from tests.helpers.fmu_hosts import gearbox_motion

H = 1.0e-3


def grid(t_end: float) -> np.ndarray:
    """fmpy's communication points for output_interval = H: start + n H."""
    return np.arange(int(round(t_end / H)) + 1) * H


@pytest.mark.parametrize("start_values, params", [
    ({}, WindParameters()),
    ({"seed": 7, "amplitude": 1, "n_harmonics": 64, "omega0": 1.2, "f_max": 3.0},
     WindParameters(seed=7, amplitude="paper", n_harmonics=64, mean_speed_rad_s=1.2, f_max_rad_s=3.0)),
])
def test_wind_source_matches_rotor_speed_process(fmu_path, start_values, params):
    result = simulate_fmu(fmu_path("WindSource"), start_time=0.0, stop_time=0.5, step_size=H, output_interval=H,
                          start_values=start_values)
    process = RotorSpeedProcess(params)
    assert np.allclose(result["time"], grid(0.5), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result["omega"], process.speed(result["time"]), rtol=1e-13)
    np.testing.assert_allclose(result["phi"], process.angle(result["time"]), rtol=1e-12, atol=1e-15)


def test_generator_rotor_matches_component_with_a_load_event(fmu_path):
    t_end = 0.5
    times = grid(t_end)
    torque = 2.0e4 + 3.0e3 * np.sin(20.0 * times)
    table = np.array(list(zip(times, torque)), dtype=[("time", float), ("shaft_torque", float)])
    start = {"inertia": 120.0, "counter_torque": 2.2e4, "initial_speed": 150.0, "initial_angle": 0.3,
             "event2.kind": 1, "event2.start": 0.2, "event2.duration": 0.1, "event2.factor": 0.5}
    result = simulate_fmu(fmu_path("GeneratorRotor"), start_time=0.0, stop_time=t_end, step_size=H, output_interval=H,
                          input=table, start_values=start)
    params = GeneratorParameters(120.0, 2.2e4, events=(LoadEvent("torque_step", 0.2, 0.1, 0.5),))
    rotor = GeneratorRotor(params, 150.0, 0.3)
    t = result["time"]
    speed, angle = [rotor.speed_rad_s], [rotor.angle_rad]
    for n in range(len(t) - 1):
        rotor.step(t[n], t[n + 1] - t[n], torque[n])
        speed.append(rotor.speed_rad_s)
        angle.append(rotor.angle_rad)
    np.testing.assert_allclose(result["omega"], speed, rtol=1e-12)
    np.testing.assert_allclose(result["phi"], angle, rtol=1e-12)
    np.testing.assert_array_equal(result["generator_torque"], [params.schedule()(x) for x in t])
    assert set(result["generator_torque"]) == {2.2e4, 1.1e4}  # the torque step is visible


def _gearbox_table(t_end: float, ratio: float) -> tuple[np.ndarray, np.ndarray]:
    names = ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen")
    times = grid(t_end)
    rows = np.array([[gearbox_motion(t, ratio)[n] for n in names] for t in times])
    table = np.array([(t, *row) for t, row in zip(times, rows)], dtype=[("time", float)] + [(n, float) for n in names])
    return table, rows


def _stage2_impact(drivetrain):
    stage = drivetrain.stages[1]
    impact = replace(stage.sun_mesh, law="impact")
    return with_stage(drivetrain, 1, sun_mesh=impact, ring_mesh=impact)


@pytest.mark.parametrize("start_values, configure, mode", [
    ({}, lambda dt: dt, "average"),
    ({"shaft_torque_mode": 1, "stage2.contact_law": 1, "shaft3.stiffness": 2.0e4},
     lambda dt: replace(_stage2_impact(dt), output_shaft=replace(dt.output_shaft, stiffness_nm_per_rad=2.0e4)), "end"),
])
def test_gearbox_matches_gearbox_model(fmu_path, start_values, configure, mode):
    t_end = 0.3
    drivetrain = configure(cosim_preset("table6"))
    model = GearboxModel(drivetrain, shaft_torque_mode=mode)
    table, rows = _gearbox_table(t_end, model.ratio)
    outputs = ["shaft_torque", "shaft_torque_end", "shaft_torque_avg", "omega_out", "torque_rotor",
               "stage1.F_sp[1]", "stage2.F_rp[3]", "stage3.F_mesh", "shaft2.torque", "stage2.sun.omega"]
    result = simulate_fmu(fmu_path("Gearbox"), start_time=0.0, stop_time=t_end, step_size=H, output_interval=H,
                          input=table, start_values=start_values, output=outputs)
    t = result["time"]
    np.testing.assert_array_equal(t, grid(t_end))
    model.initialize(0.0, *rows[0], drivetrain.generator.counter_torque_nm)  # the FMU's counter_torque default
    expected = {name: [] for name in outputs}

    def record():
        shafts = model.shaft_torques_nm
        speeds = dict(zip(model.assembly.dof_names, model.speeds_rad_s))
        forces = dict(zip(model.assembly.mesh_names, model.contact_force_n))
        values = {"shaft_torque": model.shaft_torque_nm, "shaft_torque_end": model.shaft_torque_end_nm,
                  "shaft_torque_avg": model.shaft_torque_average_nm, "omega_out": model.output_speed_rad_s,
                  "torque_rotor": model.rotor_torque_nm, "shaft2.torque": shafts[1],
                  "stage2.sun.omega": speeds["stage2.sun"]}
        for name in outputs:
            expected[name].append(values[name] if name in values else forces[name])

    record()
    for n in range(len(t) - 1):
        model.step(t[n], t[n + 1] - t[n], *rows[n])
        record()
    for name in outputs:
        np.testing.assert_allclose(result[name], expected[name], rtol=1e-12, atol=1e-9, err_msg=name)
    assert result["omega_out"][0] == pytest.approx(model.ratio * rows[0][0], rel=1e-12)  # kinematic initial state
    assert np.ptp(result["shaft_torque"]) > 1.0e3  # the prescribed twist loads shaft 3
