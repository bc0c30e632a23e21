"""The Gauss-Seidel order follows the FMUs' declared direct dependencies (issue 30.4).

A pass-through FMU (an output that depends directly on an input) between two others must be
stepped before the consumer of its output, or the consumer receives the previous step's value:
the Modelica Reference-FMU ``Feedthrough`` between ``wind.omega`` and ``gearbox.omega_rotor``
changed the stage-1 force std by 5.3 % with the receivers-first order. Every one-step delay
an order still puts on a connection is said, with the connection and why.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from orchestrator.cosim.coupling_delays import FEEDTHROUGH, LOOP, coupling_delays
from orchestrator.cosim.graph import dependency_order, stepping_order
from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import load_scenario
from tests.helpers.reference_fmus import reference_fmu

#: W (a source) -> F (a pass-through: F.y depends directly on F.u) -> C
CHAIN = [("W.y", "F.u"), ("F.y", "C.u")]
PASS_F = {"F.u": ["F.y"]}


def test_a_pass_through_is_stepped_before_its_consumer():
    # receivers first (the order without dependencies) would step C before F: C got F's previous output
    assert stepping_order(["W", "F", "C"], [("W", "F"), ("F", "C")]) == ["C", "F", "W"]
    assert dependency_order(["W", "F", "C"], CHAIN, PASS_F) == ["F", "C", "W"]


def test_a_chain_of_pass_throughs_keeps_the_data_flow_order():
    connections = [("W.y", "F1.u"), ("F1.y", "F2.u"), ("F2.y", "C.u")]
    feedthrough = {"F1.u": ["F1.y"], "F2.u": ["F2.y"]}
    order = dependency_order(["C", "F2", "F1", "W"], connections, feedthrough)
    assert order.index("F1") < order.index("F2") < order.index("C")
    assert order[-1] == "W"  # the source still steps after its receivers (its state outputs pass at t_k)


def test_without_direct_dependencies_the_order_is_the_receivers_first_one():
    connections = [("W.y", "G.u"), ("G.t", "H.u"), ("H.w", "G.w")]
    edges = [(o.split(".")[0], i.split(".")[0]) for o, i in connections]
    assert dependency_order(["W", "G", "H"], connections, {}) == stepping_order(["W", "G", "H"], edges)


def test_the_dependency_order_puts_no_delay_on_a_pass_through():
    order = dependency_order(["W", "F", "C"], CHAIN, PASS_F)
    assert coupling_delays(["W", "F", "C"], order, "gauss-seidel", CHAIN, PASS_F) == ()


def test_an_explicit_order_that_delays_a_pass_through_says_which_connection_and_why():
    (delay,) = coupling_delays(["W", "F", "C"], ["C", "F", "W"], "gauss-seidel", CHAIN, PASS_F, explicit=True,
                               default_order=["F", "C", "W"])
    assert delay.kind == FEEDTHROUGH and delay.connections == ("F.y -> C.u",)
    assert delay.received == "t_{k-1}"  # F's output of the previous step, computed from W's value of t_{k-1}
    assert "simulation.order steps F after C" in delay.note and "(F, C, W)" in delay.note


def test_jacobi_delays_every_pass_through_and_says_so():
    (delay,) = coupling_delays(["W", "F", "C"], ["F", "C", "W"], "jacobi", CHAIN, PASS_F)
    assert delay.kind == FEEDTHROUGH and "Jacobi" in delay.why and "--algorithm gauss-seidel" in delay.why


def test_a_feedback_loop_names_its_lagging_direction_once():
    connections = [("G.t", "H.u"), ("H.w", "G.w")]
    delays = coupling_delays(["G", "H"], ["G", "H"], "gauss-seidel", connections, {})
    assert [(d.kind, d.source, d.target, d.connections) for d in delays] == [(LOOP, "H", "G", ("H.w -> G.w",))]
    assert "deliberate" in delays[0].why


# ------------------------------------------------------------------ the paper's system with a pass-through
def _paper(fmu_dir: Path, tmp_path: Path, through: tuple[str, str, str] | None = None, order: str = "") -> Path:
    """``paper-60s`` over 4 s; with ``through = (fmu, input, output)`` that FMU between wind.omega and the gearbox."""
    text = (Path(__file__).parents[3] / "orchestrator" / "scenarios" / "paper-60s.toml").read_text()
    text = text.replace("stop = 60.0", "stop = 4.0").replace("window = [5.0, 60.0]", "window = [1.0, 4.0]")
    for name in ("WindSource", "Gearbox", "GeneratorRotor"):
        text = text.replace(f'"{name}.fmu"', f'"{(fmu_dir / (name + ".fmu")).as_posix()}"')
    if through is not None:
        fmu, inp, out = through
        text = text.replace('from = "wind.omega"\nto = "gearbox.omega_rotor"',
                            f'from = "wind.omega"\nto = "ft.{inp}"\n[[connections]]\nfrom = "ft.{out}"\n'
                            'to = "gearbox.omega_rotor"')
        gain = "[components.ft.parameters]\ngain = 1.0\n" if inp == "u" else ""  # the toy's default gain is 2
        text = text.replace("[components.generator]", f'[components.ft]\nfmu = "{fmu}"\n{gain}\n[components.generator]')
    if order:
        text = text.replace('extrapolation = "hold"', f'extrapolation = "hold"\norder = {order}')
    path = tmp_path / f"paper{'-ft' if through else ''}{'-ordered' if order else ''}.toml"
    path.write_text(text)
    return path


def _run(path: Path):
    system = resolve_system(load_scenario(path))
    return system, CoSimulation(system).run(handle_sigint=False)


@pytest.mark.slow
@pytest.mark.parametrize("through", ["reference", "toy"])
def test_a_pass_through_between_wind_and_gearbox_changes_nothing(fmu_dir, toy_dir, tmp_path, through):
    fmu = (reference_fmu("Feedthrough").as_posix(), "Float64_continuous_input", "Float64_continuous_output") \
        if through == "reference" else ((toy_dir / "ToyGain.fmu").as_posix(), "u", "y")  # y = gain u, gain 1
    _, plain = _run(_paper(fmu_dir, tmp_path))
    system, passed = _run(_paper(fmu_dir, tmp_path, fmu))
    assert system.order == ("ft", "gearbox", "generator", "wind")
    assert [(d.kind, d.source, d.target) for d in system.delays] == [(LOOP, "generator", "gearbox")]
    assert system.notes == ()  # the loop's explicit coupling is in the summary, not printed on every run
    assert plain.complete and passed.complete
    for name in ("gearbox.stage1.F_sp[1]", "gearbox.stage3.F_mesh", "generator.omega", "gearbox.shaft_torque"):
        a, b = plain.column(name), passed.column(name)
        np.testing.assert_allclose(b, a, rtol=0.0, atol=1e-9 * np.max(np.abs(a)))

    # the receivers-first order (what the master chose before) hands the gearbox the previous step's speed
    system, late = _run(_paper(fmu_dir, tmp_path, fmu, order='["gearbox", "generator", "ft", "wind"]'))
    (delay,) = [d for d in system.delays if d.kind == FEEDTHROUGH]
    assert delay.connections == ("ft." + fmu[2] + " -> gearbox.omega_rotor",)
    assert any("simulation.order steps ft after gearbox" in n for n in system.notes)
    a, b = plain.column("gearbox.stage1.F_sp[1]"), late.column("gearbox.stage1.F_sp[1]")
    assert np.max(np.abs(b - a)) > 1e-6 * np.max(np.abs(a))
