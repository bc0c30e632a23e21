"""Algebraic loops solved by fixed-point iteration at every communication point (``algebraic_loops = "iterate"``).

Two Reference-FMU Feedthrough instances (``Float64_continuous_output`` depends
directly on ``Float64_continuous_input``) closed into a loop by two SSP
LinearTransformations ``u = f * y + c``. By hand: both outputs equal the fixed
point ``y = f (f y + c) + c``, i.e. ``y = c (1 + f) / (1 - f^2) = c / (1 - f)``
(``f = 0.5, c = 1``: y = 2); the Gauss-Seidel sweeps contract by ``f^2`` per
sweep, so they need about ``log(tol) / log(f^2)`` sweeps; for ``|f| >= 1`` they
diverge.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import AlgebraicLoopError, InitializationError, ScenarioError
from orchestrator.inputs.scenario import SimulationSettings
from orchestrator.interop.ssp import import_ssp
from orchestrator.interop.ssp_export import export_ssp
from tests.helpers.ssp_documents import feedthrough, real, ssd, write_ssp

PORTS = real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")
LOOP = """
  <ssd:System name="loop">
    <ssd:Elements>{a}{b}
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="Float64_continuous_output" endElement="b"
                      endConnector="Float64_continuous_input"><ssc:LinearTransformation factor="{f}" offset="{c}"/></ssd:Connection>
      <ssd:Connection startElement="b" startConnector="Float64_continuous_output" endElement="a"
                      endConnector="Float64_continuous_input"><ssc:LinearTransformation factor="{f}" offset="{c}"/></ssd:Connection>
    </ssd:Connections>
  </ssd:System>"""


def loop_scenario(tmp_path, f: float = 0.5, c: float = 1.0, **simulation):
    folder = write_ssp(tmp_path / "loop", ssd(LOOP.format(a=feedthrough("a", PORTS), b=feedthrough("b", PORTS),
                                                          f=f, c=c)))
    scenario = import_ssp(folder)
    return scenario.with_simulation(**simulation) if simulation else scenario


def test_without_iteration_the_loop_is_refused_saying_how_to_iterate_it(tmp_path):
    with pytest.raises(AlgebraicLoopError, match=r'a\.Float64_continuous_output -> b\.Float64_continuous_input.*'
                                                 r'\[simulation\] algebraic_loops = "iterate"'):
        resolve_system(loop_scenario(tmp_path))


@pytest.mark.parametrize("f, c", [(0.5, 1.0), (-0.8, 3.0), (0.0, 2.5)])
def test_the_iterated_loop_gives_the_hand_computed_fixed_point_at_every_sample(tmp_path, f, c):
    system = resolve_system(loop_scenario(tmp_path, f, c, algebraic_loops="iterate", loop_tolerance=1e-14))
    assert system.algebraic_loops == (("a", "b"),)
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    expected = c / (1.0 - f)
    for name in ("a.Float64_continuous_output", "b.Float64_continuous_output"):
        values = outcome.column(name)
        assert len(values) == 11  # t = 0 (after initialisation) ... 1 s
        np.testing.assert_allclose(values, expected, rtol=1e-13, atol=0, err_msg=name)


def test_the_sweeps_stop_at_the_tolerance_and_count_like_the_contraction(tmp_path):
    system = resolve_system(loop_scenario(tmp_path, 0.5, 1.0, algebraic_loops="iterate", loop_tolerance=1e-6))
    sim = CoSimulation(system, step_loop="python")
    outcome = sim.run(handle_sigint=False)
    assert outcome.complete, outcome.error
    values = outcome.column("a.Float64_continuous_output")
    assert np.all(np.abs(values - 2.0) <= 1e-5)  # within the tolerance's reach, not exact
    assert np.any(values != 2.0)


def test_a_loop_with_gain_above_one_stops_with_a_message_naming_it(tmp_path):
    system = resolve_system(loop_scenario(tmp_path, 2.0, 1.0, algebraic_loops="iterate", loop_max_iterations=30))
    with pytest.raises(InitializationError, match=r"initialisation did not reach a fixed point after 30 sweeps "
                                                  r"\(simulation\.loop_max_iterations; an algebraic loop converges "
                                                  r"only where its gain is below 1 in magnitude\); still changing: "
                                                  r"a\.Float64_continuous_input"):
        CoSimulation(system).run(handle_sigint=False)


@pytest.mark.parametrize("key, value, match", [
    ("algebraic_loops", "solve", r"simulation\.algebraic_loops = 'solve': expected one of refuse, iterate"),
    ("loop_tolerance", 0.0, r"simulation\.loop_tolerance = 0\.0: expected a number > 0 and < 1"),
    ("loop_max_iterations", 0, r"simulation\.loop_max_iterations = 0: expected a whole number from 1 to 10000"),
    ("loop_max_iterations", 2.5, r"simulation\.loop_max_iterations = 2\.5: expected a whole number"),
])
def test_bad_loop_settings_are_refused_naming_the_key(key, value, match):
    with pytest.raises(ScenarioError, match=match):
        SimulationSettings(stop_s=1.0, step_s=0.1, **{key: value})


def test_the_loop_settings_survive_ssp_export_and_import(tmp_path):
    scenario = loop_scenario(tmp_path, algebraic_loops="iterate", loop_tolerance=1e-12, loop_max_iterations=40)
    again = import_ssp(export_ssp(resolve_system(scenario), tmp_path / "loop.ssp"))
    assert (again.simulation.algebraic_loops, again.simulation.loop_tolerance,
            again.simulation.loop_max_iterations) == ("iterate", 1e-12, 40)
    outcome = CoSimulation(resolve_system(again)).run(handle_sigint=False)
    assert outcome.complete and math.isclose(outcome.column("b.Float64_continuous_output")[-1], 2.0, rel_tol=1e-11)


#: a sine drives a loop of two adders: y1 = g1 y2 + sin, y2 = g2 y1 (+ 0), so y1 = sin / (1 - g1 g2), y2 = g2 y1
ADDER_LOOP = """
[simulation]
stop = 0.5
step = 0.05
algebraic_loops = "iterate"
loop_tolerance = 1e-14
loop_max_iterations = {max_iterations}
[components.sine]
fmu = "ToySine.fmu"
[components.sine.parameters]
amplitude = 3.0
[components.a1]
fmu = "ToyAdder.fmu"
[components.a1.parameters]
gain = {g1}
[components.a2]
fmu = "ToyAdder.fmu"
[components.a2.parameters]
gain = {g2}
[[connections]]
from = "sine.y"
to = "a1.u2"
[[connections]]
from = "a2.y"
to = "a1.u1"
[[connections]]
from = "a1.y"
to = "a2.u1"
[record]
variables = ["sine.y", "a1.y", "a2.y"]
"""


@pytest.mark.parametrize("g1, g2", [(0.5, 0.5), (-1.5, 0.4)])
def test_a_driven_loop_follows_its_hand_computed_solution_at_every_communication_point(toy_scenario, g1, g2):
    from orchestrator.inputs.scenario_file import load_scenario

    system = resolve_system(load_scenario(toy_scenario(ADDER_LOOP.format(g1=g1, g2=g2, max_iterations=200))))
    assert system.algebraic_loops == (("a1", "a2"),)
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    s = outcome.column("sine.y")
    assert np.ptp(s) > 2.5  # the loop is driven (half a period of amplitude 3)
    np.testing.assert_allclose(outcome.column("a1.y"), s / (1.0 - g1 * g2), rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(outcome.column("a2.y"), g2 * s / (1.0 - g1 * g2), rtol=1e-12, atol=1e-13)


def test_a_loop_without_a_solution_stops_the_run_where_it_diverges_keeping_what_was_computed(toy_scenario):
    from orchestrator.inputs.scenario_file import load_scenario

    # g1 g2 = 1: y1 = y1 + sin has no solution once sin != 0 (at t = 0 it is 0, and everything converges)
    system = resolve_system(load_scenario(toy_scenario(ADDER_LOOP.format(g1=1.0, g2=1.0, max_iterations=25))))
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert not outcome.complete
    assert outcome.error.startswith("the algebraic loop through a1, a2 did not converge at t = 0.05 s: an input "
                                    "still moved by")
    assert "after 25 sweeps (simulation.loop_max_iterations" in outcome.error
    assert outcome.steps == 0 and list(outcome.time_s) == [0.0]  # the converged start is kept
    assert outcome.column("a1.y")[0] == 0.0
