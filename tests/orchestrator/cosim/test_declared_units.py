"""Scenario parameters and ``--set`` values with their units, converted to the unit each FMU declares."""

from __future__ import annotations

import math

import pytest

from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import apply_parameters, parse_assignment
from orchestrator.inputs.scenario_file import find_scenario, load_scenario, scenario_from_dict


@pytest.fixture(scope="module")
def paper(fmu_dir):
    """``paper(values) -> the resolved paper-60s system with the suite's FMUs``."""
    from orchestrator.provision.project_fmus import ensure_fmus

    base = load_scenario(find_scenario("paper-60s"))
    paths = ensure_fmus(base, fmu_dir, build=False)

    def resolve(values=None, scenario=None):
        return resolve_system(apply_parameters(scenario or base, values or {}), fmu_paths=paths)

    return resolve


#: (parameter, quantity, the SI number by hand)
QUANTITIES = [
    ("gearbox.stage1.backlash", "0.56 mm", 0.56e-3),
    ("generator.counter_torque", "25.4 kN m", 25.4e3),
    ("wind.omega0", "16 rpm", 16 * 2 * math.pi / 60),
    ("generator.inertia", "1.51e8 kg mm^2", 151.0),
    ("gearbox.stage2.k0", "5e5 N/mm^1.5", 5e5 * 1000**1.5),   # N/mm^1.5 -> N/m^1.5: x 1000^1.5
    ("gearbox.stage3.k0", "5e5 N/mm^e", 5e5 * 1000**1.5),     # ^e: the stage's exponent (1.5)
    ("gearbox.shaft3.stiffness", "1e5 N mm/deg", 1e5 * 1e-3 * 180 / math.pi),  # Table 6's shaft 3
    ("gearbox.stage1.lambda", "600 1/mm", 6e5),
    ("gearbox.stage1.pressure_angle", "20 deg", math.radians(20)),
]


@pytest.mark.parametrize("name, text, si", QUANTITIES, ids=[q[0] for q in QUANTITIES])
def test_a_quantity_with_its_unit_is_the_si_number_the_fmu_declares(paper, name, text, si):
    comp, param = name.split(".", 1)
    value = paper({name: text}).scenario.component(comp).parameters[param]
    assert value == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize("name, text", [(q[0], q[1]) for q in QUANTITIES[:4]])
def test_set_on_the_command_line_takes_the_same_quantities(paper, name, text):
    key, value = parse_assignment(f"{name}={text}")
    comp, param = key.split(".", 1)
    assert value == text
    assert paper({key: value}).scenario.component(comp).parameters[param] == \
        paper({name: text}).scenario.component(comp).parameters[param]


def test_the_exponent_of_k0_is_the_scenarios_value_of_that_stages_exponent(paper):
    values = {"gearbox.stage1.exponent": 1.0, "gearbox.stage1.k0": "8e5 N/mm"}  # 16 N/(mm um) over 50 mm: plausible
    assert paper(values).scenario.component("gearbox").parameters["stage1.k0"] == pytest.approx(8e8)
    with pytest.raises(ScenarioError, match=r"stage1\.k0 = '2e5 N/mm\^1\.5': expected a quantity of dimension "
                                            r"\[mass\] \[time\]\^-2 \(SI unit N/m\^e\); the unit 'N/mm\^1\.5' is "
                                            r"\[mass\] \[length\]\^-0\.5 \[time\]\^-2"):
        paper({"gearbox.stage1.exponent": 1.0, "gearbox.stage1.k0": "2e5 N/mm^1.5"})


@pytest.mark.parametrize("name, text, expected", [
    ("gearbox.stage1.backlash", "0.56 N", r"\[length\] \(SI unit m\); the unit 'N' is \[mass\] \[length\] \[time\]\^-2"),
    ("gearbox.shaft3.stiffness", "5.7 kN m", r"\[angle\]\^-1 \(SI unit N\.m/rad\); the unit 'kN m' is"),
    ("wind.omega0", "0.27 Hz", r"\[time\]\^-1 \[angle\] \(SI unit rad/s\); the unit 'Hz' is \[time\]\^-1"),
    ("generator.inertia", "151 kg", r"\[mass\] \[length\]\^2 \(SI unit kg\.m2\); the unit 'kg' is \[mass\]"),
    ("gearbox.stage1.backlash", "0.56 blorps", r"a unit dtcosim knows \('blorps' is none"),
])
def test_a_unit_of_another_dimension_names_the_key_the_unit_and_the_expected_dimension(paper, name, text,
                                                                                         expected):
    comp, param = name.split(".", 1)
    with pytest.raises(ScenarioError, match=rf"components\.{comp}\.parameters\.{re_escape(param)} = '{text}': "
                                            rf"expected .*{expected}"):
        paper({name: text})


def re_escape(text: str) -> str:
    import re

    return re.escape(text)


def test_a_scenario_file_takes_quantities_in_its_parameter_tables(paper, tmp_path):
    import tomllib

    doc = tomllib.loads(find_scenario("paper-60s").read_text())
    doc["components"]["gearbox"].setdefault("parameters", {})["stage1"] = {"backlash": "0.56 mm"}
    doc["components"]["generator"].setdefault("parameters", {})["counter_torque"] = "25.4 kN m"
    scenario = scenario_from_dict(doc, name="q", base_dir=find_scenario("paper-60s").parent, source="q.toml")
    system = paper(scenario=scenario)
    assert system.scenario.component("gearbox").parameters["stage1.backlash"] == pytest.approx(5.6e-4)
    assert system.scenario.component("generator").parameters["counter_torque"] == pytest.approx(25.4e3)
