"""Scenario validation: every bad scenario gives one clear error naming the key, before any FMU is instantiated."""

from __future__ import annotations

import re

import pytest

from orchestrator.commands import cli
from orchestrator.cosim.fmi_runtime import FmuInstance
from orchestrator.cosim.graph import (
    find_algebraic_loop,
    initialization_order,
    stepping_order,
)
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import AlgebraicLoopError, ScenarioError
from orchestrator.inputs.scenario_file import load_scenario
from tests.helpers.scenarios import TOY_SCENARIO


def _replace(old: str, new: str):
    def edit(text: str) -> str:
        assert old in text, old
        return text.replace(old, new, 1)
    return edit


def _append(extra: str):
    return lambda text: text + extra


def _prepend(extra: str):
    """Top-level keys must come before the first table header."""
    return lambda text: extra + text


BAD = {
    "unknown top-level key": (_prepend('foo = 1\n'), "foo"),
    "unknown simulation key": (_replace("step = 0.01", "step = 0.01\nstepsize = 0.01"), "simulation.stepsize"),
    "unknown component key": (_replace('fmu = "ToySine.fmu"', 'fmu = "ToySine.fmu"\nfmu_path = "x"'), "components.src.fmu_path"),
    "missing FMU file": (_replace('fmu = "ToySine.fmu"', 'fmu = "Missing.fmu"'), "components.src.fmu"),
    "unknown variable in a connection": (_replace('from = "src.y"', 'from = "src.yy"'), "connections[0].from"),
    "unknown component in a connection": (_replace('from = "src.y"', 'from = "nosuch.y"'), "connections[0].from"),
    "connection into an output": (_replace('to = "int.u"', 'to = "int.x"'), "connections[0].to"),
    "input connected twice": (_append('\n[[connections]]\nfrom = "fail.y"\nto = "int.u"\n'), "connections[1].to"),
    "step zero": (_replace("step = 0.01", "step = 0.0"), "simulation.step"),
    "step negative": (_replace("step = 0.01", "step = -0.01"), "simulation.step"),
    "stop equal to start": (_replace("stop = 0.1", "stop = 0.0"), "simulation.stop"),
    "stop before start": (_replace("stop = 0.1", "stop = 0.1\nstart = 0.5"), "simulation.stop"),
    "step of wrong type": (_replace("step = 0.01", 'step = "10 ms"'), "simulation.step"),
    "stop of wrong type": (_replace("stop = 0.1", "stop = true"), "simulation.stop"),
    "Real parameter of wrong type": (_replace("amplitude = 2.0", 'amplitude = "big"'), "components.src.parameters.amplitude"),
    "Integer parameter given a float": (_replace("mode = 0", "mode = 1.5"), "components.fail.parameters.mode"),
    "unknown parameter": (_replace("amplitude = 2.0", "amplitud = 2.0"), "components.src.parameters.amplitud"),
    "record pattern matching nothing": (_replace('"src.y", "int.x"', '"src.nothing*", "int.x"'), "record.variables[0]"),
    "output interval not a multiple of the step": (_replace("step = 0.01", "step = 0.01\noutput_interval = 0.015"), "simulation.output_interval"),
    "window outside the run": (_replace("step = 0.01", "step = 0.01\nwindow = [0.0, 5.0]"), "simulation.window"),
    "unknown algorithm": (_replace("step = 0.01", 'step = 0.01\nalgorithm = "newton"'), "simulation.algorithm"),
    "connections not an array of tables": (
        lambda text: "connections = 3\n" + text.replace('[[connections]]\nfrom = "src.y"\nto = "int.u"', ""), "connections"),
    "initial binding onto a connected input": (_append('\n[[initial]]\nfrom = "fail.y"\nto = "int.u"\n'), "initial[0].to"),
    "TOML syntax error": (_append("\n[simulation\n"), "(syntax)"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_scenario_names_the_key(case, toy_scenario):
    edit, key = BAD[case]
    path = toy_scenario(edit(TOY_SCENARIO))
    with pytest.raises(ScenarioError, match=re.escape(key)) as info:
        resolve_system(load_scenario(path))
    assert info.value.key == key
    assert "expected" in str(info.value)


@pytest.mark.parametrize("case", ["missing FMU file", "unknown variable in a connection", "input connected twice",
                                  "step zero", "Integer parameter given a float", "stop of wrong type"])
def test_cli_reports_bad_scenario_before_instantiating(case, toy_scenario, monkeypatch, capsys, tmp_path):
    instantiated = []
    monkeypatch.setattr(FmuInstance, "instantiate", lambda self, *a: instantiated.append(self.name))
    edit, key = BAD[case]
    path = toy_scenario(edit(TOY_SCENARIO))
    code = cli.main(["run", str(path), "--out", str(tmp_path / "out"), "--no-build", "-q"])
    err = capsys.readouterr().err
    assert code == 1
    assert key in err and "invalid scenario entry" in err
    assert err.count("error:") == 1
    assert instantiated == []
    assert not (tmp_path / "out").exists()


def test_valid_toy_scenario_resolves(toy_scenario):
    system = resolve_system(load_scenario(toy_scenario()))
    assert [r.column for r in system.recorded] == ["src.y", "int.x", "int.u_seen", "int.t_seen"]
    assert system.order == ("int", "src", "fail")  # receivers before their sources
    assert system.init_order == ("src", "int", "fail")  # sources first


def test_parameters_as_nested_tables_become_dotted_names(toy_scenario):
    text = TOY_SCENARIO.replace("[components.src.parameters]\namplitude = 2.0",
                                "[components.src.parameters]\nnested = { deeper = 1.0 }\n\"quoted.name\" = 2")
    sc = load_scenario(toy_scenario(text))
    assert dict(sc.component("src").parameters) == {"nested.deeper": 1.0, "quoted.name": 2}


def test_algebraic_loop_is_detected_with_the_cycle(toy_scenario):
    text = """
name = "loop"
[simulation]
stop = 0.1
step = 0.01
[components.a]
fmu = "ToyGain.fmu"
[components.b]
fmu = "ToyGain.fmu"
[[connections]]
from = "a.y"
to = "b.u"
[[connections]]
from = "b.y"
to = "a.u"
"""
    with pytest.raises(AlgebraicLoopError, match="algebraic loop") as info:
        resolve_system(load_scenario(toy_scenario(text)))
    assert info.value.key == "connections"
    cycle = info.value.cycle
    assert cycle[0] == cycle[-1] and set(cycle) == {"a.y", "b.u", "b.y", "a.u"}
    assert "a.u -> a.y -> b.u -> b.y -> a.u" in str(info.value)


def test_loop_through_a_state_output_is_not_algebraic(toy_scenario):
    text = """
name = "ok-loop"
[simulation]
stop = 0.1
step = 0.01
[components.gain]
fmu = "ToyGain.fmu"
[components.int]
fmu = "ToyIntegrator.fmu"
[[connections]]
from = "gain.y"
to = "int.u"
[[connections]]
from = "int.x"
to = "gain.u"
"""
    system = resolve_system(load_scenario(toy_scenario(text)))
    assert system.order == ("gain", "int")


def test_graph_orders():
    comps = ["wind", "gearbox", "generator"]
    edges = [("wind", "gearbox"), ("generator", "gearbox"), ("gearbox", "generator")]
    assert stepping_order(comps, edges) == ["gearbox", "generator", "wind"]
    assert initialization_order(comps, edges + [("gearbox", "generator")]) == ["wind", "gearbox", "generator"]
    # a chain a -> b -> c: receivers first for stepping, sources first for initialisation
    chain = [("a", "b"), ("b", "c")]
    assert stepping_order(["a", "b", "c"], chain) == ["c", "b", "a"]
    assert initialization_order(["a", "b", "c"], chain) == ["a", "b", "c"]
    assert find_algebraic_loop([("a.y", "b.u")], {"b.u": ["b.y"]}) is None
    assert find_algebraic_loop([("a.y", "b.u"), ("b.y", "a.u")], {"b.u": ["b.y"], "a.u": ["a.y"]}) is not None


def test_cli_check_validates_without_instantiating(toy_scenario, monkeypatch, capsys, tmp_path):
    instantiated = []
    monkeypatch.setattr(FmuInstance, "instantiate", lambda self, *a: instantiated.append(self.name))
    assert cli.main(["run", str(toy_scenario()), "--check", "--out", str(tmp_path / "o")]) == 0
    assert "toy: valid (3 FMUs, 1 connections, 4 recorded variables" in capsys.readouterr().out
    assert instantiated == [] and not (tmp_path / "o").exists()


def test_scenario_pickles_with_plain_pickle():
    """A Scenario crosses process boundaries (multiprocessing, Dask) with the standard pickle."""
    import pickle

    from orchestrator.inputs.scenario_file import packaged_scenarios

    scenario = load_scenario(packaged_scenarios()["grid-fault"])
    clone = pickle.loads(pickle.dumps(scenario))
    assert clone == scenario
    gen = next(c for c in clone.components if c.name == "generator")
    with pytest.raises(TypeError):
        gen.parameters["inertia"] = 1.0  # still read-only after the round trip
