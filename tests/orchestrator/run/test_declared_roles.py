"""Analyses follow declared roles and signals, never names: a third-party generator in the paper's system."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from orchestrator.cosim.physics_view import PhysicsUnavailable, physics_view
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.scenario_file import load_scenario
from orchestrator.result_files import read_timeseries
from tests.helpers.scenarios import dtcosim, write_scenario

FOREIGN_GENERATOR = """
name = "foreign-generator"
[simulation]
stop = 1.0
step = 1.0e-3
window = [0.5, 1.0]

[components.wind]
fmu = "WindSource.fmu"
[components.gearbox]
fmu = "Gearbox.fmu"
[components.generator]
fmu = "ToyGenerator.fmu"
{generator_role}

[[connections]]
from = "wind.omega"
to = "gearbox.omega_rotor"
[[connections]]
from = "wind.phi"
to = "gearbox.phi_rotor"
[[connections]]
from = "generator.omega"
to = "gearbox.omega_gen"
[[connections]]
from = "generator.phi"
to = "gearbox.phi_gen"
[[connections]]
from = "gearbox.shaft_torque"
to = "generator.shaft_torque"
[[initial]]
from = "gearbox.omega_out"
to = "generator.initial_speed"

[record]
variables = ["wind.omega", "gearbox.stage*.F_*", "gearbox.shaft*.torque", "generator.omega", "generator.F_x"]
"""


@pytest.fixture
def foreign_scenario(fmu_dir, toy_dir, tmp_path):
    """``make(generator_role="")`` -> scenario file with the project's wind and gearbox and the toy generator."""
    for name in ("WindSource", "Gearbox"):
        shutil.copy(fmu_dir / f"{name}.fmu", tmp_path / f"{name}.fmu")
    shutil.copy(toy_dir / "ToyGenerator.fmu", tmp_path / "ToyGenerator.fmu")
    return lambda generator_role="": write_scenario(tmp_path, FOREIGN_GENERATOR.format(generator_role=generator_role))


@pytest.mark.slow
def test_a_foreign_generator_runs_and_the_summary_names_what_was_skipped(foreign_scenario, tmp_path):
    out = tmp_path / "out"
    proc = dtcosim("run", str(foreign_scenario()), "--out", str(out), "--no-build", "--compare-reference", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is True
    skipped = {s["analysis"]: s["reason"] for s in summary["analyses_skipped"]}
    # the Fig. 16 statistic and plot need a generator, the reference a dtcosim GeneratorRotor: skipped, with reasons
    assert "role generator" in skipped["generator_vs_ideal"] and "generator_vs_ideal" not in summary
    assert "role generator" in skipped["plot:generator_speed"]
    assert "generator" in skipped["comparison"] and "skipped" in summary["comparison"]
    # the gearbox's declared contact forces are analysed; the foreign output named like one is not
    meshes = summary["contact_loss"]["meshes"]
    assert "gearbox.stage1.F_sp[1]" in meshes and "gearbox.stage3.F_mesh" in meshes
    assert "generator.F_x" not in meshes
    assert "generator.F_x" not in summary["fatigue"]["del"]
    assert (out / "contact_forces.png").is_file() and (out / "rotor_speed.png").is_file()
    assert not (out / "generator_speed.png").exists()


@pytest.mark.slow
def test_a_declared_foreign_generator_gets_the_generator_analyses(foreign_scenario, tmp_path):
    path = foreign_scenario('role = "generator"\nsignals = { generator_speed = "omega" }')
    out = tmp_path / "out"
    proc = dtcosim("run", str(path), "--out", str(out), "--no-build", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    fig16 = summary["generator_vs_ideal"]
    assert fig16["ratio_source"] == "the Gearbox FMU's record"
    assert abs(fig16["ratio"] - 100.0) < 1e-9
    # the statistic is that of the declared signals: omega_gen / (ratio omega_rotor) - 1 over the window
    header, data = read_timeseries(out / "timeseries.csv")
    t, rotor, gen = data[:, 0], data[:, header.index("wind.omega [rad/s]")], data[:, header.index("generator.omega [-]")]
    inside = (t >= 0.5 - 1e-12) & (t <= 1.0 + 1e-12)
    expected = np.mean(gen[inside] / (100.0 * rotor[inside]) - 1.0)
    assert fig16["relative_deviation"]["mean"] == pytest.approx(expected, rel=1e-9)
    assert (out / "generator_speed.png").is_file()
    # still no dtcosim record of the generator: no monolithic physics
    with pytest.raises(PhysicsUnavailable, match="GeneratorRotor|generator"):
        physics_view(resolve_system(load_scenario(path)))


@pytest.mark.parametrize("declaration, key, expected", [
    ('role = "generatr"', "components.generator.role", "one of wind_source, gearbox, generator"),
    ('signals = { generator_speed = "omega" }', "components.generator.signals", "signals only together with role"),
    ('role = "generator"\nsignals = { speed = "omega" }', "components.generator.signals.speed",
     "generator_speed"),
    ('role = "generator"\nsignals = { generator_speed = "omga" }', "components.generator.signals.generator_speed",
     "did you mean omega"),
    ('role = "generator"\nsignals = { generator_speed = ["omega", "phi"] }',
     "components.generator.signals.generator_speed", "one variable name"),
])
def test_bad_role_declarations_are_named_errors(foreign_scenario, declaration, key, expected):
    with pytest.raises(ScenarioError, match=expected) as info:
        resolve_system(load_scenario(foreign_scenario(declaration)))
    assert info.value.key == key


def test_a_role_contradicting_the_fmus_record_is_refused(foreign_scenario):
    path = foreign_scenario()
    text = path.read_text().replace('[components.gearbox]\nfmu = "Gearbox.fmu"',
                                    '[components.gearbox]\nfmu = "Gearbox.fmu"\nrole = "generator"')
    path.write_text(text)
    with pytest.raises(ScenarioError, match="the role Gearbox.fmu declares in its record") as info:
        resolve_system(load_scenario(path))
    assert info.value.key == "components.gearbox.role"


FOREIGN_GEARBOX = """
name = "foreign-gearbox"
[simulation]
stop = 2.0
step = 0.01
[components.gearbox]
fmu = "ToyGearbox.fmu"
role = "gearbox"
signals = { shaft_torque = "F_x", contact_force = "shaft1.torque" }
"""


def test_a_foreign_gearbox_gets_its_analyses_by_declared_kind_and_unit_not_by_name(toy_dir, tmp_path):
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.run.analyses import analyse_run

    shutil.copy(toy_dir / "ToyGearbox.fmu", tmp_path / "ToyGearbox.fmu")
    system = resolve_system(load_scenario(write_scenario(tmp_path, FOREIGN_GEARBOX)))
    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    fatigue = analyse_run(system, outcome, tmp_path, plots=False).summary["fatigue"]
    # the declared shaft torque F_x has the LDD, the contact force called shaft1.torque none
    assert list(fatigue["ldd"]) == ["gearbox.F_x"] and fatigue["shaft_torques"] == ["gearbox.F_x"]
    assert fatigue["ldd"]["gearbox.F_x"]["unit"] == "N.m"
    # units from the modelDescription, not from the names
    assert fatigue["del"]["gearbox.F_x"]["unit"] == "N.m" and fatigue["del"]["gearbox.shaft1.torque"]["unit"] == "N"
    assert fatigue["del"]["gearbox.F_x"]["max_range"] == pytest.approx(2000.0, rel=1e-9)  # 2000 +- 1000 sampled at peaks
