"""A scenario's coupling under Jacobi (``[jacobi]``, issue 31.3): read, applied with the algorithm, refused with the key."""

from __future__ import annotations

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import SimulationOverrides
from orchestrator.inputs.scenario_file import find_scenario, load_scenario

PAPER = find_scenario("paper-60s")


def test_the_paper_scenario_declares_its_coupling_and_step_for_jacobi():
    scenario = load_scenario(PAPER)
    assert scenario.simulation.algorithm == "gauss-seidel" and scenario.jacobi.step_s == 0.02
    assert scenario.jacobi.describe() == ("gearbox.generator_interface = 2, generator.follow_gearbox = True, "
                                          "gearbox.omega_generator -> generator.omega_gearbox")
    coupled = scenario.for_algorithm("jacobi")
    assert coupled.jacobi is None and coupled.simulation.algorithm == "jacobi"
    assert coupled.component("gearbox").parameters["generator_interface"] == 2
    assert coupled.component("generator").parameters["follow_gearbox"] is True
    assert [str(c) for c in coupled.connections[len(scenario.connections):]] == \
        ["gearbox.omega_generator -> generator.omega_gearbox"]
    assert scenario.for_algorithm("gauss-seidel") == scenario.with_simulation(algorithm="gauss-seidel")


def test_the_command_line_algorithm_brings_the_coupling_and_a_step_given_wins():
    scenario = load_scenario(PAPER)
    coupled, _ = SimulationOverrides(algorithm="jacobi").apply(scenario)
    assert coupled.component("generator").parameters["follow_gearbox"] is True
    assert coupled.simulation.step_s == 0.02
    stepped, _ = SimulationOverrides(algorithm="jacobi", step_s=0.01).apply(scenario)
    assert stepped.simulation.step_s == 0.01 and stepped.component("gearbox").parameters["generator_interface"] == 2


def _variant(tmp_path, old: str, new: str):
    text = PAPER.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "variant.toml"
    path.write_text(text.replace(old, new).replace("WindSource.fmu", str(PAPER.parent / "x.fmu")))
    return path


def test_a_scenario_stepped_with_jacobi_is_coupled_so_from_the_start(tmp_path):
    scenario = load_scenario(_variant(tmp_path, 'algorithm = "gauss-seidel"', 'algorithm = "jacobi"'))
    assert scenario.jacobi is None and scenario.component("generator").parameters["follow_gearbox"] is True


@pytest.mark.parametrize("old, new, match", [
    ("[jacobi.parameters.generator]", "[jacobi.parameters.generatr]",
     r"jacobi \(components\).*generatr.*a declared component"),
    ('to = "generator.omega_gearbox"', 'to = "generator.shaft_torque"', r"jacobi \(connections\[\d+\]\.to\).*connected once"),
    ("step = 2.0e-2               # s, the largest", "step = 3.0e-2               # s, the largest",
     r"jacobi \(simulation.output_interval\).*whole multiple of the step 0.03"),
    ("step = 2.0e-2               # s, the largest", 'step = "fast"               # s, the largest', r"jacobi.step"),
])
def test_a_mistake_in_the_table_is_refused_naming_it(tmp_path, old, new, match):
    with pytest.raises(ScenarioError, match=match):
        load_scenario(_variant(tmp_path, old, new))
