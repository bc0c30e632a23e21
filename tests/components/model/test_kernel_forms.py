"""The kernel's two forms - compiled (numba) and interpreted (numpy) - of one source, on every stage kind and option.

Both run the same equations (:mod:`components.model.kernel`), so they agree per step to
1e-12 (in practice to the last bit): checked where it is defined, one communication step
taken by both from the same state, at many states along a coupled run (start-up impacts,
backlash traversals and steady running included), on every packaged drivetrain, contact
law and generator interface, plus the building blocks and the monolithic right-hand side.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from components.compile.choice import compiled_module
from components.errors import ParameterError, SolverError
from components.model import kernel as model_kernel
from components.model.assembly import Assembly
from components.model.contact import ContactLaw
from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor
from components.model.integrators import StepControl
from components.model.kernel import ENVIRONMENT_VARIABLE, choose_kernel
from components.model.mesh_stiffness import MeshPhasing
from components.model.presets import (
    cosim_preset,
    sensitivity_variant,
    table5_planetary,
    with_stage,
)
from components.model.wind import RotorSpeedProcess, WindParameters
from orchestrator.inputs.drivetrain_file import load_drivetrain_file, packaged_drivetrains

ck, _reason = compiled_module(model_kernel.MONOLITHIC, ahead_of_time=False)
pytestmark = pytest.mark.skipif(ck is None, reason=f"compiled kernel unavailable: {_reason}")
#: the agreement of the two forms per step, relative to each quantity's scale
TOLERANCE = 1e-12


def _cosim_ready(dt):
    """A drivetrain with a generator (cosim_preset's generator and shaft 3 if it has none)."""
    if dt.generator is not None:
        return dt
    template = cosim_preset("table6")
    return replace(dt, generator=template.generator, output_shaft=template.output_shaft, output_torque_nm=0.0)


def _variants():
    table6 = cosim_preset("table6")
    five = table5_planetary(n_planets=5)
    yield "table3", cosim_preset("table3")
    yield "table5", cosim_preset("table5")
    yield "table6", table6
    yield "sec4.1", _cosim_ready(sensitivity_variant(8.0, 100.0))
    yield "table5-4-planets", _cosim_ready(table5_planetary(n_planets=4))
    yield "table5-5-planets-impact", _cosim_ready(five.with_meshes(law="impact"))
    yield "table6-impact", table6.with_meshes(law="impact")
    yield "table6-mixed-laws", with_stage(table6, 2, mesh=replace(table6.stages[2].mesh, law="impact"))
    yield "table6-stiffness-variation", table6.with_meshes(stiffness_variation=0.3)
    yield "table6-exponent-2", table6.with_meshes(exponent=2.0)
    for name, path in packaged_drivetrains().items():  # those with a generator: a Gearbox is cut there
        spec = load_drivetrain_file(path)
        if spec.drivetrain.generator is not None:
            yield f"file:{name}", spec.cosim_drivetrain()


VARIANTS = dict(_variants())


def _relative(a: np.ndarray, b: np.ndarray, scale: np.ndarray) -> float:
    return float(np.max(np.abs(a - b) / scale))


#: the generator interface and the rotor extrapolation: the default, and the interface model with the
#: rotor's derivative inputs
INTERFACES = {"motion": {}, "inertia": {"generator_interface": "inertia", "rotor_derivatives": True}}


def _jerk(wind: RotorSpeedProcess, t: float) -> float:
    return (wind.acceleration(t + 1e-6) - wind.acceleration(t - 1e-6)) / 2e-6


@pytest.mark.parametrize("interface", list(INTERFACES))
@pytest.mark.parametrize("name", list(VARIANTS))
def test_one_communication_step_is_the_same_in_both_forms(name, interface):
    dt = VARIANTS[name]
    wind = RotorSpeedProcess(WindParameters())
    h = 2e-3
    options = INTERFACES[interface]
    numpy_model = GearboxModel(dt, kernel="numpy", **options)
    compiled = GearboxModel(dt, kernel="compiled", **options)
    assert (numpy_model.kernel, compiled.kernel) == ("numpy", "compiled")
    w0, p0 = wind.speed(0.0), wind.angle(0.0)
    gen = GeneratorRotor(dt.generator, compiled.ratio * w0, compiled.ratio * p0)
    compiled.initialize(0.0, w0, p0, gen.speed_rad_s, gen.angle_rad, gen.counter_torque(0.0))
    # the run is the compiled form's (the interpreted one would take 150 steps, a TVMS one ~40 s); at every 5th
    # state both forms take the step from that state
    samples, outputs = [], []
    for k in range(150):
        t = k * h
        inputs = (wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad, gen.counter_torque(t),
                  wind.acceleration(t), _jerk(wind, t))
        if k % 5 == 0:
            state = json.loads(json.dumps(compiled.get_state()))
            numpy_model.set_state(state)
            numpy_model.step(t, h, *inputs)
            compiled.set_state(state)
        compiled.step(t, h, *inputs)
        outputs.append(compiled.output_vector())
        if k % 5 == 0:
            samples.append((t, outputs[-1], compiled.y.copy(), compiled.integrator, numpy_model.output_vector(),
                            numpy_model.y.copy(), numpy_model.integrator))
        gen.step(t, h, compiled.shaft_torque_nm)
    # each output compared on the scale it has over the run (torque_rotor, e.g., is a small sum of large terms)
    scale = np.abs(outputs).max(axis=0) + 1e-300
    for t, got, y, counters, expected, expected_y, expected_counters in samples:
        assert _relative(got, expected, scale) < TOLERANCE, (name, t)
        assert _relative(y, expected_y, np.abs(expected_y).max() + 1e-300) < TOLERANCE, (name, t)
        assert counters == expected_counters, (name, t)
    assert len(samples) == 30


def test_a_coupled_run_stays_close_over_many_steps():
    """Over 2000 coupled steps the two forms stay together (round-off amplified by step control at most)."""
    dt = cosim_preset("table6")
    wind = RotorSpeedProcess(WindParameters())
    runs = {}
    for kernel in ("numpy", "compiled"):
        model = GearboxModel(dt, kernel=kernel)
        w0, p0 = wind.speed(0.0), wind.angle(0.0)
        model.initialize(0.0, w0, p0, model.ratio * w0, model.ratio * p0)
        gen = GeneratorRotor(dt.generator, model.output_speed_rad_s, model.ratio * p0)
        out = []
        for k in range(2000):
            t = k * 1e-3
            model.step(t, 1e-3, wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
            gen.step(t, 1e-3, model.shaft_torque_nm)
            out.append(model.contact_force_n.copy())
        runs[kernel] = np.array(out)
    scale = np.abs(runs["numpy"]).max()
    assert np.abs(runs["compiled"] - runs["numpy"])[1000:].max() < 1e-6 * scale


@pytest.mark.parametrize("name", ["table6", "table6-impact", "table6-mixed-laws", "table6-exponent-2"])
def test_contact_law_is_the_same_in_both_forms(name):
    a = Assembly(VARIANTS[name], cut_at_generator=True)
    table = a.law.table
    rng = np.random.default_rng(3)
    half = table[:, 4]
    d = (rng.uniform(-3.0, 3.0, (400, a.n_mesh)) * half) + rng.normal(0.0, 1e-5, (400, a.n_mesh))
    rate = rng.normal(0.0, 5e-3, d.shape)
    factor = rng.uniform(0.8, 1.2, d.shape)
    cf = ContactLaw(a.law.meshes, kernel="numpy").evaluate(d, rate, factor)
    got = np.array([[ck.contact_force(d[r, i], rate[r, i], factor[r, i], table[i]) for i in range(a.n_mesh)]
                    for r in range(d.shape[0])])
    for k, want in enumerate((cf.force, cf.d_force_d_deflection, cf.d_force_d_rate, cf.elastic)):
        scale = np.abs(want).max() + 1e-300
        assert np.max(np.abs(got[..., k] - want)) <= TOLERANCE * scale, k


def test_stiffness_factors_are_the_same_in_both_forms():
    a = Assembly(VARIANTS["table6-stiffness-variation"], cut_at_generator=True)
    table = a.phasing_table
    factor, slope = np.empty(a.n_mesh), np.empty(a.n_mesh)
    angles = np.linspace(-3.0, 40.0, 997)
    want_f, want_s = MeshPhasing.__new__(MeshPhasing), None
    want_f.table = table
    want_f, want_s = want_f.factors(angles, kernel="numpy")
    for angle, wf, ws in zip(angles, want_f, want_s):
        ck.stiffness_factors(angle, table, factor, slope)
        np.testing.assert_allclose(factor, wf, rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(slope, ws, rtol=0, atol=TOLERANCE * np.abs(want_s).max())


@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
@pytest.mark.parametrize("interface", list(INTERFACES))
def test_failed_step_leaves_the_state_untouched(interface, kernel):
    dt = cosim_preset("table6")
    wind = RotorSpeedProcess(WindParameters())
    model = GearboxModel(dt, control=StepControl(max_steps=30), kernel=kernel, **INTERFACES[interface])
    gen = GeneratorRotor(dt.generator, initial_speed_rad_s=dt.ratio * wind.speed(0.0))
    model.initialize(0.0, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s, gen.angle_rad)
    model.step(0.0, 1e-4, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s, gen.angle_rad, 2.0e4)
    before = json.dumps(model.get_state())
    with pytest.raises(SolverError, match=r"more than 30 steps.*at t ="):
        model.step(1e-4, 0.5, wind.speed(0.0), wind.angle(0.0), gen.speed_rad_s + 50.0, gen.angle_rad, 3.0e4)
    assert json.dumps(model.get_state()) == before
    with pytest.raises(SolverError, match="non-finite input.*omega_rotor=nan"):
        model.step(1e-4, 1e-3, math.nan, 0.0, 0.0, 0.0)
    with pytest.raises(SolverError, match="non-finite input.*omega_gen=nan"):
        model.step(1e-4, 1e-3, 1.0, 0.0, math.nan, 0.0)
    assert json.dumps(model.get_state()) == before


def test_states_move_between_the_two_forms():
    """A state taken from the compiled model continues bit-identically in another compiled model and in numpy."""
    dt = cosim_preset("table6")
    wind = RotorSpeedProcess(WindParameters())
    model = GearboxModel(dt, kernel="compiled")
    w0, p0 = wind.speed(0.0), wind.angle(0.0)
    model.initialize(0.0, w0, p0, model.ratio * w0, model.ratio * p0)
    gen = GeneratorRotor(dt.generator, model.output_speed_rad_s, model.ratio * p0)
    for k in range(300):
        t = k * 1e-3
        model.step(t, 1e-3, wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
        gen.step(t, 1e-3, model.shaft_torque_nm)
    state = json.loads(json.dumps(model.get_state()))
    inputs = (wind.speed(0.3), wind.angle(0.3), gen.speed_rad_s, gen.angle_rad)
    results = []
    for kernel in ("compiled", "compiled", "numpy"):
        other = GearboxModel(dt, kernel=kernel)
        other.set_state(state)
        other.step(0.3, 1e-3, *inputs)
        results.append(other.output_vector())
    model.step(0.3, 1e-3, *inputs)
    np.testing.assert_array_equal(results[0], model.output_vector())
    np.testing.assert_array_equal(results[1], model.output_vector())
    scale = np.maximum(np.abs(results[2]), 1e-6 * np.abs(results[2]).max())
    assert _relative(results[0], results[2], scale) < TOLERANCE


def test_kernel_choice(monkeypatch):
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "numpy")
    assert choose_kernel() == ("numpy", None)
    assert GearboxModel(cosim_preset("table6")).kernel == "numpy"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "compiled")
    assert GearboxModel(cosim_preset("table6")).kernel == "compiled"
    assert GearboxModel(cosim_preset("table6"), kernel="numpy").kernel == "numpy"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "fortran")
    with pytest.raises(ParameterError, match="DTCOSIM_KERNEL.*fortran.*auto, numpy, compiled"):
        GearboxModel(cosim_preset("table6"))


def _monolithic_variants():
    from components.model.generator import LoadEvent
    from components.model.presets import preset

    table6 = preset("table6")
    yield "table3", preset("table3")
    yield "table5", preset("table5")
    yield "table6", table6
    yield "sec4.1", sensitivity_variant(8.0, 100.0)
    yield "table5-5-planets-impact", table5_planetary(n_planets=5).with_meshes(law="impact")
    yield "table6-stiffness-variation", table6.with_meshes(stiffness_variation=0.3)
    events = (LoadEvent("torque_step", 0.2, factor=1.5), LoadEvent("grid_fault", 0.5, 0.1))
    yield "table6-events", replace(table6, generator=replace(table6.generator, events=events))


@pytest.mark.parametrize("name", [n for n, _ in _monolithic_variants()])
def test_monolithic_rhs_and_jacobian_are_the_same_in_both_forms(name):
    from components.reference.solver import MonolithicSystem

    dt = dict(_monolithic_variants())[name]
    wind = RotorSpeedProcess(WindParameters())
    systems = {k: MonolithicSystem(dt, wind, kernel=k) for k in ("numpy", "compiled")}
    assert systems["compiled"].kernel == "compiled"
    a = systems["numpy"].assembly
    rng = np.random.default_rng(7)
    # states around the backlash and deep in contact: deflections of a few backlash widths
    q_scale = 3.0 * float(np.max(a.law.table[:, 4])) / float(np.max(np.abs(a.A)))
    schedule = dt.load_schedule()
    for t in np.linspace(0.0, 0.8, 9):
        y = np.concatenate([rng.normal(0.0, q_scale, a.n_dof), rng.normal(0.0, 1e-2, a.n_dof), rng.normal(0.0, 1.0, 3)])
        for s in systems.values():
            s.load_torque_nm = float(schedule(t))
        rhs = {k: s.rhs(t, y) for k, s in systems.items()}
        jac = {k: s.jacobian(t, y).copy() for k, s in systems.items()}
        scale = np.abs(rhs["numpy"]) + 1e-6 * np.abs(rhs["numpy"]).max()
        assert _relative(rhs["compiled"], rhs["numpy"], scale) < TOLERANCE, (name, t)
        j_scale = np.abs(jac["numpy"]).max()
        assert np.abs(jac["compiled"] - jac["numpy"]).max() <= TOLERANCE * j_scale, (name, t)
