"""The analysis window under a changed run: kept, clipped, or following a later stop; --window sets it."""

from __future__ import annotations

import argparse

import pytest

from orchestrator.commands import scenario_options
from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import SimulationOverrides
from orchestrator.inputs.scenario_file import find_scenario, load_scenario


@pytest.fixture(scope="module")
def paper():
    """paper-60s: run [0, 60] s, window [5, 60] s (it ends at the stop)."""
    return load_scenario(find_scenario("paper-60s"))


@pytest.mark.parametrize("overrides, window, note", [
    (SimulationOverrides(stop_s=600.0), (5.0, 600.0), "it ended at the stop (60 s) and follows the new one"),
    (SimulationOverrides(stop_s=30.0), (5.0, 30.0), "to fit the run [0, 30] s"),
    (SimulationOverrides(stop_s=2.0), (0.0, 2.0), "to fit the run [0, 2] s"),
    (SimulationOverrides(stop_s=600.0, window_s=(5.0, 60.0)), (5.0, 60.0), None),
    (SimulationOverrides(step_s=0.001), (5.0, 60.0), None),
], ids=["later-stop-follows", "earlier-stop-clips", "stop-before-the-window", "given-window-wins", "no-stop"])
def test_the_window_is_kept_clipped_or_follows_a_later_stop(paper, overrides, window, note):
    scenario, notes = overrides.apply(paper)
    assert scenario.simulation.window_s == window
    if note is None:
        assert notes == [] or all("window" not in n for n in notes)
    else:
        assert any(note in n for n in notes), notes


def test_a_window_that_ended_before_the_stop_stays_where_it_was(paper):
    earlier = paper.with_simulation(window_s=(5.0, 50.0))
    scenario, notes = SimulationOverrides(stop_s=600.0).apply(earlier)
    assert scenario.simulation.window_s == (5.0, 50.0) and notes == []


def _args(**given):
    base = {"stop": None, "step": None, "output_interval": None, "window": None, "algorithm": None,
            "extrapolation": None, "set": [], "algebraic_loops": None, "no_feedthrough": [], "allow_implausible": []}
    return argparse.Namespace(**{**base, **given})


def test_the_window_option_sets_the_window_and_names_itself_in_the_overrides(paper):
    args = _args(stop=600.0, window=[100.0, 600.0])
    scenario = scenario_options.apply(paper, args, "run")
    assert scenario.simulation.window_s == (100.0, 600.0)
    assert scenario_options.given_overrides(args) == ["--stop 600", "--window 100 600"]


def test_a_window_outside_the_run_is_named_before_anything_runs(paper):
    with pytest.raises(ScenarioError, match=r"simulation.window = \[0.5, 2.0\]: expected .* within \[0, 1\] s"):
        scenario_options.apply(paper, _args(stop=1.0, window=[0.5, 2.0]), "run")


@pytest.mark.parametrize("step, match", [(0.0, r"simulation\.step = 0\.0: expected > 0 s"),
                                         (-1e-3, r"simulation\.step = -0\.001: expected > 0 s"),
                                         (float("nan"), r"simulation\.step = nan: expected a finite number"),
                                         (float("inf"), r"simulation\.step = inf: expected a finite number")])
def test_a_step_that_is_no_positive_number_is_a_named_error_not_a_traceback(paper, step, match):
    # --step 0 raised ZeroDivisionError and --step nan ValueError from the output-interval check (issue 35.9)
    with pytest.raises(ScenarioError, match=match):
        SimulationOverrides(step_s=step).apply(paper)
