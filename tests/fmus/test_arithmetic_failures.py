"""Inside the FMUs: arithmetic failures become a solver discard or the parameter's message, never Python's text;
communication points that are not finite numbers are refused; published bounds equal the FMU's own checks."""

from __future__ import annotations

import math
import zipfile
from xml.etree import ElementTree as ET

import pytest
from fmpy.fmi1 import FMICallException

from components.model.presets import cosim_preset
from tests.helpers.fmu_hosts import FMI_ERROR, Instance, gearbox_motion

RATIO = cosim_preset("table6").ratio
DISCARD = 2


def test_a_singular_system_matrix_discards_the_step_with_a_plain_message(fmu_path):
    inst = Instance(fmu_path("Gearbox"), "stiff")
    inst.initialize(**{"shaft1.stiffness": 1e30, "start_at_rest": True}, **gearbox_motion(0.0, RATIO))  # singular
    inst.set(**gearbox_motion(1e-3, RATIO))
    with pytest.raises(FMICallException) as failure:
        inst.step(0.0, 1e-3)
    assert failure.value.status == DISCARD  # a solver failure, not fmi2Fatal
    errors = inst.error_messages()
    # numpy's LU reports the singular matrix; the compiled kernel's own elimination divides by its zero pivot
    assert any(m.startswith("doStep from t = 0 s, h = 0.001 s failed: ") and (
        "the model's equations have a singular matrix" in m or "a division by zero in the model" in m)
        for m in errors), errors
    assert not any("LinAlgError" in m or "Singular matrix" in m for m in errors)  # no Python exception text
    inst.free()


@pytest.mark.parametrize("t, h", [(math.nan, 1e-3), (0.0, math.nan), (math.inf, 1e-3), (0.0, -1e-3), (0.0, 0.0)])
@pytest.mark.parametrize("name", ["WindSource", "GeneratorRotor", "Gearbox"])
def test_a_communication_point_that_is_not_a_finite_number_is_refused(fmu_path, name, t, h):
    inst = Instance(fmu_path(name), "nan")
    inst.initialize(**(gearbox_motion(0.0, RATIO) if name == "Gearbox" else {}))
    before = inst.real_outputs()
    with pytest.raises(FMICallException) as failure:
        inst.step(t, h)
    assert failure.value.status == DISCARD
    assert any("doStep refused: communication point" in m and "must be finite numbers, the step > 0" in m
               for m in inst.error_messages())
    assert inst.real_outputs() == before
    inst.free()


@pytest.mark.parametrize("name, values, message", [
    ("GeneratorRotor", {"inertia": 5e-324}, "invalid parameter inertia = 5e-324: expected > 0 (within [1e-30, 1e+30])"),
    ("Gearbox", {"stage1.planet_mass": 1e308},
     "invalid parameter stage1.planet_mass = 1e+308: expected > 0 (within [1e-30, 1e+30])"),
    ("WindSource", {"n_harmonics": 2147483647},
     "invalid parameter n_harmonics = 2147483647: expected an integer within [1, 100000]"),
])
def test_magnitudes_that_would_overflow_the_model_fail_initialisation_with_the_parameter(fmu_path, name, values,
                                                                                          message):
    inst = Instance(fmu_path(name), "huge")
    inst.enter(**values)
    with pytest.raises(FMICallException) as failure:
        inst.fmu.exitInitializationMode()
    assert failure.value.status >= FMI_ERROR
    assert any(message in m for m in inst.error_messages()), inst.messages
    inst.free()


@pytest.mark.parametrize("name, variable, low, high", [
    ("Gearbox", "stage1.k0", "1e-30", "1e+30"),
    ("Gearbox", "stage2.exponent", "1.0", "3.0"),
    ("Gearbox", "shaft3.damping", "0.0", "1e+30"),
    ("WindSource", "n_harmonics", "1", "100000"),
    ("WindSource", "seed", "0", "2147483647"),
    ("GeneratorRotor", "event1.kind", "0", "3"),
])
def test_the_model_description_declares_the_bounds_the_fmu_checks(fmu_path, name, variable, low, high):
    with zipfile.ZipFile(fmu_path(name)) as archive:
        root = ET.fromstring(archive.read("modelDescription.xml"))
    node = next(v for v in root.iter("ScalarVariable") if v.get("name") == variable)
    typed = next(iter(node))
    assert (typed.get("min"), typed.get("max")) == (low, high)
    # just outside the declared range, the FMU itself refuses the value
    inst = Instance(fmu_path(name), "edge")
    below = float(low) - (1 if typed.tag == "Integer" else abs(float(low)) * 1e-9 + 1e-300)
    inst.enter(**{variable: int(below) if typed.tag == "Integer" else below})
    with pytest.raises(FMICallException):
        inst.fmu.exitInitializationMode()
    assert any(f"invalid parameter {variable}" in m for m in inst.error_messages())
    inst.free()
