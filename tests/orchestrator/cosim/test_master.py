"""The master with small real FMUs: time grid, Gauss-Seidel/Jacobi data flow, extrapolation,
initialisation, sampling, failures, convergence with the step size."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.linalg import expm

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import load_scenario
from orchestrator.inputs.transformations import LinearTransformation

CHAIN = """
name = "chain"
[simulation]
start = 0.3
stop = {stop}
step = 0.1
algorithm = "{algorithm}"
extrapolation = "{extrapolation}"
{order}
[components.src]
fmu = "ToySine.fmu"
[components.src.parameters]
frequency = 0.37
[components.int]
fmu = "ToyIntegrator.fmu"
[[connections]]
from = "src.y"
to = "int.u"
[record]
variables = ["src.y", "src.t_seen", "int.u_seen", "int.t_seen", "int.x"]
"""


def run_chain(toy_scenario, algorithm="gauss-seidel", extrapolation="hold", order="", stop=100.3):
    text = CHAIN.format(algorithm=algorithm, extrapolation=extrapolation, order=order, stop=stop)
    out = CoSimulation(resolve_system(load_scenario(toy_scenario(text)))).run(handle_sigint=False)
    assert out.complete
    return out


def test_time_is_kept_by_integer_step_count(toy_scenario):
    out = run_chain(toy_scenario)  # 1000 steps of 0.1 s from 0.3 s
    k = np.arange(1, out.steps + 1)
    # the communication point of step k-1 is t0 + (k-1) H exactly, not a running sum
    assert np.array_equal(out.column("int.t_seen")[1:], 0.3 + (k - 1) * 0.1)
    assert np.array_equal(out.time_s, 0.3 + np.arange(out.steps + 1) * 0.1)
    running = 0.3
    for _ in range(out.steps):
        running += 0.1
    assert running != out.time_s[-1]  # accumulating would have drifted


def test_gauss_seidel_default_order_feeds_values_at_the_communication_point(toy_scenario):
    out = run_chain(toy_scenario)
    # the integrator is stepped before its source: it receives y(t_k) for the step from t_k
    y = out.column("src.y")
    assert np.array_equal(out.column("int.u_seen")[1:], y[:-1])


def test_gauss_seidel_with_source_first_feeds_the_new_values(toy_scenario):
    out = run_chain(toy_scenario, order='order = ["src", "int"]')
    assert np.array_equal(out.column("int.u_seen")[1:], out.column("src.y")[1:])


def test_jacobi_feeds_values_at_the_communication_point(toy_scenario):
    out = run_chain(toy_scenario, algorithm="jacobi", order='order = ["src", "int"]')
    assert np.array_equal(out.column("int.u_seen")[1:], out.column("src.y")[:-1])


def test_linear_extrapolation_to_the_step_midpoint(toy_scenario):
    y_out = run_chain(toy_scenario, extrapolation="linear")
    y = y_out.column("src.y")
    u = y_out.column("int.u_seen")
    # samples at t_k, t_{k-1}: 1.5 y_k - 0.5 y_{k-1}; first step holds
    assert u[1] == y[0]
    np.testing.assert_allclose(u[2:], 1.5 * y[1:-1] - 0.5 * y[:-2], rtol=0, atol=1e-15)
    gs = run_chain(toy_scenario, extrapolation="linear", order='order = ["src", "int"]')
    y, u = gs.column("src.y"), gs.column("int.u_seen")
    # source already stepped: mean of the samples at t_{k+1} and t_k
    np.testing.assert_allclose(u[1:], 0.5 * (y[1:] + y[:-1]), rtol=0, atol=1e-15)


def test_sampling_every_n_steps_matches_every_step(toy_scenario):
    every = run_chain(toy_scenario, stop=10.3)
    text = CHAIN.format(algorithm="gauss-seidel", extrapolation="hold", order="", stop=10.3).replace(
        "step = 0.1", "step = 0.1\noutput_interval = 0.5")
    sparse = CoSimulation(resolve_system(load_scenario(toy_scenario(text)))).run(handle_sigint=False)
    assert sparse.values.shape == (21, 5)
    np.testing.assert_array_equal(sparse.time_s, every.time_s[::5])
    np.testing.assert_array_equal(sparse.values, every.values[::5])


INIT = """
name = "init"
[simulation]
stop = 0.05
step = 0.01
[components.gain]
fmu = "ToyGain.fmu"
[components.gain.parameters]
u = 3.0
[components.int]
fmu = "ToyIntegrator.fmu"
[components.follower]
fmu = "ToyInit.fmu"
[components.follower.parameters]
p0 = 0.5
[[connections]]
from = "int.x"
to = "follower.u"
[[initial]]
from = "gain.y"
to = "int.x0"
[[initial]]
from = "follower.y"
to = "gain.gain"
"""


def test_initialisation_propagates_outputs_into_parameters(toy_scenario):
    system = resolve_system(load_scenario(toy_scenario(INIT)))
    out = CoSimulation(system).run(handle_sigint=False)
    # sweep 1: int.x0 = gain.y = 2 (default gain) * 3 = 6; follower.y = p0 = 0.5 -> gain.gain = 0.5
    # sweep 2: int.x0 = 0.5 * 3 = 1.5; nothing else changes; sweep 3 confirms the fixed point
    assert out.complete
    assert out.initial_values == {"int.x0": 1.5, "gain.gain": 0.5}
    assert out.column("int.x")[0] == 1.5


def test_initial_binding_sets_a_parameter_before_exit(toy_scenario):
    text = INIT.split("[[initial]]\nfrom = \"follower.y\"")[0].replace("u = 3.0", "u = 3.0\ngain = 2.0")
    out = CoSimulation(resolve_system(load_scenario(toy_scenario(text)))).run(handle_sigint=False)
    assert out.initial_values == {"int.x0": 6.0}
    assert out.column("int.x")[0] == 6.0


FAIL = """
name = "fail"
[simulation]
stop = 1.0
step = 0.01
[components.src]
fmu = "ToySine.fmu"
[components.fail]
fmu = "ToyFailer.fmu"
[components.fail.parameters]
fail_at = 0.5
mode = 0
[[connections]]
from = "src.y"
to = "fail.u"
[record]
variables = ["src.y", "fail.y"]
"""


def test_fmu_failure_stops_the_run_with_partial_results(toy_scenario):
    out = CoSimulation(resolve_system(load_scenario(toy_scenario(FAIL)))).run(handle_sigint=False)
    assert not out.complete
    assert out.steps == 50 and out.stopped_at_s == pytest.approx(0.5)
    assert out.time_s.size == 51 and np.all(np.isfinite(out.values))
    assert "FMU 'fail'" in out.error and "fmi2DoStep" in out.error and "discard" in out.error
    assert "t = 0.5 s" in out.error and "solver failed to converge" in out.error


MASSES = """
name = "masses"
[simulation]
stop = 2.0
step = {step}
output_interval = 0.02
algorithm = "{algorithm}"
[components.a]
fmu = "ToyMassA.fmu"
[components.b]
fmu = "ToyMassB.fmu"
[[connections]]
from = "a.x"
to = "b.xa"
[[connections]]
from = "a.v"
to = "b.va"
[[connections]]
from = "b.F"
to = "a.F"
[record]
variables = ["a.x"]
"""


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_coupling_error_of_a_split_oscillator_shrinks_with_the_step(toy_scenario, algorithm):
    ma, ka, ca, mb, kb, cb = 1.0, 100.0, 0.5, 0.5, 50.0, 0.2
    A = np.array([[0, 1, 0, 0], [-(ka + kb) / ma, -(ca + cb) / ma, kb / ma, cb / ma],
                  [0, 0, 0, 1], [kb / mb, cb / mb, -kb / mb, -cb / mb]])
    errors = []
    for h in (4e-3, 2e-3, 1e-3):
        text = MASSES.format(step=h, algorithm=algorithm)
        out = CoSimulation(resolve_system(load_scenario(toy_scenario(text, f"m{h}.toml")))).run(handle_sigint=False)
        exact = np.array([(expm(A * t) @ [0.1, 0, 0, 0])[0] for t in out.time_s])
        errors.append(np.sqrt(np.mean((out.column("a.x") - exact) ** 2)))
    assert errors[0] > errors[1] > errors[2]
    assert errors[0] / errors[2] > 3.0  # first order at least
    assert errors[2] < 1e-3


def test_failure_between_samples_keeps_the_sampled_rows(toy_scenario):
    text = FAIL.replace("step = 0.01", "step = 0.01\noutput_interval = 0.03")
    out = CoSimulation(resolve_system(load_scenario(toy_scenario(text)))).run(handle_sigint=False)
    assert not out.complete and out.steps == 50 and out.stopped_at_s == pytest.approx(0.5)
    assert out.time_s.size == 17 and out.time_s[-1] == pytest.approx(0.48)
    every = CoSimulation(resolve_system(load_scenario(toy_scenario(FAIL, "every.toml")))).run(handle_sigint=False)
    np.testing.assert_array_equal(out.values, every.values[::3][:17])


def test_wall_time_limit_stops_between_blocks_and_keeps_the_samples(toy_scenario):
    text = CHAIN.format(algorithm="gauss-seidel", extrapolation="hold", order="", stop=100.3)
    system = resolve_system(load_scenario(toy_scenario(text)))
    out = CoSimulation(system).run(handle_sigint=False, wall_time_limit_s=1e-9)
    assert not out.complete and not out.interrupted
    assert 0 < out.steps < 1000 and out.steps % 250 == 0  # stopped after a whole block of steps
    assert out.error == f"wall-time limit of 1e-09 s reached at t = {out.stopped_at_s:.6g} s"
    assert out.time_s.size == out.steps + 1 and np.all(np.isfinite(out.values))
    # no limit (None or 0): the same run completes
    assert CoSimulation(system).run(handle_sigint=False, wall_time_limit_s=0).complete


def both_executors(system):
    """The run of ``system`` by the compiled loop and by the Python loop (the same stepping plan)."""
    compiled = CoSimulation(system, step_loop="compiled").run(handle_sigint=False)
    python = CoSimulation(system, step_loop="python").run(handle_sigint=False)
    return compiled, python


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("extrapolation", ["hold", "linear"])
@pytest.mark.parametrize("interval", [0.001, 0.003])
@pytest.mark.parametrize("transformed", [False, True])
def test_the_compiled_and_the_python_loop_record_the_same_values(toy_scenario, algorithm, extrapolation, interval,
                                                                  transformed):
    pytest.importorskip("numba")
    text = MASSES.format(step=1e-3, algorithm=algorithm).replace(
        "output_interval = 0.02", f'output_interval = {interval}\nextrapolation = "{extrapolation}"')
    scenario = load_scenario(toy_scenario(text))
    if transformed:  # a linear transformation (SSP) on one of the coupled inputs
        scenario = replace(scenario, connections=tuple(
            replace(c, transformation=LinearTransformation(0.9, 1e-3)) if c.target.variable == "xa" else c
            for c in scenario.connections))
    compiled, python = both_executors(resolve_system(scenario))
    assert compiled.complete and python.complete and compiled.steps == python.steps
    np.testing.assert_array_equal(compiled.values, python.values)  # the same FMI calls with the same values
    np.testing.assert_array_equal(compiled.time_s, python.time_s)


@pytest.mark.parametrize("interval", [0.01, 0.03])
def test_the_compiled_and_the_python_loop_stop_alike_on_a_failing_fmu(toy_scenario, interval):
    pytest.importorskip("numba")
    text = FAIL.replace("step = 0.01", f"step = 0.01\noutput_interval = {interval}")
    compiled, python = both_executors(resolve_system(load_scenario(toy_scenario(text))))
    assert not compiled.complete and compiled.steps == python.steps == 50
    assert compiled.error == python.error and "fmi2DoStep" in compiled.error
    np.testing.assert_array_equal(compiled.values, python.values)
    np.testing.assert_array_equal(compiled.time_s, python.time_s)


def test_the_compiled_step_loop_refuses_what_it_cannot_run(toy_scenario):
    pytest.importorskip("numba")
    system = resolve_system(load_scenario(toy_scenario(MASSES.format(step=1e-3, algorithm="jacobi"))))
    with pytest.raises(ValueError, match="step_loop 'compiled' cannot run this system: profiling timers"):
        CoSimulation(system, profile=True, step_loop="compiled").run(handle_sigint=False)
    profiled = CoSimulation(system, profile=True).run(handle_sigint=False)  # auto: the Python loop times the calls
    assert profiled.complete and set(profiled.profile) == {"a", "b"}
    assert all(times["fmi2DoStep"] > 0 for times in profiled.profile.values())
    np.testing.assert_array_equal(profiled.values, CoSimulation(system).run(handle_sigint=False).values)


def test_an_unknown_step_loop_is_refused_and_the_earlier_names_are_accepted(toy_scenario):
    system = resolve_system(load_scenario(toy_scenario()))
    with pytest.raises(ValueError, match="step_loop 'turbo': expected one of auto, compiled, python"):
        CoSimulation(system, step_loop="turbo")
    assert [CoSimulation(system, step_loop=name).step_loop for name in ("numba", "generated", "interpreted")] == \
        ["compiled", "python", "python"]


