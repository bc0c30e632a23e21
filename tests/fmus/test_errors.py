"""Errors reach the host with a status and a message naming the cause; the host never crashes.

dtcosim's FMU binary (fmus/native/dtcosim_fmi2.c) maps a Python exception to fmi2Error (that
instance cannot go on; pythonfmu 0.7's wrapper said fmi2Fatal) and forwards log messages only
with ``loggingOn``; the slaves log the message first and echo errors to stderr (see
fmus/slaves/base.py).
"""

from __future__ import annotations

import math
import textwrap

import pytest
from fmpy.fmi1 import FMICallException

from components.model.presets import cosim_preset
from tests.helpers.fmu_hosts import (
    FMI_ERROR,
    Instance,
    gearbox_motion,
    run_python,
)

RATIO = cosim_preset("table6").ratio
DISCARD = 2


@pytest.mark.parametrize("name, values, message", [
    ("WindSource", {"sigma": -0.1}, "invalid parameter sigma = -0.1: expected > 0"),
    ("WindSource", {"n_harmonics": 0}, "invalid parameter n_harmonics = 0: expected an integer within [1, 100000]"),
    ("WindSource", {"f_min": 5.0, "f_max": 2.0}, "invalid parameter f_max = 2.0: expected > f_min"),
    ("WindSource", {"amplitude": 2}, "invalid parameter amplitude = 2: expected 0 = variance, 1 = paper"),
    ("Gearbox", {"stage1.k0": -1.0}, "invalid parameter stage1.k0 = -1.0: expected > 0"),
    ("Gearbox", {"stage2.lambda": 0.0}, "invalid parameter stage2.lambda = 0.0: expected > 0"),
    ("Gearbox", {"stage3.contact_law": 7}, "invalid parameter stage3.contact_law = 7: expected 0 (CFS) or 1 (impact)"),
    ("Gearbox", {"stage2.pressure_angle": 2.0}, "invalid parameter stage2.pressure_angle = 2.0: expected within"),
    ("Gearbox", {"stage2.planet_mass": 0.0}, "invalid parameter stage2.planet_mass = 0.0: expected > 0"),
    ("Gearbox", {"stage1.ring_radius": 0.05}, "invalid parameter stage1.ring_radius = 0.05: expected > sun radius"),
    ("Gearbox", {"shaft3.damping": -1.0}, "invalid parameter shaft3.damping = -1.0: expected >= 0"),
    ("Gearbox", {"solver.rtol": 0.0}, "invalid parameter solver.rtol = 0.0: expected > 0"),
    ("Gearbox", {"shaft_torque_mode": 2}, "invalid parameter shaft_torque_mode = 2"),
    ("Gearbox", {"generator_interface": 3},
     "invalid parameter generator_interface = 3: expected 0 = motion, 1 = inertia, 2 = inertia_own"),
    ("Gearbox", {"generator_interface": 1, "generator_inertia": -3.0},
     "invalid parameter generator_inertia = -3.0: expected > 0"),
    ("Gearbox", {"omega_rotor": math.inf}, "invalid parameter omega_rotor = inf: expected a finite real number"),
    ("GeneratorRotor", {"inertia": 0.0}, "invalid parameter inertia = 0.0: expected > 0"),
    ("GeneratorRotor", {"event3.kind": 1, "event3.duration": -1.0}, "invalid parameter event3.duration = -1.0: expected > 0"),
    ("GeneratorRotor", {"event1.kind": 2, "event1.duration": math.inf}, "invalid parameter event1.duration = inf"),
    ("GeneratorRotor", {"event4.kind": 9}, "invalid parameter event4.kind = 9: expected 0 = none, 1 = torque_step"),
    ("GeneratorRotor", {"initial_speed": math.nan}, "invalid parameter initial_speed = nan"),
])
def test_bad_parameter_fails_initialisation_with_its_name(fmu_path, name, values, message):
    inst = Instance(fmu_path(name), "bad")
    inst.enter(**values)
    with pytest.raises(FMICallException, match="fmi2ExitInitializationMode failed") as failure:
        inst.fmu.exitInitializationMode()
    assert failure.value.status >= FMI_ERROR
    assert any(message in m for m in inst.error_messages()), inst.messages
    inst.free()


def test_bad_parameter_fails_already_when_an_output_is_read_in_initialisation_mode(fmu_path):
    inst = Instance(fmu_path("WindSource"), "bad")
    inst.enter(sigma=-1.0)
    with pytest.raises(FMICallException, match="fmi2GetReal failed"):
        inst.get("omega")
    assert any("getReal: invalid parameter sigma = -1.0" in m for m in inst.error_messages())
    inst.free()


def test_outputs_follow_parameters_and_inputs_in_initialisation_mode(fmu_path):
    wind = Instance(fmu_path("WindSource"), "wind")
    wind.enter(omega0=2.0, sigma=1e-9)
    assert wind.get("omega")[0] == pytest.approx(2.0, abs=1e-6)
    gearbox = Instance(fmu_path("Gearbox"), "gearbox")
    gearbox.enter(omega_rotor=1.5)
    assert gearbox.get("omega_out")[0] == pytest.approx(RATIO * 1.5, rel=1e-12)
    gearbox.set(omega_rotor=2.0, **{"stage3.driven_radius": 0.1})  # parameters count too (ratio 1 for stage 3)
    assert gearbox.get("omega_out")[0] == pytest.approx(RATIO / 1.25 * 2.0, rel=1e-12)
    generator = Instance(fmu_path("GeneratorRotor"), "generator")
    generator.enter(initial_speed=123.0)
    assert generator.get("omega")[0] == 123.0
    for inst in (wind, gearbox, generator):
        inst.fmu.exitInitializationMode()
        inst.free()


def test_solver_failure_discards_the_step_and_keeps_the_state(fmu_path):
    inst = Instance(fmu_path("Gearbox"), "g")
    inst.initialize(**{"solver.max_steps": 2}, **gearbox_motion(0.0, RATIO))
    before = inst.real_outputs()
    jump = gearbox_motion(1e-3, RATIO)
    jump["phi_gen"] += 0.5  # a generator angle jump the integrator cannot take in 2 internal steps
    inst.set(**jump)
    with pytest.raises(FMICallException) as failure:
        inst.step(0.0, 1e-3)
    assert failure.value.status == DISCARD
    assert any("doStep from t = 0 s, h = 0.001 s failed: more than 2 steps" in m for m in inst.error_messages())
    assert inst.real_outputs() == before
    inst.free()


#: the Gearbox's interface model with the rotor's derivative inputs (paper-60s)
INTERFACE_MODEL = {"generator_interface": 1, "rotor_derivatives": True}


@pytest.mark.parametrize("name, parameters, bad_input", [
    ("Gearbox", {}, {"omega_rotor": math.nan}),
    ("Gearbox", INTERFACE_MODEL, {"counter_torque": math.nan}),
    ("Gearbox", INTERFACE_MODEL, {"jerk_rotor": math.inf}),
    ("GeneratorRotor", {}, {"shaft_torque": math.inf}),
])
def test_non_finite_input_discards_the_step_and_the_next_step_is_unaffected(fmu_path, name, parameters, bad_input):
    def good_inputs(t):
        if name != "Gearbox":
            return {"shaft_torque": 2.0e4}
        extra = {"counter_torque": 2.54e4, "alpha_rotor": 0.0, "jerk_rotor": 0.0} if parameters else {}
        return {**gearbox_motion(t, RATIO), **extra}

    inst, clean = Instance(fmu_path(name), "hit"), Instance(fmu_path(name), "clean")
    for i in (inst, clean):
        i.initialize(**parameters, **good_inputs(0.0))
    inst.set(**bad_input)
    with pytest.raises(FMICallException) as failure:
        inst.step(0.0, 1e-3)
    assert failure.value.status == DISCARD
    assert any("non-finite input" in m for m in inst.error_messages())
    for i in (inst, clean):
        i.set(**good_inputs(0.0))
        i.step(0.0, 1e-3)
    assert inst.real_outputs() == clean.real_outputs()
    inst.free()
    clean.free()


def test_host_misuse_is_reported(fmu_path):
    inst = Instance(fmu_path("GeneratorRotor"), "g")
    inst.enter()
    with pytest.raises(FMICallException, match="fmi2DoStep failed with status 2"):
        inst.step(0.0, 1e-3)  # before exitInitializationMode
    assert any("call exitInitializationMode first" in m for m in inst.error_messages())
    inst.fmu.exitInitializationMode()
    inst.set(inertia=1.0)  # fixed parameter after initialisation: ignored with a warning
    assert inst.get("inertia") == [151.0]
    assert any(s == 1 and "inertia is fixed after initialisation" in m for s, m in inst.messages)
    with pytest.raises(FMICallException) as failure:
        inst.set(omega=1.0)
    assert failure.value.status == FMI_ERROR
    assert any("setReal: TypeError: omega is an output and cannot be set" in m for m in inst.error_messages())
    inst.free()


def test_corrupt_serialised_state_is_refused(fmu_path):
    inst = Instance(fmu_path("Gearbox"), "g")
    inst.initialize()
    state = inst.fmu.deSerializeFMUstate(b"not json")
    with pytest.raises(FMICallException, match="fmi2SetFMUstate failed"):
        inst.fmu.setFMUstate(state)
    assert any("setFMUstate: ValueError: not a Gearbox FMU state" in m for m in inst.error_messages())
    inst.free()


FAILING_HOST = textwrap.dedent('''
    import sys
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    path, n = sys.argv[1], int(sys.argv[2])
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(path)
    failures = 0
    for i in range(n + 1):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="Gearbox", instanceName=f"i{i}")
        fmu.instantiate(loggingOn=False)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        if i < n:
            fmu.setReal([vr["stage1.sun_mass"]], [-1.0])
        try:
            fmu.exitInitializationMode()
            fmu.doStep(0.0, 1e-3)
            print("good instance stepped", fmu.getReal([vr["omega_out"]]))
        except Exception:
            failures += 1
        fmu.freeInstance()
    print("failures", failures)
''')


def _upstream_exit_race(result) -> bool:
    """The known pythonfmu shutdown race: SIGABRT with glibc's heap message, after the host's last line."""
    return (result.returncode == -6 and "failures " in result.stdout
            and ("corrupted double-linked list" in result.stderr or "double free" in result.stderr))


@pytest.mark.slow
def test_host_survives_many_failed_instances_and_sees_the_message_without_logging(fmu_path, tmp_path, this_python):
    script = tmp_path / "failing_host.py"
    script.write_text(FAILING_HOST)
    result = run_python(this_python, str(script), str(fmu_path("Gearbox")), "12")
    if _upstream_exit_race(result):
        # pythonfmu 0.7's library destructor can tear down its Python thread state while the
        # interpreter shuts down (glibc "corrupted double-linked list", SIGABRT after all output);
        # seen in well under 1 of 30 runs here and not ours to fix: one retry, a repeat fails
        result = run_python(this_python, str(script), str(fmu_path("Gearbox")), "12")
    assert result.returncode == 0, f"exit code {result.returncode}; stdout {result.stdout[-500:]!r}; stderr {result.stderr[-1500:]}"
    assert "failures 12" in result.stdout and "good instance stepped" in result.stdout
    # loggingOn = false: pythonfmu drops logger messages, the slave echoes errors to stderr
    assert result.stderr.count("invalid parameter stage1.sun_mass = -1.0: expected > 0") == 12


@pytest.mark.parametrize("code, stdout, stderr, known", [
    (-6, "good instance stepped\nfailures 12\n", "corrupted double-linked list\n", True),
    (-6, "", "corrupted double-linked list\n", False),  # before the host finished: a real crash
    (-11, "failures 12\n", "corrupted double-linked list\n", False),  # another signal
    (-6, "failures 12\n", "Fatal Python error: ...\n", False),  # another abort
    (0, "failures 12\n", "", False),
])
def test_only_the_known_upstream_exit_race_is_retried(code, stdout, stderr, known):
    import subprocess

    assert _upstream_exit_race(subprocess.CompletedProcess([], code, stdout, stderr)) is known
