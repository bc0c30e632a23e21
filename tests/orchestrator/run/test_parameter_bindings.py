"""A value two FMUs need has one source (issue 30.3): the Gearbox's generator inertia is bound to the generator's.

The Gearbox's generator interface model integrates a copy of the generator inertia within each
step; it was a hand-kept copy (``generator_inertia``), so ``--set generator.inertia=120`` alone
moved the Table 7 statistics 1.1e-2 from the monolithic reference. Every packaged scenario now
binds it (``[[initial]] from = "generator.inertia"``): read from the generator FMU through FMI in
initialisation mode and set on the Gearbox.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import apply_parameters
from orchestrator.inputs.scenario_file import find_scenario, load_scenario, packaged_scenarios
from tests.helpers.scenarios import dtcosim


@pytest.mark.parametrize("name", sorted(packaged_scenarios()))
def test_every_packaged_scenario_binds_the_gearbox_generator_inertia_to_the_generator(name):
    scenario = load_scenario(find_scenario(name))
    bindings = {str(b.target): str(b.source) for b in scenario.initial}
    assert bindings["gearbox.generator_inertia"] == "generator.inertia"


def test_a_value_for_the_bound_copy_is_refused_naming_its_source():
    scenario = load_scenario(find_scenario("paper-60s"))
    with pytest.raises(ScenarioError, match=r"components\.gearbox\.parameters\.generator_inertia = 151.*binds "
                                            r"gearbox\.generator_inertia to generator\.inertia.*set that instead"):
        apply_parameters(scenario, {"gearbox.generator_inertia": 151.0})


@pytest.mark.slow
def test_the_generator_inertia_alone_keeps_table7_within_1e4_of_the_monolithic_reference(fmu_dir, tmp_path):
    out = tmp_path / "out"
    proc = dtcosim("run", "--set", "generator.inertia=120", "--stop", "20", "--compare-reference", "--no-plots",
                   "-q", "--fmu-dir", str(fmu_dir), "--out", str(out), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["initial_values"]["gearbox.generator_inertia"] == 120.0  # from the generator, through FMI
    worst = max(abs(entry["relative_difference"][stat]) for name, entry in summary["comparison"]["variables"].items()
                if ".F_" in name for stat in ("mean", "std"))
    assert worst < 1e-4  # 1.1e-2 with the copy left at the Table 6 value
