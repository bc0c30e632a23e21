"""Integer, Boolean, String and Enumeration connections; the checks made before anything is instantiated."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import AlgebraicLoopError, ScenarioError
from orchestrator.inputs.scenario_file import load_scenario
from orchestrator.run.results import write_timeseries
from tests.helpers.reference_fmus import read_typed_timeseries, reference_fmu
from tests.helpers.scenarios import write_scenario

#: Feedthrough input -> output of each non-Real type, and a value different from the start value
TYPED = {"Integer": ("Int32_input", "Int32_output", 42),
         "Boolean": ("Boolean_input", "Boolean_output", True),
         "String": ("String_input", "String_output", 'he said "a, b"'),
         "Enumeration": ("Enumeration_input", "Enumeration_output", 2)}


def toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace('"', '\\"') + '"'
    return repr(value)


def feedthrough_pair(tmp_path, fmi_type: str, algorithm: str = "gauss-seidel", output_interval: float = 0.1) -> str:
    fmu = reference_fmu("Feedthrough").as_posix()
    inp, out, value = TYPED[fmi_type]
    return f"""
name = "pair"
[simulation]
stop = 1.0
step = 0.1
output_interval = {output_interval!r}
algorithm = "{algorithm}"
[components.a]
fmu = "{fmu}"
[components.a.parameters]
{inp} = {toml_value(value)}
[components.b]
fmu = "{fmu}"
[[connections]]
from = "a.{out}"
to = "b.{inp}"
[record]
variables = ["a.{out}", "b.{out}"]
"""


@pytest.mark.parametrize("fmi_type", list(TYPED))
@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_two_feedthroughs_pass_each_type_through_unchanged(fmi_type, algorithm, tmp_path):
    inp, out, value = TYPED[fmi_type]
    system = resolve_system(load_scenario(write_scenario(tmp_path, feedthrough_pair(tmp_path, fmi_type, algorithm))))
    assert [rv.type for rv in system.recorded] == [fmi_type, fmi_type]
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete and len(outcome.time_s) == 11
    for column in ("a." + out, "b." + out):
        samples = outcome.column(column)
        if fmi_type == "String":
            assert list(samples) == [value] * 11
        else:
            assert np.all(samples == float(value))
    tags, columns = read_typed_timeseries(write_timeseries(tmp_path / "t.csv", outcome))
    written = {"Integer": "42", "Boolean": "1", "String": value, "Enumeration": "2"}[fmi_type]
    assert columns["b." + out] == [written] * 11
    assert tags["b." + out] == {"Boolean": "Boolean 0/1", "String": "String"}.get(fmi_type, "-")
    if fmi_type == "String":  # quoted, inner quotes doubled
        assert '"he said ""a, b"""' in (tmp_path / "t.csv").read_text()


TYPED_CHAIN = """
name = "chain"
[simulation]
stop = 1.0
step = 0.1
output_interval = {interval}
algorithm = "{algorithm}"
[components.src]
fmu = "ToyTyped.fmu"
[components.a]
fmu = "{feedthrough}"
[components.b]
fmu = "{feedthrough}"
[[connections]]
from = "src.n"
to = "a.Int32_input"
[[connections]]
from = "src.odd"
to = "a.Boolean_input"
[[connections]]
from = "src.label"
to = "a.String_input"
[[connections]]
from = "a.Int32_output"
to = "b.Int32_input"
[[connections]]
from = "a.Boolean_output"
to = "b.Boolean_input"
[[connections]]
from = "a.String_output"
to = "b.String_input"
[[connections]]
from = "a.Enumeration_output"
to = "b.Enumeration_input"
[record]
variables = ["src.n", "src.odd", "src.label", "b.Int32_output", "b.Boolean_output", "b.String_output",
             "b.Enumeration_output"]
"""


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("interval", [0.1, 0.2])
def test_changing_values_of_every_type_travel_along_a_chain_in_the_python_loop(algorithm, interval, toy_scenario):
    text = TYPED_CHAIN.format(algorithm=algorithm, interval=interval,
                              feedthrough=reference_fmu("Feedthrough").as_posix())
    system = resolve_system(load_scenario(toy_scenario(text)))
    with pytest.raises(ValueError, match="cannot run this system: an FMU has Integer, Enumeration, Boolean or String"):
        CoSimulation(system, step_loop="compiled").run(handle_sigint=False)  # typed ports: the Python loop only
    # the plain loop and the profiled one (its FMI calls timed) record the same values
    runs = [CoSimulation(system, profile=profile).run(handle_sigint=False) for profile in (False, True)]
    for outcome in runs:
        assert outcome.complete
        n = outcome.column("src.n")
        stride = round(interval / 0.1)
        np.testing.assert_array_equal(n, stride * np.arange(len(n)))  # n counts the steps
        # src's state outputs reach a as the values of t_k (a is stepped before src). a and b pass their inputs
        # through (declared dependencies): Gauss-Seidel steps a before b, so b passes on what src gave a in the
        # same step (one step in all); Jacobi hands b a's outputs of the previous step (two); the values arrive
        # unchanged
        delay = 1 if algorithm == "gauss-seidel" else 2
        steps = n.astype(int)
        expected_n = np.maximum(steps - delay, 0)
        np.testing.assert_array_equal(outcome.column("b.Int32_output"), expected_n)
        np.testing.assert_array_equal(outcome.column("b.Boolean_output"), expected_n % 2)
        labels = [f'step {m}, "quoted", comma' if m else "step 0" for m in expected_n]
        assert list(outcome.column("b.String_output")) == labels
        np.testing.assert_array_equal(outcome.column("b.Enumeration_output"), 1.0)
    np.testing.assert_array_equal(runs[0].values, runs[1].values)
    assert all(list(runs[0].text[k]) == list(runs[1].text[k]) for k in runs[0].text)
    # the run says where the order delays (Jacobi: a -> b), and nowhere else
    assert [(d.kind, d.source, d.target, d.received) for d in system.delays] == (
        [] if algorithm == "gauss-seidel" else [("feedthrough", "a", "b", "t_{k-1}")])


def test_a_connection_between_different_types_names_both(tmp_path):
    text = feedthrough_pair(tmp_path, "Integer").replace('to = "b.Int32_input"', 'to = "b.Boolean_input"')
    with pytest.raises(ScenarioError, match=r"connections\[0\].*Int32_output is Integer, Boolean_input is Boolean"):
        resolve_system(load_scenario(write_scenario(tmp_path, text)))


def test_a_start_value_where_fmi_forbids_one_states_the_rule(tmp_path):
    fmu = reference_fmu("BouncingBall").as_posix()
    text = f"""
[simulation]
stop = 1.0
step = 0.01
[components.ball]
fmu = "{fmu}"
[components.ball.parameters]
"der(h)" = 1.0
"""
    with pytest.raises(ScenarioError, match=r'components\.ball\.parameters\.der\(h\).*initial calculated.*'
                                            r'FMI 2\.0 allows a start value.*initial="exact" or initial="approx"'):
        resolve_system(load_scenario(write_scenario(tmp_path, text)))
    constant = text.replace('"der(h)" = 1.0', "v_min = 0.2")
    with pytest.raises(ScenarioError, match=r"v_min has causality local, variability constant"):
        resolve_system(load_scenario(write_scenario(tmp_path, constant)))


def test_an_fmu_without_a_binary_for_this_platform_is_refused_naming_what_it_has(tmp_path):
    original = reference_fmu("Dahlquist")
    foreign = tmp_path / "Dahlquist.fmu"
    with zipfile.ZipFile(original) as zin, zipfile.ZipFile(foreign, "w") as zout:
        for item in zin.infolist():
            name = item.filename.replace("binaries/linux64/Dahlquist.so", "binaries/win64/Dahlquist.dll")
            zout.writestr(name, zin.read(item.filename))
    text = '[simulation]\nstop = 1.0\nstep = 0.1\n[components.d]\nfmu = "Dahlquist.fmu"\n'
    with pytest.raises(ScenarioError, match=r"components\.d\.fmu.*binary for this platform \(linux64: "
                                            r"binaries/linux64/Dahlquist\.so\); it has binaries for: win64"):
        resolve_system(load_scenario(write_scenario(tmp_path, text)))


GAIN_LOOP = """
[simulation]
stop = 0.1
step = 0.01
[components.g1]
fmu = "ToyGain.fmu"
{declaration}
[components.g2]
fmu = "ToyGain.fmu"
[[connections]]
from = "g1.y"
to = "g2.u"
[[connections]]
from = "g2.y"
to = "g1.u"
"""


def test_a_loop_through_fmus_that_omit_dependencies_is_refused_saying_how_to_declare_it(toy_scenario):
    with pytest.raises(AlgebraicLoopError, match=r'g1\.y, g2\.y have no declared dependencies.*'
                                                 r'\[components\.g1\] no_feedthrough = \["y"\]'):
        resolve_system(load_scenario(toy_scenario(GAIN_LOOP.format(declaration=""))))
    declared = resolve_system(load_scenario(toy_scenario(GAIN_LOOP.format(declaration='no_feedthrough = ["y"]'))))
    assert CoSimulation(declared).run(handle_sigint=False).complete


def test_no_feedthrough_must_name_an_output_without_declared_dependencies(toy_scenario, tmp_path):
    with pytest.raises(ScenarioError, match=r"components\.g1\.no_feedthrough\[0\] = 'x'.*an output of"):
        resolve_system(load_scenario(toy_scenario(GAIN_LOOP.format(declaration='no_feedthrough = ["x"]'))))
    fmu = reference_fmu("Feedthrough").as_posix()
    text = f"""
[simulation]
stop = 0.1
step = 0.1
[components.f]
fmu = "{fmu}"
no_feedthrough = ["Int32_output"]
"""
    with pytest.raises(ScenarioError, match=r"does not declare direct dependencies; Int32_output depends on "
                                            r"Int32_input"):
        resolve_system(load_scenario(write_scenario(tmp_path, text)))


def test_a_discard_without_progress_stays_a_failure_with_the_last_successful_time(toy_scenario):
    text = """
[simulation]
stop = 1.0
step = 0.1
[components.fail]
fmu = "ToyFailer.fmu"
[components.fail.parameters]
mode = 0
fail_at = 0.5
"""
    outcome = CoSimulation(resolve_system(load_scenario(toy_scenario(text)))).run(handle_sigint=False)
    assert not outcome.complete and outcome.ended_by is None
    assert "fmi2DoStep returned discard" in outcome.error
    assert "without progress in the step (last successful time 0.5 s)" in outcome.error


@pytest.mark.parametrize("fmi_type", list(TYPED))
def test_initial_bindings_of_every_type(fmi_type, tmp_path):
    inp, out, value = TYPED[fmi_type]
    text = feedthrough_pair(tmp_path, fmi_type).replace("[[connections]]", "[[initial]]")
    system = resolve_system(load_scenario(write_scenario(tmp_path, text)))
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.initial_values == {f"b.{inp}": value}
    samples = outcome.column("b." + out)
    assert (list(samples) == [value] * 11) if fmi_type == "String" else np.all(samples == float(value))
