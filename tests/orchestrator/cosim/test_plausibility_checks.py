"""A scenario's implausible values are refused before any run, naming key, value, bound and reason (issue 30.2)."""

from __future__ import annotations

import re

import pytest

from orchestrator.commands import cli
from orchestrator.inputs.scenario_file import find_scenario, packaged_scenarios
from tests.helpers.openfast_data import openfast_file


def check(fmu_dir, capsys, *args: str, scenario: str = "paper-60s") -> tuple[int, str]:
    code = cli.main(["run", scenario, "--fmu-dir", str(fmu_dir), "--check", *args])
    return code, capsys.readouterr().err


#: (--set assignments, scenario key, value, expectation after "a plausible value")
REFUSED = [
    # the case: 0.3 meant in mm, read as 0.3 m (30 modules)
    (["gearbox.stage1.backlash=0.3"], "components.gearbox.parameters.stage1.backlash", "0.3",
     r"within \[0, 0\.002952\] m \(0\.295 modules: the circular backlash .*\); it is 0\.3 m in SI"),
    (["gearbox.stage2.width=0.006"], "components.gearbox.parameters.stage2.width", "0.006",
     r"within \[0\.0225, 0\.4\] m \(at least the tooth height 2\.25 m = 22\.5 mm"),
    (["gearbox.stage1.planet_inertia=1.56e7"], "components.gearbox.parameters.stage1.planet_inertia", "15600000.0",
     r"within \[1\.568, 32\.96\] kg m\^2"),
    (["gearbox.stage3.k0=5e5"], "components.gearbox.parameters.stage3.k0", "500000.0",  # N/mm^1.5 meant
     r"within \[7\.204e\+09, 1\.945e\+11\] N/m\^e \(the mesh's secant stiffness per face width at the rated force "
     r"3\.379e\+05 N, .* = 0\.00878 N/\(mm um\), within 3x of ISO 6336-1's c_gamma_alpha 15\.6 N/\(mm um\)"),
    # a value the scenario gives makes one it leaves implausible: the message says which
    (["gearbox.stage3.module=0.0015"], "components.gearbox.parameters.stage3.backlash", "'0.00056 (as built)'",
     r"within \[0, 0\.0004428\] m .*\(the FMU's own value, implausible with the values this scenario gives: "
     r"stage3\.module\)"),
    (["wind.omega0=160 rpm"], "components.wind.parameters.omega0", "16.755160819145562",
     r"within \[-2\.513, 2\.513\] rad/s \(at most 1\.5 x the drivetrain's rated rotor speed 16 rpm"),
    (["generator.counter_torque=254 kN m"], "components.generator.parameters.counter_torque", "254000.0",
     r"within \[-7\.62e\+04, 7\.62e\+04\] N m \(at most 3 x the drivetrain's rated torque 2\.54e\+04 N m"),
    (["generator.event1.kind=1", "generator.event1.start=1", "generator.event1.factor=10"],
     "components.generator.parameters.event1.factor", "10",
     r"within \[-3, 3\] \(a torque factor x 2\.54e\+04 N m at most 3 x the drivetrain's rated torque"),
]


@pytest.mark.parametrize("assignments, key, value, expected", REFUSED, ids=[r[1].rsplit(".", 1)[1] for r in REFUSED])
def test_an_implausible_value_is_refused_and_kept_when_allowed(fmu_dir, capsys, assignments, key, value, expected):
    sets = [a for item in assignments for a in ("--set", item)]
    code, err = check(fmu_dir, capsys, *sets)
    comp_param = key.split(".", 3)[1] + "." + key.split(".", 3)[3]
    assert code == 1 and re.search(
        rf"invalid scenario entry {re.escape(key)} = {re.escape(value)}: expected a plausible value {expected}.*; a "
        rf"deliberate value is kept by \[plausibility\] allow = \[\"{re.escape(comp_param)}\"\] in the scenario or "
        rf"--allow-implausible {re.escape(comp_param)}$", err.strip()), err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert check(fmu_dir, capsys, *sets, "--allow-implausible", comp_param)[0] == 0


def test_the_values_as_built_are_not_refused_again(fmu_dir, capsys):
    """Table 6's stage-2 width is the paper's (allowed where it is defined): restating it is no new finding."""
    assert check(fmu_dir, capsys, "--set", "gearbox.stage2.width=5 mm", "--set", "gearbox.stage1.backlash=0.56 mm")[0] == 0


def test_a_scenario_keeps_a_value_by_its_plausibility_table(fmu_dir, capsys, tmp_path):
    text = find_scenario("paper-60s").read_text() + '\n[plausibility]\nallow = ["gearbox.stage1.backlash"]\n'
    path = tmp_path / "deliberate.toml"
    path.write_text(text)
    assert check(fmu_dir, capsys, "--set", "gearbox.stage1.backlash=0.3", scenario=str(path))[0] == 0
    path.write_text(text.replace("stage1.backlash", "stage1.backlsh"))
    code, err = check(fmu_dir, capsys, scenario=str(path))
    assert code == 1 and "invalid scenario entry plausibility.allow[0] = 'gearbox.stage1.backlsh': expected a " \
                         "parameter of gearbox (Gearbox.fmu) (did you mean stage1.backlash" in err


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(packaged_scenarios()))
def test_every_packaged_scenario_is_plausible(name, tmp_path_factory, capsys):
    if name.startswith("openfast"):
        openfast_file("DLC1.1_0_NREL5MW_OC3_spar_0.outb")  # skips without the shared data
    home = tmp_path_factory.getbasetemp() / "plausible-fmus"
    assert cli.main(["run", name, "--fmu-dir", str(home), "--check"]) == 0, capsys.readouterr().err
