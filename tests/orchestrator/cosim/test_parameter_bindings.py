"""Parameter bindings (``[[bindings]]``): a value two FMUs need has one source, bound through FMI.

The Gearbox's interface model needs the generator inertia; the GeneratorRotor owns it. Bound, changing the
generator's inertia alone keeps the co-simulation on the monolithic reference; a value for the bound copy is
refused wherever it comes from; SSP export keeps the link (one system-level value mapped to both) and the
import restores it.
"""

from __future__ import annotations

import json
import re
import zipfile

import numpy as np
import pytest
import tomllib

from fmus import registry
from fmus.slaves.record import GEARBOX, GENERATOR
from orchestrator.commands import cli
from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import apply_parameters
from orchestrator.inputs.scenario_file import find_scenario, load_scenario, packaged_scenarios, scenario_from_dict
from orchestrator.interop.ssp_import import import_ssp
from orchestrator.provision.locate import resolve_fmu_paths
from tests.helpers.scenarios import dtcosim

# the sine's amplitude is the gain's gain: y = amplitude * u
TOYS = """
name = "bound"
[simulation]
stop = 0.3
step = 0.1
[components.src]
fmu = "ToySine.fmu"
[components.src.parameters]
amplitude = 3.0
[components.gain]
fmu = "ToyGain.fmu"
[components.gain.parameters]
u = 2.0
[[bindings]]
from = "src.amplitude"
to = "gain.gain"
[record]
variables = ["gain.y"]
"""


def test_a_bound_parameter_takes_its_sources_value_through_fmi(toy_scenario):
    system = resolve_system(load_scenario(toy_scenario(TOYS)))
    assert system.parameter_values("gain")["gain"] == 3.0  # what the physics view and the checks see
    out = CoSimulation(system).run(handle_sigint=False)
    assert out.complete and out.initial_values == {"gain.gain": 3.0}
    np.testing.assert_array_equal(out.column("gain.y"), 6.0)  # 3.0 (the sine's amplitude, not ToyGain's 2) x 2.0
    changed = resolve_system(apply_parameters(load_scenario(toy_scenario(TOYS)), {"src.amplitude": 5.0}))
    np.testing.assert_array_equal(CoSimulation(changed).run(handle_sigint=False).column("gain.y"), 10.0)


@pytest.mark.parametrize("change, key, expected", [
    (lambda t: t.replace("u = 2.0", "u = 2.0\ngain = 4.0"), r"components\.gain\.parameters\.gain",
     r"no value: gain\.gain takes its value from src\.amplitude .*set src\.amplitude instead"),
    (lambda t: t + '[[bindings]]\nfrom = "src.frequency"\nto = "gain.gain"\n', r"bindings\[1\]\.to",
     r"a parameter bound once \(already to src\.amplitude\)"),
    (lambda t: t + '[[bindings]]\nfrom = "gain.gain"\nto = "src.amplitude"\n', r"bindings",
     r"bindings without a cycle"),
    (lambda t: t.replace('to = "gain.gain"', 'to = "src.frequency"'), r"bindings\[0\]\.to",
     r"a parameter of another component than 'src'"),
    (lambda t: t + '[[connections]]\nfrom = "src.y"\nto = "gain.gain"\n', r"bindings\[0\]\.to",
     r"not also set by the connection from src\.y"),
])
def test_a_binding_that_cannot_hold_is_refused_naming_the_key(toy_scenario, change, key, expected):
    with pytest.raises(ScenarioError, match=key + ".*" + expected):
        load_scenario(toy_scenario(change(TOYS)))


@pytest.mark.parametrize("source, target, expected", [
    ("src.y", "gain.gain", r"bindings\[0\]\.from.*a parameter \(causality parameter or calculatedParameter\); "
                           r"y has causality output"),
    ("src.amplitude", "gain.u", r"bindings\[0\]\.to.*a parameter \(causality parameter\); u has causality input"),
])
def test_a_binding_joins_parameters_only(toy_scenario, source, target, expected):
    text = TOYS.replace('from = "src.amplitude"\nto = "gain.gain"', f'from = "{source}"\nto = "{target}"')
    with pytest.raises(ScenarioError, match=expected):
        resolve_system(load_scenario(toy_scenario(text.replace("u = 2.0", ""))))


def test_a_set_of_the_bound_copy_is_refused_on_the_command_line(capsys):
    assert cli.main(["run", "--set", "gearbox.generator_inertia=120", "--check"]) == 1
    err = capsys.readouterr().err
    assert "components.gearbox.parameters.generator_inertia = 120" in err
    assert "takes its value from generator.inertia" in err and "--set generator.inertia=" in err


def _kind(fmu: str):
    kind = registry.of_file(fmu)
    return kind.role if kind is not None else None


@pytest.mark.parametrize("name", sorted(packaged_scenarios()))
def test_every_packaged_gearbox_takes_the_generator_inertia_from_the_generator(name):
    path = packaged_scenarios()[name]
    doc = tomllib.loads(path.read_text())
    roles = {c: _kind(t["fmu"]) for c, t in doc["components"].items()}
    if GEARBOX not in roles.values() or GENERATOR not in roles.values():
        pytest.skip(f"{name} has no Gearbox and GeneratorRotor")
    gearbox = next(c for c, r in roles.items() if r == GEARBOX)
    generator = next(c for c, r in roles.items() if r == GENERATOR)
    scenario = scenario_from_dict(doc, name=name, base_dir=path.parent, source=str(path))
    assert scenario.bound_source(f"{gearbox}.generator_inertia") == f"{generator}.inertia"


@pytest.mark.slow
def test_changing_the_generator_inertia_alone_keeps_table7_on_the_reference(fmu_dir, tmp_path, capsys):
    """The issue's case: --set generator.inertia=120 moved the Table 7 statistics 1.1e-2 from the monolithic
    reference while the Gearbox kept its copy (151 kg m^2); bound, they stay within the paper scenario's 1e-4."""
    out = tmp_path / "run"
    assert cli.main(["run", "--set", "generator.inertia=120", "--compare-reference", "--fmu-dir", str(fmu_dir),
                     "--out", str(out), "--no-plots", "-q"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["initial_values"]["gearbox.generator_inertia"] == 120.0
    variables = summary["comparison"]["variables"]
    paper = load_scenario(find_scenario(None))
    gearbox = resolve_system(paper, fmu_paths=resolve_fmu_paths(paper, fmu_dir)).roles["gearbox"]
    forces = [s.variable for s in gearbox.of_kind("contact_force")]
    worst = max(abs(variables[f"gearbox.{f}"]["relative_difference"][m]) for f in forces for m in ("mean", "std"))
    assert worst < 1e-4, worst
    # without the link (the binding removed, the Gearbox's own 151 kg m^2) the same change is far off
    text = packaged_scenarios()["paper-60s"].read_text()
    unlinked = tmp_path / "unlinked.toml"
    unlinked.write_text(re.sub(r'\[\[bindings\]\]\nfrom = "generator.inertia"\nto = "gearbox.generator_inertia"\n',
                               "", text))
    assert "[[bindings]]" not in unlinked.read_text()
    assert cli.main(["run", str(unlinked), "--set", "generator.inertia=120", "--compare-reference", "--fmu-dir",
                     str(fmu_dir), "--out", str(tmp_path / "unlinked"), "--no-plots", "-q"]) == 0
    variables = json.loads((tmp_path / "unlinked" / "summary.json").read_text())["comparison"]["variables"]
    assert max(abs(variables[f"gearbox.{f}"]["relative_difference"][m]) for f in forces for m in ("mean", "std")) > 1e-3


@pytest.mark.slow
def test_the_exported_ssp_keeps_the_link(fmu_dir, tmp_path):
    ssp = tmp_path / "paper.ssp"
    proc = dtcosim("export-ssp", "--set", "generator.inertia=120", "--stop", "1", "--out", str(ssp),
                   "--fmu-dir", str(fmu_dir), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "gearbox.generator_inertia is bound to generator.inertia" in proc.stderr  # libcosim/ecos: change both
    with zipfile.ZipFile(ssp) as zf:
        ssd = zf.read("SystemStructure.ssd").decode()
    # one value on the system, mapped to the source and the bound copy (SSP 1.0 system-level parameter binding) ...
    system_binding = ssd[ssd.index("<ssd:ParameterBindings>"):ssd.index("<ssd:Elements>")]
    assert '<ssv:Parameter name="generator.inertia">' in system_binding and 'value="120.0"' in system_binding
    for target in ("generator.inertia", "gearbox.generator_inertia"):
        assert f'<ssm:MappingEntry source="generator.inertia" target="{target}" />' in system_binding
    assert '<dtc:Binding source="generator.inertia" target="gearbox.generator_inertia" />' in ssd
    # ... which dtcosim's import turns back into the binding; a new system value reaches both
    scenario = import_ssp(ssp)
    assert [str(b) for b in scenario.bindings] == ["gearbox.generator_inertia = generator.inertia"]
    assert "generator_inertia" not in scenario.component("gearbox").parameters
    folder = tmp_path / "edited"
    with zipfile.ZipFile(ssp) as zf:
        zf.extractall(folder)
    text = (folder / "SystemStructure.ssd").read_text()
    (folder / "SystemStructure.ssd").write_text(text.replace(system_binding, system_binding.replace(
        'value="120.0"', 'value="130.0"')))
    system = resolve_system(import_ssp(folder))
    assert system.parameter_values("generator")["inertia"] == 130.0
    assert system.parameter_values("gearbox")["generator_inertia"] == 130.0
    assert CoSimulation(system).initial_values()["gearbox.generator_inertia"] == 130.0


STUDY = """
name = "inertia"
engine = "cosim"
measures = ["wind.omega:std"]
[base]
scenario = "paper-60s"
[simulation]
stop = 0.1
window = [0.0, 0.1]
[[axes]]
parameter = "{parameter}"
values = [120.0, 151.0]
"""


def test_a_study_varies_the_source_and_refuses_the_bound_copy(fmu_dir, write_study, capsys):
    assert cli.main(["sweep", str(write_study(STUDY.format(parameter="generator.inertia"))), "--check",
                     "--fmu-dir", str(fmu_dir)]) == 0
    capsys.readouterr()
    path = write_study(STUDY.format(parameter="gearbox.generator_inertia"), "copy.toml")
    assert cli.main(["sweep", str(path), "--check", "--fmu-dir", str(fmu_dir)]) == 1
    assert capsys.readouterr().err.strip().endswith(
        "axes[0].parameter = 'gearbox.generator_inertia': expected a parameter the scenario does not bind: "
        "gearbox.generator_inertia takes its value from generator.inertia ([[bindings]]); vary generator.inertia "
        "instead")
