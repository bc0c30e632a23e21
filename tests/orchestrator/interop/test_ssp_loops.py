"""Imported systems whose FMUs declare no output dependencies (as 20-sim's FMUs in libcosim's crane demo).

Two toy masses coupled by a spring-damper (:mod:`tests.helpers.toy_fmus`: ToyMassA's
outputs x, v are states, ToyMassB's F is computed in its step) form a cycle of
connections A.x -> B.xa, B.F -> A.F. With ``dependencies=""`` the FMUs say their
outputs do not depend directly on their inputs; the same binaries with the
attribute removed say nothing, which FMI 2 reads as "depends on every input":
an algebraic loop for a master that needs an order. Jacobi needs none (every FMU
takes its partners' outputs of the previous communication point), so it runs
the undeclared system, with a note, to the same samples as the declared one.
"""

from __future__ import annotations

import re
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import AlgebraicLoopError
from orchestrator.interop.ssp import import_ssp
from orchestrator.result_files import read_timeseries
from tests.helpers.scenarios import dtcosim
from tests.helpers.ssp_documents import osp_experiment, real, ssd

MASSES = f"""
  <ssd:System name="masses">
    <ssd:Elements>
      <ssd:Component name="massA" source="resources/ToyMassA.fmu">
        <ssd:Connectors>{real("F", "input") + real("x", "output") + real("v", "output")}</ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="massB" source="resources/ToyMassB.fmu">
        <ssd:Connectors>{real("xa", "input") + real("va", "input") + real("F", "output") + real("x", "output")}
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="massA" startConnector="x" endElement="massB" endConnector="xa"/>
      <ssd:Connection startElement="massA" startConnector="v" endElement="massB" endConnector="va"/>
      <ssd:Connection startElement="massB" startConnector="F" endElement="massA" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>"""


def _without_dependencies(fmu: Path, dest: Path) -> None:
    """``fmu`` copied to ``dest`` with every ``dependencies``/``dependenciesKind`` attribute removed."""
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = re.sub(r'\s+dependencies(Kind)?="[^"]*"', "", data.decode("utf-8"))
                assert "dependencies" not in text
                data = text.encode("utf-8")
            zout.writestr(item, data)


@pytest.fixture
def masses(toy_dir, tmp_path):
    """``masses(declared)`` -> an SSP folder with the two masses, their dependencies declared or not."""
    def make(declared: bool) -> Path:
        folder = tmp_path / ("declared" if declared else "undeclared")
        (folder / "resources").mkdir(parents=True)
        for name in ("ToyMassA", "ToyMassB"):
            if declared:
                shutil.copy(toy_dir / f"{name}.fmu", folder / "resources" / f"{name}.fmu")
            else:
                _without_dependencies(toy_dir / f"{name}.fmu", folder / "resources" / f"{name}.fmu")
        (folder / "SystemStructure.ssd").write_text(ssd(MASSES, osp_experiment(step=0.01, stop=0.5)))
        return folder
    return make


def test_without_jacobi_the_loop_is_refused_naming_the_command_line_remedies(masses):
    with pytest.raises(AlgebraicLoopError) as err:
        resolve_system(import_ssp(masses(declared=False)))
    message = str(err.value)
    for remedy in ("--no-feedthrough massA.x", "--no-feedthrough massB.F", "--algorithm jacobi",
                   "--algebraic-loops iterate"):
        assert remedy in message, message
    resolve_system(import_ssp(masses(declared=True)))  # the declared system has no loop


def test_jacobi_runs_the_undeclared_system_with_a_note_to_the_samples_of_the_declared_one(masses):
    runs = {}
    for declared in (True, False):
        system = resolve_system(import_ssp(masses(declared)).with_simulation(algorithm="jacobi"))
        assert bool(system.notes) is not declared
        outcome = CoSimulation(system).run(handle_sigint=False)
        assert outcome.complete, outcome.error
        runs[declared] = outcome
    assert "only through outputs that declare no dependencies" in system.notes[0] and "libcosim" in system.notes[0]
    assert np.ptp(runs[True].column("massB.F")) > 1.0  # the masses move
    np.testing.assert_array_equal(runs[False].values, runs[True].values)


@pytest.mark.slow
def test_the_command_line_states_what_the_fmus_do_not(masses, tmp_path):
    declared, undeclared = masses(True), masses(False)
    out = {}
    for name, folder, options in [("declared", declared, []),
                                  ("options", undeclared, ["--no-feedthrough", "massA", "--no-feedthrough", "massB.F"])]:
        proc = dtcosim("run", str(folder), *options, "--no-plots", "--quiet", "--out", str(tmp_path / name),
                       cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        out[name] = read_timeseries(tmp_path / name / "timeseries.csv")
    # Gauss-Seidel with the outputs declared on the command line: the declared system's samples
    assert out["options"][0] == out["declared"][0]
    np.testing.assert_array_equal(out["options"][1], out["declared"][1])
    proc = dtcosim("run", str(undeclared), "--algorithm", "jacobi", "--check", cwd=tmp_path)
    assert proc.returncode == 0 and "note: the connections close a loop" in proc.stderr, proc.stderr
    proc = dtcosim("run", str(undeclared), "--algebraic-loops", "iterate", "--check", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = dtcosim("run", str(undeclared), "--no-feedthrough", "massC", "--check", cwd=tmp_path)
    assert proc.returncode != 0 and "--no-feedthrough = 'massC'" in proc.stderr and "massA, massB" in proc.stderr


def _dtc_simulation(ssp: Path) -> dict:
    from lxml import etree

    with zipfile.ZipFile(ssp) as zf:
        root = etree.fromstring(zf.read("SystemStructure.ssd"))
    el = root.find(".//{https://dtcosim.org/SSP/Annotations}Simulation")
    return dict(el.attrib)


@pytest.mark.slow
def test_an_export_for_a_jacobi_host_says_what_its_step_was_tuned_for(toy_scenario, tmp_path):
    scenario = toy_scenario()
    proc = dtcosim("export-ssp", str(scenario), "--target", "libcosim", "--out", str(tmp_path / "a.ssp"), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    attrs = _dtc_simulation(tmp_path / "a.ssp")
    # the scenario's own step was chosen for its Gauss-Seidel master: said in the SSD, the output, and warned about
    assert (attrs["algorithm"], attrs["target"], attrs["stepTunedFor"]) == ("jacobi", "libcosim", "gauss-seidel")
    assert "target libcosim: jacobi at H = 10 ms, the scenario's step, chosen for gauss-seidel" in proc.stdout
    assert "warning: libcosim steps with jacobi" in proc.stderr and "--algorithms jacobi" in proc.stderr
    proc = dtcosim("export-ssp", str(scenario), "--target", "ecos", "--step", "0.005", "--out",
                   str(tmp_path / "b.ssp"), cwd=tmp_path)
    assert proc.returncode == 0 and "steps with jacobi" not in proc.stderr, proc.stderr
    attrs = _dtc_simulation(tmp_path / "b.ssp")
    assert (attrs["algorithm"], attrs["target"], attrs["stepTunedFor"], attrs["step"]) == \
        ("jacobi", "ecos", "jacobi", "0.005")
    assert "target ecos: jacobi at H = 5 ms (given with --step)" in proc.stdout
    proc = dtcosim("export-ssp", str(scenario), "--target", "ecos", "--algorithm", "gauss-seidel", "--out",
                   str(tmp_path / "c.ssp"), cwd=tmp_path)
    assert proc.returncode != 0 and "--target ecos steps with jacobi" in proc.stderr
    assert not (tmp_path / "c.ssp").exists()


@pytest.mark.slow
def test_an_export_takes_the_step_the_coupling_study_measured_for_the_targets_algorithm(toy_scenario, tmp_path):
    import json

    scenario = toy_scenario()
    criteria = "every Table 7 statistic within 0.8 x 0.0001 and generator-speed RMS < 0.8 x 0.0001 rad/s"
    tuning = tmp_path / "steps.json"  # as benchmarks/coupling_study.py --json writes it
    tuning.write_text(json.dumps({"scenario": "toy", "window_s": [5.0, 60.0], "criteria": criteria,
                                  "largest_step_s": {"gauss-seidel": 0.01, "jacobi": 0.002}}))
    proc = dtcosim("export-ssp", str(scenario), "--target", "libcosim", "--tuning", str(tuning), "--out",
                   str(tmp_path / "a.ssp"), cwd=tmp_path)
    assert proc.returncode == 0 and "steps with jacobi" not in proc.stderr, proc.stderr
    attrs = _dtc_simulation(tmp_path / "a.ssp")
    assert (attrs["algorithm"], attrs["step"], attrs["stepTunedFor"]) == ("jacobi", "0.002", "jacobi")
    assert attrs["stepCriteria"] == criteria + ", measured with the window [5, 60] s"
    assert "target libcosim: jacobi at H = 2 ms, the largest step within the coupling study's criteria" in proc.stdout
    for change, key in [({"scenario": "paper-60s"}, "scenario = 'paper-60s'"),
                        ({"largest_step_s": {"gauss-seidel": 0.01, "jacobi": None}}, "largest_step_s.jacobi = None")]:
        tuning.write_text(json.dumps({"scenario": "toy", "criteria": criteria,
                                      "largest_step_s": {"jacobi": 0.002}, **change}))
        proc = dtcosim("export-ssp", str(scenario), "--target", "ecos", "--tuning", str(tuning), "--out",
                       str(tmp_path / "b.ssp"), cwd=tmp_path)
        assert proc.returncode != 0 and "steps.json" in proc.stderr and key in proc.stderr, proc.stderr
        assert not (tmp_path / "b.ssp").exists()
