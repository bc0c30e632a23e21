"""``dtcosim modes`` for every packaged scenario (issue 29, item 5): held and torque-driven rotors."""

from __future__ import annotations

import json

import pytest

from orchestrator.commands.cli import main as dtcosim
from orchestrator.inputs.scenario_file import packaged_scenarios
from tests.helpers.openfast_data import openfast_file

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fmu_home(tmp_path_factory):
    return tmp_path_factory.mktemp("modes-fmus")


@pytest.mark.parametrize("name", sorted(packaged_scenarios()))
def test_every_packaged_scenario_has_modes_paired_by_eigenvalue(name, fmu_home, tmp_path, capsys):
    if name.startswith("openfast"):
        openfast_file("DLC2.3_1.out")  # skips without the shared data
    out = tmp_path / "m"
    assert dtcosim(["modes", name, "--fmu-dir", str(fmu_home), "--out", str(out), "--speed-points", "3",
                    "--shapes", "2"]) == 0, capsys.readouterr().err
    text = capsys.readouterr().out
    summary = json.loads((out / "modes.json").read_text())
    modes = summary["modes"]
    assert modes and all(m["damped_frequency_hz"] is None or m["damped_frequency_hz"] <= m["undamped_frequency_hz"]
                         for m in modes)
    assert [m["undamped_frequency_hz"] for m in modes] == sorted(m["undamped_frequency_hz"] for m in modes)
    if name == "openfast-dlc11-torque":
        # the Rotor FMU drives the gearbox: free at both ends, at the record's first RotSpeed
        assert summary["rotor"]["driven_by"] == "torque" and summary["dof_names"][0] == "rotor"
        assert "torque-driven rotor 3.87592e+07 kg m^2" in text
        assert summary["operating_point"]["rotor_speed_rpm"] == pytest.approx(12.126, abs=1e-3)
        assert modes[0]["kinetic_energy_fraction"]["rotor"] > 0.05
    else:
        assert summary["rotor"] == "held (prescribed speed)" and "rotor held" in text


def test_verify_is_refused_for_a_torque_driven_rotor(fmu_home, tmp_path, capsys):
    openfast_file("DLC1.1_0_NREL5MW_OC3_spar_2.outb")
    assert dtcosim(["modes", "openfast-dlc11-torque", "--fmu-dir", str(fmu_home), "--out", str(tmp_path),
                    "--verify"]) == 1
    assert "--verify" in capsys.readouterr().err
