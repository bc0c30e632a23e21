"""Load events and analysis settings in scenarios: syntax, validation naming the key, mapping onto the
GeneratorRotor FMU's event slots and into the monolithic reference (model descriptions only, no run)."""

from __future__ import annotations

import math
import re
import tomllib

import pytest

from components.model.generator import LoadEvent
from orchestrator.cosim.event_slots import assign_events
from orchestrator.cosim.physics_view import physics_view
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.analysis_settings import AnalysisSettings
from orchestrator.inputs.load_events import ScenarioEvent
from orchestrator.inputs.scenario_file import find_scenario, load_scenario, packaged_scenarios, scenario_from_dict

EVENT_SCENARIOS = ("grid-fault", "emergency-stop", "torque-step")


def _grid_fault_data() -> dict:
    return tomllib.loads(find_scenario("grid-fault").read_text())


def _with(data: dict, **top) -> dict:
    out = dict(data)
    out.update(top)
    return out


@pytest.mark.parametrize("event, key, expected", [
    ({"kind": "brownout", "start": 10.0, "duration": 0.5}, r"events\[0\]\.kind", "one of 'torque_step'"),
    ({"kind": "grid_fault", "start": 10.0, "duration": -0.5}, r"events\[0\]\.duration", "> 0"),
    ({"kind": "grid_fault", "start": 10.0, "duration": 0.0}, r"events\[0\]\.duration", "> 0"),
    ({"kind": "grid_fault", "start": 10.0}, r"events\[0\]\.duration", "missing"),
    ({"kind": "emergency_stop", "start": 10.0, "duration": math.inf}, r"events\[0\]\.duration", "finite duration"),
    ({"kind": "torque_step", "start": 10.0}, r"events\[0\]\.factor", "missing"),
    ({"kind": "grid_fault", "start": 10.0, "duration": 0.5, "factor": 0.5}, r"events\[0\]\.factor", "no factor"),
    ({"kind": "torque_step", "start": 10.0, "factor": "1.5"}, r"events\[0\]\.factor", "finite number"),
    ({"kind": "grid_fault", "start": 15.0, "duration": 0.5}, r"events\[0\]\.start", r"inside the run.*\[0, 15\)"),
    ({"kind": "grid_fault", "start": 22.0, "duration": 0.5}, r"events\[0\]\.start", "inside the run"),
    ({"kind": "grid_fault", "start": -1.0, "duration": 0.5}, r"events\[0\]\.start", ">= 0"),
    ({"kind": "grid_fault", "start": 10.0, "duration": 0.5, "stat": 1}, r"events\[0\]\.stat", "known key"),
    ({"kind": "grid_fault", "duration": 0.5}, r"events\[0\]\.start", "missing"),
    ({"kind": "grid_fault", "start": 10.0, "duration": 0.5, "component": "gen"}, r"events\[0\]\.component",
     "declared component"),
])
def test_bad_event_definitions_name_the_key(event, key, expected):
    data = _with(_grid_fault_data(), events=[event])
    with pytest.raises(ScenarioError, match=key) as info:
        scenario_from_dict(data, source="bad.toml")
    assert re.search(expected, str(info.value)), str(info.value)


def test_events_must_be_an_array_of_tables_and_stay_inside_a_shortened_run():
    with pytest.raises(ScenarioError, match=r"events = .*array of tables"):
        scenario_from_dict(_with(_grid_fault_data(), events={"kind": "grid_fault"}))
    sc = load_scenario(find_scenario("grid-fault"))
    with pytest.raises(ScenarioError, match=r"events\[0\]\.start = 10\.0.*\[0, 5\) s"):
        sc.with_simulation(stop_s=5.0, window_s=(0.0, 5.0))


@pytest.fixture(scope="module")
def fmu_paths(fmu_dir):
    return {"wind": fmu_dir / "WindSource.fmu", "gearbox": fmu_dir / "Gearbox.fmu",
            "generator": fmu_dir / "GeneratorRotor.fmu"}


def test_too_many_events_for_the_fmu_slots(fmu_paths):
    events = [{"kind": "torque_step", "start": 6.0 + i, "duration": 0.5, "factor": 1.1} for i in range(5)]
    sc = scenario_from_dict(_with(_grid_fault_data(), events=events), source="five.toml")  # structurally fine
    with pytest.raises(ScenarioError, match=r"events\[4\].*at most 4 load events for component 'generator'.*"
                                            r"event1\.\.event4"):
        resolve_system(sc, fmu_paths=fmu_paths)


def test_slot_parameters_given_twice_or_events_on_a_component_without_slots(fmu_paths):
    data = _grid_fault_data()
    data["components"]["generator"]["parameters"] = {"event1.kind": 1}
    with pytest.raises(ScenarioError, match=r"components\.generator\.parameters\.event1\.kind.*\[\[events\]\] only"):
        resolve_system(scenario_from_dict(data), fmu_paths=fmu_paths)
    ev = {"kind": "grid_fault", "start": 10.0, "duration": 0.5, "component": "wind"}
    with pytest.raises(ScenarioError, match=r"events\[0\]\.component = 'wind'.*WindSource\.fmu \(WindSource\) has none"):
        resolve_system(scenario_from_dict(_with(_grid_fault_data(), events=[ev])), fmu_paths=fmu_paths)


@pytest.mark.parametrize("name", EVENT_SCENARIOS)
def test_packaged_event_scenarios_fill_the_generator_slots_and_the_reference(name, fmu_paths):
    sc = load_scenario(find_scenario(name))
    assert name in packaged_scenarios()
    assert len(sc.events) == 1 and sc.events[0].start_s == 10.0
    w0, w1 = sc.simulation.window_s
    assert w0 < sc.events[0].start_s and min(sc.events[0].end_s, sc.simulation.stop_s) <= w1  # window covers it
    system = resolve_system(sc, fmu_paths=fmu_paths)
    assert system.scenario.events == ()  # moved into the FMU parameters: checking again is a no-op
    assert resolve_system(system.scenario, fmu_paths=fmu_paths).scenario == system.scenario
    (assigned,) = system.events
    assert (assigned.component, assigned.slot) == ("generator", 1)
    params = system.scenario.component("generator").parameters
    ev = sc.events[0]
    assert params["event1.kind"] == {"torque_step": 1, "grid_fault": 2, "emergency_stop": 3}[ev.kind]
    assert params["event1.start"] == 10.0 and params["event1.duration"] == ev.duration_s
    assert "event2.kind" not in params
    reference = physics_view(system).drivetrain.generator.events
    assert reference == (ev.load_event(),)


def test_event_defaults_and_slot_values():
    step = ScenarioEvent("torque_step", 3.0, factor=1.5)
    assert step.duration_s == math.inf and step.load_event() == LoadEvent("torque_step", 3.0, math.inf, 1.5)
    assert step.slot_values(2) == {"event2.kind": 1, "event2.start": 3.0, "event2.duration": math.inf,
                                   "event2.factor": 1.5}
    stop = ScenarioEvent("emergency_stop", 1.0, 2.0)
    assert stop.factor == 1.0 and stop.load_event().torque(25.4e3) == -25.4e3
    assert ScenarioEvent("grid_fault", 1.0, 0.5).load_event().torque(25.4e3) == 0.0
    assert step.as_dict()["duration_s"] is None  # JSON: a permanent step has no finite duration


def test_two_events_on_one_generator_take_consecutive_slots(fmu_paths):
    events = [{"kind": "torque_step", "start": 6.0, "duration": 2.0, "factor": 1.2},
              {"kind": "grid_fault", "start": 11.0, "duration": 0.3}]
    sc = scenario_from_dict(_with(_grid_fault_data(), events=events))
    scenario, assigned = assign_events(sc, resolve_system(sc, fmu_paths=fmu_paths).interfaces)
    assert [a.slot for a in assigned] == [1, 2]
    params = scenario.component("generator").parameters
    assert (params["event1.kind"], params["event2.kind"], params["event2.start"]) == (1, 2, 11.0)


@pytest.mark.parametrize("table, key", [
    ({"woehler_exponents": []}, "analysis.woehler_exponents"),
    ({"woehler_exponents": [3, -5]}, "analysis.woehler_exponents"),
    ({"woehler_exponents": [3, 3]}, "analysis.woehler_exponents"),
    ({"reference_frequency_hz": 0}, "analysis.reference_frequency_hz"),
    ({"ldd_bins": 0}, "analysis.ldd_bins"),
    ({"ldd_bins": [0.0, 2.0, 1.0]}, "analysis.ldd_bins"),
    ({"rainflow_residue": "full"}, "analysis.rainflow_residue"),
    ({"contact_loss_threshold_n": -1.0}, "analysis.contact_loss_threshold_n"),
    ({"spectrum": "yes"}, "analysis.spectrum"),
    ({"woehler": [3]}, "analysis.woehler"),
])
def test_bad_analysis_settings_name_the_key(table, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        scenario_from_dict(_with(_grid_fault_data(), analysis=table), source="bad.toml")


def test_analysis_settings_are_read_and_give_the_fatigue_settings():
    sc = scenario_from_dict(_with(_grid_fault_data(), analysis={
        "woehler_exponents": [4, 9], "reference_frequency_hz": 2.0, "ldd_bins": [-1e5, 0.0, 1e5], "spectrum": "always"}))
    a = sc.analysis
    assert a == AnalysisSettings((4.0, 9.0), 2.0, (-1e5, 0.0, 1e5), "half", 1.0, "always")
    fs = a.fatigue_settings()
    assert fs.wohler_exponents == (4.0, 9.0) and fs.reference_cycles_for(10.0) == 20.0 and fs.ldd_bins == (-1e5, 0.0, 1e5)
    assert load_scenario(find_scenario("paper-60s")).analysis == AnalysisSettings()


def test_ssp_export_carries_events_and_analysis_settings(fmu_paths, tmp_path):
    """Events travel as the generator's slot parameters (a permanent step as INF), non-default
    [analysis] settings as the dtcosim annotation; the archive stays valid SSP 1.0."""
    from fmpy.ssp.ssd import read_ssd

    from orchestrator.interop.ssp import export_ssp, import_ssp

    data = tomllib.loads(find_scenario("torque-step").read_text())
    data["analysis"] = {"woehler_exponents": [4, 9], "ldd_bins": [-1e5, 0.0, 1e5], "spectrum": "never"}
    original = scenario_from_dict(data)
    system = resolve_system(original, fmu_paths=fmu_paths)
    ssp = export_ssp(system, tmp_path / "step.ssp")
    read_ssd(str(ssp))  # validates against the SSP 1.0 schema
    back = import_ssp(ssp)
    assert back.analysis == original.analysis and back.events == ()
    gen = back.component("generator").parameters
    assert (gen["event1.kind"], gen["event1.start"], gen["event1.duration"], gen["event1.factor"]) == (1, 10.0, math.inf, 1.5)
    again = resolve_system(back, fmu_paths=fmu_paths)
    assert physics_view(again).drivetrain.generator.events == (LoadEvent("torque_step", 10.0, math.inf, 1.5),)
    # reported as events again (summary "events", event plot), read from the slot parameters
    assert [a.as_dict() for a in again.events] == [a.as_dict() for a in system.events]


def test_slot_parameters_set_directly_are_reported_and_checked(fmu_paths):
    sc = load_scenario(find_scenario("paper-60s")).with_parameters(
        "generator", **{"event2.kind": 3, "event2.start": 4.0, "event2.duration": 0.25})
    (a,) = resolve_system(sc, fmu_paths=fmu_paths).events
    assert (a.component, a.slot, a.event.kind, a.event.start_s, a.event.duration_s, a.event.factor) == (
        "generator", 2, "emergency_stop", 4.0, 0.25, 1.0)
    bad = sc.with_parameters("generator", **{"event2.duration": -1.0})
    with pytest.raises(ScenarioError, match=r"components\.generator\.parameters\.event2\.duration = -1\.0"):
        resolve_system(bad, fmu_paths=fmu_paths)
    with pytest.raises(ScenarioError, match=r"event2\.kind = 7"):
        resolve_system(sc.with_parameters("generator", **{"event2.kind": 7}), fmu_paths=fmu_paths)
