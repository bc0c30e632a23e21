"""SSP 1.0 export/import: round trip, identical re-run, and the same system in libcosim."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.interop.ssp import NS, PARAMETER_SET, export_ssp, import_ssp
from orchestrator.provision.locate import resolve_fmu_paths
from orchestrator.run.runner import load_any
from tests.helpers.scenarios import dtcosim

TOY = """
name = "toy-ssp"
description = "sine into integrator"
[simulation]
start = 0.1
stop = 1.1
step = 0.01
output_interval = 0.02
window = [0.5, 1.1]
algorithm = "jacobi"
extrapolation = "linear"
[components.gain]
fmu = "ToyGain.fmu"
[components.gain.parameters]
u = 3.0
[components.src]
fmu = "ToySine.fmu"
[components.src.parameters]
amplitude = 2.5
[components.int]
fmu = "ToyIntegrator.fmu"
[components.fail]
fmu = "ToyFailer.fmu"
[components.fail.parameters]
mode = 0
[[connections]]
from = "src.y"
to = "int.u"
[[initial]]
from = "gain.y"
to = "int.x0"
[record]
variables = ["src.y", "int.*"]
"""


def test_export_import_round_trip_and_identical_run(toy_scenario, tmp_path):
    original = load_scenario(toy_scenario(TOY))
    system = resolve_system(original)
    ssp = export_ssp(system, tmp_path / "toy.ssp", CoSimulation(system).initial_values())
    with zipfile.ZipFile(ssp) as zf:
        names = set(zf.namelist())
        root = ET.fromstring(zf.read("SystemStructure.ssd"))
    assert names == {"SystemStructure.ssd", "resources/ToyGain.fmu", "resources/ToySine.fmu",
                     "resources/ToyIntegrator.fmu", "resources/ToyFailer.fmu"}
    # libcosim needs typed connectors for connected variables and the fixed-step algorithm
    int_connectors = {c.get("name"): c for c in root.findall(".//ssd:Component[@name='int']/ssd:Connectors/ssd:Connector", NS)}
    assert int_connectors["u"].get("kind") == "input" and int_connectors["u"].find("ssc:Real", NS) is not None
    fsa = root.find("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    assert float(fsa.get("baseStepSize")) == 0.01
    # the initial binding's value is in the parameter set for other hosts
    x0 = root.find(".//ssd:Component[@name='int']//ssv:Parameter[@name='x0']/ssv:Real", NS)
    assert float(x0.get("value")) == 6.0
    # one parameter-set name for all components: hosts that apply sets by name (ecos) apply them all
    assert {p.get("name") for p in root.iter(f"{{{NS['ssv']}}}ParameterSet")} == {PARAMETER_SET}

    # valid against the SSP 1.0 schema (fmpy validates while reading)
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(ssp))
    assert [c.name for c in ssd.system.elements] == ["gain", "src", "int", "fail"]

    back = import_ssp(ssp)
    assert back.name == original.name and back.description == original.description
    assert back.simulation == original.simulation
    assert back.connections == original.connections and back.initial == original.initial
    assert back.recorded == original.recorded
    assert [(c.name, dict(c.parameters)) for c in back.components] == [(c.name, dict(c.parameters)) for c in original.components]
    run_a = CoSimulation(system).run(handle_sigint=False)
    run_b = CoSimulation(resolve_system(back)).run(handle_sigint=False)
    assert run_a.names == run_b.names
    np.testing.assert_array_equal(run_a.time_s, run_b.time_s)
    np.testing.assert_array_equal(run_a.values, run_b.values)


@pytest.fixture(scope="module")
def paper_ssp(fmu_dir, tmp_path_factory):
    """The paper scenario exported with `dtcosim export-ssp`."""
    work = tmp_path_factory.mktemp("ssp")
    proc = dtcosim("export-ssp", "--out", str(work / "paper.ssp"), "--fmu-dir", str(fmu_dir), cwd=work)
    assert proc.returncode == 0, proc.stderr
    assert "generator.initial_speed" in proc.stdout
    return work / "paper.ssp"


@pytest.mark.slow
def test_a_full_disk_while_an_ssp_is_written_names_it_and_leaves_nothing(toy_scenario, tmp_path, monkeypatch,
                                                                        capsys):
    """export-ssp said 'error: No space left on device', naming no file (the archive's write error has none)."""
    import errno

    real_write = zipfile.ZipFile.write

    def full(self, filename, arcname=None, *args, **kwargs):
        if str(arcname).endswith("ToyIntegrator.fmu"):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(self, filename, arcname, *args, **kwargs)

    monkeypatch.setattr(zipfile.ZipFile, "write", full)
    from orchestrator.commands.cli import main

    out = tmp_path / "ssp" / "toy.ssp"
    assert main(["export-ssp", str(toy_scenario(TOY)), "--no-build", "--out", str(out)]) == 1
    errors = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert errors == [f"dtcosim export-ssp: error: {out}: No space left on device"]
    assert list(out.parent.iterdir()) == []


def test_reimported_paper_ssp_runs_identically(paper_ssp, fmu_dir):
    stop = dict(stop_s=3.0, window_s=(1.0, 3.0))
    toml = load_scenario(find_scenario(None)).with_simulation(**stop)
    from_toml = resolve_system(toml, fmu_paths=resolve_fmu_paths(toml, fmu_dir))
    from_ssp = resolve_system(load_any(paper_ssp).with_simulation(**stop))
    assert from_ssp.order == from_toml.order
    a = CoSimulation(from_toml).run(handle_sigint=False)
    b = CoSimulation(from_ssp).run(handle_sigint=False)
    assert a.names == b.names
    np.testing.assert_array_equal(a.values, b.values)


def ours_interval(path) -> float:
    """Output interval of a scenario or SSP [s]."""
    return load_any(path).simulation.output_interval_s


@pytest.fixture(scope="module")
def paper_ssp_1ms(fmu_dir, tmp_path_factory):
    """The paper scenario at H = 1 ms, exported as SSP (libcosim's coupling is first order: 1e-3 holds at 1 ms)."""
    work = tmp_path_factory.mktemp("ssp1ms")
    text = find_scenario("paper-60s").read_text()
    text = re.sub(r"(?m)^step = \S+", "step = 1.0e-3", text)
    text = re.sub(r"(?m)^output_interval = \S+", "output_interval = 1.0e-3", text)
    scenario = work / "paper-1ms.toml"
    scenario.write_text(text)
    assert load_scenario(scenario).simulation.step_s == 1e-3
    proc = dtcosim("export-ssp", str(scenario), "--out", str(work / "paper.ssp"), "--fmu-dir", str(fmu_dir), cwd=work)
    assert proc.returncode == 0, proc.stderr
    return work / "paper.ssp"


@pytest.mark.slow
def test_exported_ssp_runs_in_libcosim_like_dtcosim(paper_ssp_1ms):
    from orchestrator.interop.libcosim import run_ssp_in_libcosim

    paper_ssp = paper_ssp_1ms
    stop = 10.0
    lib = run_ssp_in_libcosim(paper_ssp, stop, ["generator.omega", "wind.omega"])
    ours = CoSimulation(resolve_system(load_any(paper_ssp).with_simulation(stop_s=stop, window_s=(0.0, stop)))).run(
        handle_sigint=False)
    assert lib.time_s.size == ours.time_s.size == round(stop / ours_interval(paper_ssp)) + 1 == 10001
    np.testing.assert_allclose(lib.time_s, ours.time_s, rtol=0, atol=1e-9)
    np.testing.assert_allclose(lib.values["wind.omega"], ours.column("wind.omega"), rtol=1e-12)
    deviation = np.max(np.abs(lib.values["generator.omega"] / ours.column("generator.omega") - 1.0))
    print(f"libcosim vs dtcosim generator speed, max relative deviation over [0, {stop:g}] s: {deviation:.2e}")
    assert deviation < 1e-3
