"""The Gauss-Seidel order follows the declared direct dependencies, and the run names every one-step delay.

A pass-through FMU (an output that depends directly on an input) between a source and its consumer must
change nothing: stepped just before the consumer, it hands on what the source gave it in the same step.
Checked on hand-made graphs, with a toy pass-through of our own (declared ``dependencies``), and with the
Modelica Reference-FMU ``Feedthrough`` between the paper's wind and gearbox.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from orchestrator.commands import cli
from orchestrator.cosim.coupling_delays import coupling_delays
from orchestrator.cosim.graph import dependency_order, stepping_order
from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.provision.locate import resolve_fmu_paths
from tests.helpers.reference_fmus import reference_fmu

# the paper's system: the wind drives the gearbox, gearbox <-> generator is a feedback loop (state outputs only)
PAPER = ["wind.omega -> gearbox.omega_rotor", "wind.phi -> gearbox.phi_rotor", "generator.omega -> gearbox.omega_gen",
         "gearbox.shaft_torque -> generator.shaft_torque"]
# ... with a pass-through ft (ft.y = ft.u, declared) between wind.omega and gearbox.omega_rotor
WITH_FT = ["wind.omega -> ft.u", "ft.y -> gearbox.omega_rotor"] + PAPER[1:]
FT = {"ft.u": ["ft.y"]}


def pairs(links):
    return [tuple(link.split(" -> ")) for link in links]


def component_edges(links):
    return [(a.partition(".")[0], b.partition(".")[0]) for a, b in pairs(links)]


def test_without_direct_dependencies_the_order_is_receivers_first():
    comps = ["wind", "gearbox", "generator"]
    assert dependency_order(comps, pairs(PAPER), {}) == stepping_order(comps, component_edges(PAPER)) \
        == ["gearbox", "generator", "wind"]


@pytest.mark.parametrize("components", [["wind", "ft", "gearbox", "generator"], ["ft", "wind", "gearbox", "generator"],
                                        ["gearbox", "generator", "wind", "ft"]])
def test_a_pass_through_steps_just_before_its_consumer_wherever_it_is_declared(components):
    assert dependency_order(components, pairs(WITH_FT), FT) == ["ft", "gearbox", "generator", "wind"]


def test_an_unconnected_input_makes_no_pass_through():
    # ft.y depends on ft.u, but ft.u is a start value (constant): ft is an ordinary source
    links = pairs(["ft.y -> gearbox.omega_rotor", "generator.omega -> gearbox.omega_gen",
                   "gearbox.shaft_torque -> generator.shaft_torque"])
    assert dependency_order(["ft", "gearbox", "generator"], links, FT) == ["gearbox", "generator", "ft"]


def test_a_chain_of_pass_throughs_steps_in_the_direction_of_the_data():
    links = pairs(["src.y -> f1.u", "f1.y -> f2.u", "f2.y -> sink.u"])
    order = dependency_order(["f2", "sink", "f1", "src"], links, {"f1.u": ["f1.y"], "f2.u": ["f2.y"]})
    assert order == ["f1", "f2", "sink", "src"]
    assert coupling_delays(["f2", "sink", "f1", "src"], order, "gauss-seidel", links,
                           {"f1.u": ["f1.y"], "f2.u": ["f2.y"]}) == ()


def test_a_loop_through_a_pass_through_is_a_loop_of_its_ends():
    # generator.omega reaches the gearbox through ft: the loop gearbox <-> generator keeps its declaration order,
    # ft steps just before the gearbox and hands it the generator's speed of t_k, as a direct connection would
    links = pairs(["generator.omega -> ft.u", "ft.y -> gearbox.omega_gen", "gearbox.shaft_torque -> generator.shaft_torque"])
    for comps in (["gearbox", "generator", "ft"], ["ft", "gearbox", "generator"]):
        assert dependency_order(comps, links, FT) == ["ft", "gearbox", "generator"]
    # and the forward direction through ft: the generator gets the gearbox's new torque, as directly
    links = pairs(["generator.omega -> gearbox.omega_gen", "gearbox.shaft_torque -> ft.u", "ft.y -> generator.shaft_torque"])
    assert dependency_order(["gearbox", "generator", "ft"], links, FT) == ["gearbox", "ft", "generator"]


def test_the_paper_loop_is_said_once_as_its_deliberate_delay():
    comps = ["wind", "gearbox", "generator"]
    links = pairs(PAPER + ["generator.phi -> gearbox.phi_gen"])
    (delay,) = coupling_delays(comps, dependency_order(comps, links, {}), "gauss-seidel", links, {})
    assert (delay.kind, delay.source, delay.target, delay.received) == ("loop", "generator", "gearbox", "t_k")
    assert delay.connections == ("generator.omega -> gearbox.omega_gen", "generator.phi -> gearbox.phi_gen")
    assert "feedback loop gearbox <-> generator" in delay.note and "not algebraic" in delay.note
    assert coupling_delays(comps, ["gearbox", "generator", "wind"], "jacobi", links, {}) == ()  # Jacobi has no order


@pytest.mark.parametrize("order, received", [(["gearbox", "generator", "ft", "wind"], "t_{k-1}"),
                                             (["wind", "gearbox", "generator", "ft"], "t_k")])
def test_an_explicit_order_that_steps_the_pass_through_late_is_named(order, received):
    comps = ["wind", "ft", "gearbox", "generator"]
    delays = coupling_delays(comps, order, "gauss-seidel", pairs(WITH_FT), FT, explicit=True,
                             default_order=dependency_order(comps, pairs(WITH_FT), FT))
    late = [d for d in delays if d.kind == "feedthrough"]
    assert [(d.source, d.target, d.connections, d.received) for d in late] == [
        ("ft", "gearbox", ("ft.y -> gearbox.omega_rotor",), received)]
    assert "simulation.order steps ft after gearbox" in late[0].why
    assert "(ft, gearbox, generator, wind)" in late[0].why  # the order that avoids it


def test_delays_add_up_along_a_chain_and_jacobi_delays_every_pass_through():
    links = pairs(["src.y -> f1.u", "f1.y -> f2.u", "f2.y -> sink.u"])
    ft = {"f1.u": ["f1.y"], "f2.u": ["f2.y"]}
    late = coupling_delays(["src", "f1", "f2", "sink"], ["sink", "f2", "f1", "src"], "gauss-seidel", links, ft,
                           explicit=True)
    assert [(d.source, d.received) for d in late] == [("f1", "t_{k-1}"), ("f2", "t_{k-2}")]
    jacobi = coupling_delays(["src", "f1", "f2", "sink"], ["f1", "f2", "sink", "src"], "jacobi", links, ft)
    assert [(d.source, d.received) for d in jacobi] == [("f1", "t_{k-1}"), ("f2", "t_{k-2}")]
    assert "Jacobi sets every input from the values of t_k" in jacobi[0].why


CHAIN = """
name = "pass"
[simulation]
stop = 3.0
step = 0.1
algorithm = "{algorithm}"
{order}
[components.src]
fmu = "ToySine.fmu"
[components.src.parameters]
frequency = 0.37
[components.int]
fmu = "ToyIntegrator.fmu"
{middle}
[record]
variables = ["src.y", "int.u_seen", "int.x"]
"""
DIRECT = '[[connections]]\nfrom = "src.y"\nto = "int.u"'
THROUGH = ('[components.pass]\nfmu = "ToyPass.fmu"\n[[connections]]\nfrom = "src.y"\nto = "pass.u"\n'
           '[[connections]]\nfrom = "pass.y"\nto = "int.u"')


def _toy_run(toy_scenario, middle, algorithm="gauss-seidel", order=""):
    system = resolve_system(load_scenario(toy_scenario(CHAIN.format(algorithm=algorithm, order=order, middle=middle))))
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete
    return system, outcome


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_our_own_pass_through_changes_nothing_in_the_default_order(toy_scenario, algorithm):
    _, direct = _toy_run(toy_scenario, DIRECT, algorithm)
    system, through = _toy_run(toy_scenario, THROUGH, algorithm)
    if algorithm == "gauss-seidel":
        assert system.order == ("pass", "int", "src") and system.delays == ()
        for name in ("src.y", "int.u_seen", "int.x"):
            np.testing.assert_array_equal(through.column(name), direct.column(name))
    else:  # Jacobi cannot pass it in the same step: the integrator gets the sine one step later, and is told so
        np.testing.assert_array_equal(through.column("int.u_seen")[2:], direct.column("int.u_seen")[1:-1])
        assert [(d.kind, d.connections, d.received) for d in system.delays] == [
            ("feedthrough", ("pass.y -> int.u",), "t_{k-1}")]


def test_an_explicit_late_order_delays_one_step_and_the_run_says_where(toy_scenario, capsys, tmp_path):
    _, direct = _toy_run(toy_scenario, DIRECT)
    order = 'order = ["int", "pass", "src"]'
    _, late = _toy_run(toy_scenario, THROUGH, order=order)
    # the integrator holds over step k the sine of t_{k-1}: the direct run's input one step later
    np.testing.assert_array_equal(late.column("int.u_seen")[2:], direct.column("int.u_seen")[1:-1])
    path = toy_scenario(CHAIN.format(algorithm="gauss-seidel", order=order, middle=THROUGH), "late.toml")
    assert cli.main(["run", str(path), "--out", str(tmp_path / "late"), "--no-plots", "-q"]) == 0
    err = capsys.readouterr().err
    assert "dtcosim run: note: one-step delay on pass.y -> int.u (values of t_{k-1})" in err
    assert "simulation.order steps pass after int" in err
    summary = json.loads((tmp_path / "late" / "summary.json").read_text())
    assert [(d["kind"], d["from"], d["to"], d["connections"], d["received"]) for d in summary["coupling_delays"]] == [
        ("feedthrough", "pass", "int", ["pass.y -> int.u"], "t_{k-1}")]
    assert any(n.startswith("one-step delay on pass.y -> int.u") for n in summary["notes"])


@pytest.mark.slow
def test_the_reference_feedthrough_between_wind_and_gearbox_changes_no_statistic(fmu_dir, tmp_path):
    """The issue's case: Feedthrough.fmu between wind.omega and gearbox.omega_rotor (5.3 % on the stage-1 force
    std when the gearbox was stepped before it); 3 s of the paper's scenario, statistics over [1, 3] s."""
    ft = reference_fmu("Feedthrough").as_posix()
    paper = find_scenario("paper-60s")
    text = paper.read_text().replace('[[connections]]\nfrom = "wind.omega"\nto = "gearbox.omega_rotor"',
                                     f'[components.ft]\nfmu = "{ft}"\n[[connections]]\nfrom = "wind.omega"\n'
                                     'to = "ft.Float64_continuous_input"\n[[connections]]\n'
                                     'from = "ft.Float64_continuous_output"\nto = "gearbox.omega_rotor"')
    assert "ft.Float64_continuous_output" in text
    runs = {}
    for name, source in (("direct", paper.read_text()), ("through", text),
                         ("late", text.replace('extrapolation = "hold"', 'extrapolation = "hold"\n'
                                               'order = ["gearbox", "generator", "ft", "wind"]'))):
        path = tmp_path / f"{name}.toml"
        path.write_text(source)
        sc = load_scenario(path).with_simulation(stop_s=3.0, window_s=(1.0, 3.0))
        system = resolve_system(sc, fmu_paths=resolve_fmu_paths(sc, fmu_dir))
        runs[name] = system, CoSimulation(system).run(handle_sigint=False)
    (_, direct), (system, through), (late_system, late) = runs["direct"], runs["through"], runs["late"]
    assert system.order == ("ft", "gearbox", "generator", "wind")
    assert [d.kind for d in system.delays] == ["loop"]  # only the gearbox <-> generator loop's deliberate one
    window = (through.time_s >= 1.0) & (through.time_s <= 3.0)
    for i, col in enumerate(direct.columns):
        a, b = direct.values[window, i], through.column(col.column)[window]
        for stat in (np.mean, np.std, np.min, np.max):
            assert stat(b) == pytest.approx(stat(a), rel=1e-9, abs=1e-12), (col.column, stat.__name__)
    # stepped after the gearbox, the pass-through hands it the rotor speed one step late: named, and visible
    assert [(d.source, d.target, d.received) for d in late_system.delays if d.kind == "feedthrough"] == [
        ("ft", "gearbox", "t_{k-1}")]
    j = [c.column for c in direct.columns].index("gearbox.stage1.F_sp[1]")
    assert abs(np.std(late.column("gearbox.stage1.F_sp[1]")[window]) / np.std(direct.values[window, j]) - 1) > 0.01
