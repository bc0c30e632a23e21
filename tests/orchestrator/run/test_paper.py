"""The paper's scenario through the three FMUs: `dtcosim run`, Table 7, Fig. 16, agreement with the
monolithic reference, coupling error against the communication step."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest

from components.reference.cases import TABLE7_PAPER
from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.physics_view import physics_view
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.provision.locate import resolve_fmu_paths
from orchestrator.result_files import read_timeseries
from orchestrator.run.comparison import compare, run_reference

pytestmark = pytest.mark.slow

FORCES = [f"gearbox.stage{s}.F_{k}[{i}]" for s in (1, 2) for k in ("sp", "rp") for i in (1, 2, 3)] + ["gearbox.stage3.F_mesh"]


PAPER = load_scenario(find_scenario("paper-60s")).simulation  # the packaged step and output interval


def test_run_without_arguments_builds_fmus_and_writes_results(paper_run):
    out, summary, proc = paper_run
    for name in ("timeseries.csv", "summary.json", "rotor_speed.png", "generator_speed.png", "contact_forces.png"):
        assert (out / name).stat().st_size > 1000, name
    fmu_dir = out.parent.parent / "fmus"
    assert sorted(p.name for p in fmu_dir.glob("*.fmu")) == ["Gearbox.fmu", "GeneratorRotor.fmu", "WindSource.fmu"]
    assert "building" in proc.stderr
    assert f"paper-60s: complete, {PAPER.n_steps} steps" in proc.stdout
    assert summary["complete"] is True and summary["steps"] == PAPER.n_steps
    assert summary["scenario"] == "paper-60s" and summary["window_s"] == [5.0, 60.0]


@pytest.mark.parametrize("name", sorted(TABLE7_PAPER))
def test_table7_means_within_one_percent(paper_run, name):
    _, summary, _ = paper_run
    mean = summary["statistics"][f"gearbox.{name}"]["mean"]
    paper_mean = TABLE7_PAPER[name][0]
    assert abs(mean / paper_mean - 1.0) < 0.01, (name, mean, paper_mean)


def test_fig16_generator_follows_the_ideal_gearbox(paper_run):
    out, summary, _ = paper_run
    fig16 = summary["generator_vs_ideal"]
    assert fig16["ratio"] == pytest.approx(100.0, rel=1e-12)
    assert fig16["relative_deviation"]["max_abs"] < 0.01
    header, data = read_timeseries(out / "timeseries.csv")
    t = data[:, 0]
    sel = (t >= 5.0) & (t <= 60.0)
    rotor = data[sel, header.index("wind.omega [rad/s]")]
    gen = data[sel, header.index("generator.omega [rad/s]")]
    assert np.max(np.abs(gen / (100.0 * rotor) - 1.0)) < 0.01


def test_timeseries_and_summary_format(paper_run):
    out, summary, _ = paper_run
    header, data = read_timeseries(out / "timeseries.csv")
    assert header[0] == "time [s]"
    for col in ("gearbox.stage1.F_sp[1] [N]", "gearbox.stage3.F_mesh [N]", "gearbox.shaft3.torque [N.m]",
                "generator.omega [rad/s]", "wind.omega [rad/s]", "gearbox.omega_out [rad/s]"):
        assert col in header
    rows = round(60.0 / PAPER.output_interval_s) + 1
    assert data.shape == (rows, len(header))
    np.testing.assert_allclose(data[:, 0], np.arange(rows) * PAPER.output_interval_s, rtol=0, atol=1e-12)
    stats = summary["statistics"]
    assert set(stats) == {h.rsplit(" [", 1)[0] for h in header[1:]}
    for st in stats.values():
        assert set(st) == {"mean", "std", "min", "max"} and st["min"] <= st["mean"] <= st["max"]
    assert summary["wall_time_s"] > 0 and summary["steps"] == PAPER.n_steps
    assert set(summary["versions"]) >= {"dtcosim", "python", "numpy", "scipy", "fmpy", "pythonfmu"}
    for comp, info in summary["fmus"].items():
        digest = hashlib.sha256(open(info["file"], "rb").read()).hexdigest()
        assert info["sha256"] == digest, comp
    json.dumps(summary, allow_nan=False)


def test_cosimulation_agrees_with_the_monolithic_reference_at_1ms(paper_run):
    out, summary, _ = paper_run
    paper = load_scenario(find_scenario(None))
    system = resolve_system(paper, fmu_paths=resolve_fmu_paths(paper, out.parent.parent / "fmus"))
    setup = physics_view(system)
    reference = run_reference(system, setup)
    assert reference.complete
    window = system.scenario.simulation.window_s
    stats_ref = reference.statistics(window, [n.split(".", 1)[1] for n in FORCES] + ["omega_gen", "shaft3.torque"])
    pairs = [(n, n.split(".", 1)[1]) for n in FORCES] + [("generator.omega", "omega_gen"), ("gearbox.shaft3.torque", "shaft3.torque")]
    for cosim_name, ref_name in pairs:
        co, ref = summary["statistics"][cosim_name], stats_ref[ref_name]
        assert abs(co["mean"] / ref["mean"] - 1.0) < 0.005, (cosim_name, co["mean"], ref["mean"])
        assert abs(co["std"] / ref["std"] - 1.0) < 0.02, (cosim_name, co["std"], ref["std"])


def _short(fmu_dir, step, stop=3.0, **gearbox):
    sc = load_scenario(find_scenario(None)).with_simulation(stop_s=stop, window_s=(1.0, stop), step_s=step,
                                                            output_interval_s=0.01)
    if gearbox:
        sc = sc.with_parameters("gearbox", **gearbox)
    return resolve_system(sc, fmu_paths=resolve_fmu_paths(sc, fmu_dir))


def _coupling_errors(fmu_dir, steps, **gearbox):
    """RMS difference to the monolithic solution on the common 10 ms grid over [1, 3] s."""
    system = _short(fmu_dir, steps[0], **gearbox)
    setup = physics_view(system)
    reference = run_reference(system, setup)
    out = []
    for h in steps:
        s = _short(fmu_dir, h, **gearbox)
        report = compare(CoSimulation(s).run(handle_sigint=False), reference, s, setup)["variables"]
        out.append({name: report[name]["rms_difference"] for name in ("generator.omega", "gearbox.stage1.F_sp[1]")})
    return out


#: the Gearbox's interface before the interface model: generator motion prescribed, rotor slope from two speeds
MOTION_INTERFACE = {"generator_interface": 0, "rotor_derivatives": False}


def test_coupling_error_shrinks_with_the_communication_step(fmu_dir):
    """The classic coupling error (motion interface) falls faster than first order in H."""
    steps = (10e-3, 5e-3, 2e-3, 1e-3)
    errors = _coupling_errors(fmu_dir, steps, **MOTION_INTERFACE)
    for name in ("generator.omega", "gearbox.stage1.F_sp[1]"):
        e = [row[name] for row in errors]
        print(name, " ".join(f"H={h * 1e3:g} ms: {x:.3e}" for h, x in zip(steps, e)))
        assert e[0] > e[1] > e[2] > e[3], (name, e)
        assert e[0] / e[3] > 10.0, (name, e)  # faster than first order over a factor 10 in H


def test_the_interface_model_at_10_ms_is_closer_than_the_motion_interface_at_5_ms(fmu_dir):
    """paper-60s's Gearbox interface (inertia, rotor derivatives) against the motion interface, [1, 3] s.

    Both start at the static deflection (issue 29): without the start-up transient the interface model at
    10 ms is 4.8 x (generator speed) and 8.7 x (stage-1 force) closer than the motion interface at 10 ms,
    closer than it at 5 ms, and about as close as it at 2-3 ms (measured 2026-12-03). With the start-up
    transient of the undeflected start it was closer than the motion interface at 2 ms.
    """
    interface_model = _coupling_errors(fmu_dir, (10e-3,))[0]
    motion = _coupling_errors(fmu_dir, (10e-3, 5e-3), **MOTION_INTERFACE)
    print("RMS difference to monolithic: interface model at 10 ms", interface_model, "motion interface at 10, 5 ms",
          motion)
    for name in interface_model:
        assert interface_model[name] < motion[1][name] < motion[0][name], (name, interface_model, motion)
        assert interface_model[name] < 0.25 * motion[0][name], (name, interface_model, motion)


def test_step_averaged_shaft_torque_beats_end_of_step(fmu_dir):
    avg = _coupling_errors(fmu_dir, (5e-3,), shaft_torque_mode=0)[0]
    end = _coupling_errors(fmu_dir, (5e-3,), shaft_torque_mode=1)[0]
    print("H = 5 ms, RMS difference to monolithic: averaged", avg, "end of step", end)
    for name in avg:
        assert avg[name] < 0.2 * end[name], (name, avg[name], end[name])
