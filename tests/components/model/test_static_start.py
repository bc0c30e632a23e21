"""Runs start at their operating point: the static deflection of the initial load (issue 29).

The Gearbox (both generator interfaces) and the monolithic reference put the drivetrain at the
kernel's static deflection (:mod:`components.model.kernel.statics`) before the first step, so a
constant input gives a constant output from the start; ``start="rest"`` keeps the paper's start,
undeflected with the load a step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.errors import ParameterError
from components.model.assembly import Assembly
from components.model.gearbox_model import GearboxModel
from components.model.presets import cosim_preset, preset
from components.model.wind import ConstantSpeed
from components.reference.solver import simulate_monolithic
from orchestrator.inputs.drivetrain_file import load_drivetrain_file, packaged_drivetrains

RPM16 = 16.0 * 2.0 * math.pi / 60.0


def _drivetrains():
    for name in ("table3", "table5", "table6"):
        yield name, cosim_preset(name)
    for name, path in packaged_drivetrains().items():  # those with a generator: a Gearbox is cut there
        spec = load_drivetrain_file(path)
        if spec.drivetrain.generator is not None:
            yield f"file:{name}", spec.cosim_drivetrain()


DRIVETRAINS = dict(_drivetrains())


def _constant_run(dt, interface, kernel="auto", start="operating_point", steps=300, h=5e-3):
    """Contact forces of the Gearbox driven at constant rotor speed against the generator's constant torque."""
    model = GearboxModel(dt, kernel=kernel, generator_interface=interface, start=start)
    torque = dt.generator.counter_torque_nm
    w, ratio = RPM16, model.ratio
    model.initialize(0.0, w, 0.3, ratio * w, 1.7, torque)  # any generator angle: read relative to the static twist
    forces = [model.contact_force_n.copy()]
    for k in range(steps):
        t = k * h
        model.step(t, h, w, 0.3 + w * t, ratio * w, 1.7 + ratio * w * t, torque)
        forces.append(model.contact_force_n.copy())
    return np.array(forces), model


@pytest.mark.parametrize("interface", ["motion", "inertia"])
@pytest.mark.parametrize("name", list(DRIVETRAINS))
def test_a_constant_input_gives_constant_forces_from_the_start(name, interface):
    forces, model = _constant_run(DRIVETRAINS[name], interface)
    mean = forces.mean(axis=0)
    assert np.all(np.abs(mean) > 0.0)
    assert np.abs(forces - mean).max() <= 1e-6 * np.abs(mean).max(), (name, interface)
    assert model.shaft_torque_nm == pytest.approx(DRIVETRAINS[name].generator.counter_torque_nm, rel=1e-9)


def test_start_at_rest_keeps_the_load_step():
    forces, model = _constant_run(DRIVETRAINS["table6"], "inertia", start="rest")
    assert model.static_iterations == 0 and np.all(forces[0] == 0.0)  # undeflected: teeth centred in the backlash
    assert np.ptp(forces[:, 0]) > 0.5 * np.abs(forces[-1, 0])  # the load arrives as a step: a transient


def test_the_static_deflection_of_one_parallel_stage_by_hand():
    """Table 3's parallel stage with shaft 3 and a generator: F = T / r_b of the driven gear, and the CFS
    indentation d_BL = (F / k0)^(1/e) beyond half the circumferential backlash (deep contact: tanh = 1)."""
    dt = cosim_preset("table3")
    stage, torque = dt.stages[0], dt.generator.counter_torque_nm
    forces, model = _constant_run(dt, "inertia", steps=1)
    mesh = stage.mesh
    force = torque / (stage.driven_radius_m * math.cos(mesh.pressure_angle_rad))
    assert model.contact_force_n[0] == pytest.approx(force, rel=1e-10)
    indentation = (force / mesh.stiffness) ** (1.0 / mesh.exponent)
    assert model.deflection_m[0] == pytest.approx(0.5 * mesh.backlash_circumferential_m + indentation, rel=1e-9)
    # shaft 3 twisted by T / k3
    assert model.shaft_twist_rad[0, -1] == pytest.approx(torque / dt.output_shaft.stiffness_nm_per_rad, rel=1e-9)


@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
def test_both_kernel_forms_find_the_same_static_deflection(kernel):
    a = Assembly(preset("table6"))
    q, iterations, imbalance = a.static_deflection(25.4e3, kernel=kernel)
    q_other, _, _ = a.static_deflection(25.4e3, kernel="numpy" if kernel == "compiled" else "compiled")
    np.testing.assert_allclose(q, q_other, rtol=1e-12, atol=0.0)
    assert imbalance < 1e-11
    with pytest.raises(ParameterError, match="load_nm.*non-zero"):
        a.static_deflection(0.0)


@pytest.mark.parametrize("start, constant", [("operating_point", True), ("rest", False)])
def test_the_monolithic_reference_starts_where_the_cosimulation_does(start, constant):
    dt = preset("table6")
    result = simulate_monolithic(dt, ConstantSpeed(RPM16), 0.5, output_interval_s=1e-3, start=start)
    force = result["stage1.F_sp[1]"]
    if constant:
        assert np.abs(force - force.mean()).max() <= 1e-6 * abs(force.mean())
        cosim, _ = _constant_run(cosim_preset("table6"), "inertia", steps=1)
        assert force[0] == pytest.approx(cosim[0, 0], rel=1e-9)
    else:
        assert force[0] == 0.0 and np.ptp(force) > 0.1 * abs(force[-1])
