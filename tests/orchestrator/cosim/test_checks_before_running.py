"""Everything that can be checked before a run is: ranges the FMUs declare, FMI Integer range, time grids,
sizes, broken FMU files and odd input files, each with one named error and before any FMU is instantiated."""

from __future__ import annotations

import math
import resource
import shutil
import subprocess
import sys
import zipfile

import pytest

from fmus.model_description import rewrite_archive

from orchestrator.commands.cli import main
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import apply_parameters
from orchestrator.inputs.scenario import SimulationSettings
from orchestrator.inputs.scenario_file import find_scenario, load_scenario


@pytest.fixture(scope="module")
def paper(fmu_dir):
    """The paper's scenario with the suite's FMUs: ``paper(values) -> resolved system``."""
    from orchestrator.provision.project_fmus import ensure_fmus

    base = load_scenario(find_scenario("paper-60s"))
    paths = ensure_fmus(base, fmu_dir, build=False)

    def resolve(values=None, **sim):
        scenario = apply_parameters(base, values or {})
        if sim:
            scenario = scenario.with_simulation(**sim)
        return resolve_system(scenario, fmu_paths=paths)

    return resolve


@pytest.mark.parametrize("values, key, expected", [
    ({"gearbox.stage1.k0": -1.0}, "components.gearbox.parameters.stage1.k0", "> 0 (within [1e-30, 1e+30])"),
    ({"gearbox.stage2.exponent": 3.5}, "components.gearbox.parameters.stage2.exponent", "within [1, 3]"),
    ({"gearbox.solver.max_steps": 0}, "components.gearbox.parameters.solver.max_steps",
     "an integer >= 1 (at most 2147483647, an FMI Integer)"),
    ({"wind.seed": 4294967297}, "components.wind.parameters.seed",
     "an FMI Integer within [-2147483648, 2147483647] (32 bits)"),
    ({"wind.seed": -1}, "components.wind.parameters.seed", "an integer >= 0 (at most 2147483647, an FMI Integer)"),
    ({"wind.n_harmonics": 2147483647}, "components.wind.parameters.n_harmonics", "an integer within [1, 100000]"),
    ({"generator.inertia": 5e-324}, "components.generator.parameters.inertia", "> 0 (within [1e-30, 1e+30])"),
    ({"gearbox.stage1.planet_mass": 1e308}, "components.gearbox.parameters.stage1.planet_mass",
     "> 0 (within [1e-30, 1e+30])"),
    ({"wind.amplitude": 2}, "components.wind.parameters.amplitude", "0 = variance, 1 = paper"),
    ({"gearbox.stage3.contact_law": 2}, "components.gearbox.parameters.stage3.contact_law", "0 (CFS) or 1 (impact)"),
    # coupled: each value is within its bounds, the model refuses the pair (its own check, on the host)
    ({"wind.f_min": 5.0, "wind.f_max": 1.0}, "components.wind.parameters.f_max", "> f_min = 5 rad/s"),
    ({"gearbox.stage1.sun_radius": 2.0}, "components.gearbox.parameters.stage1.ring_radius", "> sun radius"),
])
def test_values_the_fmus_refuse_are_refused_before_instantiation_with_the_fmus_message(paper, values, key,
                                                                                       expected):
    with pytest.raises(ScenarioError) as info:
        paper(values)
    assert info.value.key == key and str(info.value.expected).startswith(expected), str(info.value)


def test_run_check_rejects_a_negative_stiffness(fmu_dir, capsys):
    status = main(["run", "--fmu-dir", str(fmu_dir), "--check", "--set", "gearbox.stage1.k0=-1"])
    assert status == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.endswith("invalid scenario entry components.gearbox.parameters.stage1.k0 = -1: "
                        "expected > 0 (within [1e-30, 1e+30])")


def test_the_host_check_gives_the_fmus_own_expectation(fmu_path):
    """The FMU's record bounds are what its slave raises: probed at build, not written twice."""
    from tests.helpers.fmu_hosts import Instance

    inst = Instance(fmu_path("Gearbox"), "k0")
    inst.enter(**{"stage1.k0": -1.0})
    with pytest.raises(Exception):
        inst.fmu.exitInitializationMode()
    assert any("invalid parameter stage1.k0 = -1.0: expected > 0 (within [1e-30, 1e+30])" in m
               for m in inst.error_messages())
    inst.free()


def test_a_huge_number_of_harmonics_is_refused_before_anything_is_allocated():
    """Under a 1 GiB address-space limit: 2^31 - 1 harmonics (16 GiB of phases) give the named error, not a
    MemoryError (the speed is measured by hand: see the notes)."""
    code = ("from components.model.wind import WindParameters, RotorSpeedProcess\n"
            "from components.errors import ParameterError\n"
            "try:\n    RotorSpeedProcess(WindParameters(n_harmonics=2147483647))\n"
            "except ParameterError as exc:\n    print(exc)\n")

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, preexec_fn=limit)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == ("invalid parameter wind.n_harmonics = 2147483647: expected an integer within "
                                  "[1, 100000]")


@pytest.mark.parametrize("sim, key, expected", [
    ({"step_s": 1e308}, "simulation.step", "a step no longer than the run, stop - start = 60 s"),
    ({"stop_s": 1e308}, "simulation.step", "a step of at least 1e-09 x max(|start|, |stop|) = 1e+299 s"),
    ({"step_s": 1e-300}, "simulation.step", "a step of at least 1e-09 x max(|start|, |stop|) = 6e-08 s"),
    ({"start_s": -1e308, "stop_s": 1e308}, "simulation.stop", "a run whose length stop - start is a finite number"),
    ({"output_interval_s": 100.0}, "simulation.output_interval", "an interval no longer than the run"),
])
def test_absurd_time_grids_are_refused(sim, key, expected):
    base = dict(stop_s=60.0, step_s=1e-3, window_s=None)
    base.update(sim)
    with pytest.raises(ScenarioError) as info:
        SimulationSettings(**base)
    assert info.value.key == key and str(info.value.expected).startswith(expected)


def test_a_run_whose_results_would_not_fit_the_limit_is_refused(paper):
    with pytest.raises(ScenarioError, match=r"simulation.output_interval = 0.001: expected an interval giving at most "
                                            r"100,000,000 recorded values per run; this one gives 30,000,001 samples "
                                            r"x 23 columns \(time and 22 variables\) = 690,000,023"):
        paper(stop_s=30000.0, step_s=1e-3, output_interval_s=1e-3, window_s=(5.0, 60.0))
    paper(stop_s=30000.0, window_s=(5.0, 60.0), output_interval_s=1.0)  # fewer samples: fine


def test_three_seeds_within_the_fmi_range_give_three_different_wind_series(fmu_dir, tmp_path):
    from orchestrator.cosim.master import CoSimulation

    text = (f'name = "wind"\n[simulation]\nstop = 0.2\nstep = 0.01\n[components.wind]\nfmu = "{fmu_dir}/WindSource.fmu"\n'
            '[record]\nvariables = ["wind.omega"]\n')
    (tmp_path / "wind.toml").write_text(text)
    base = load_scenario(tmp_path / "wind.toml")
    series = []
    for seed in (1, 2147483646, 2147483647):
        out = CoSimulation(resolve_system(apply_parameters(base, {"wind.seed": seed}))).run(handle_sigint=False)
        series.append(tuple(out.column("wind.omega")))
    assert len(set(series)) == 3


def _copy_without(src, dst, prefix):
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            if not info.filename.startswith(prefix):
                zout.writestr(info, zin.read(info))


@pytest.mark.parametrize("damage, expected", [
    ("resources/", "no resources/slavemodule.txt: a PythonFMU binary cannot find its slave"),
    ("binaries/linux64/", "no co-simulation binary for this platform (linux64: binaries/linux64/Gearbox.so); "
                           "it has binaries for: win64"),
    ("not a zip", "a readable FMU"),
    ("truncated", "a readable FMU"),
    # a module that does not exist crashed `dtcosim run` with exit 139 and passed validate (issue 35.1)
    ("missing module", "resources/slavemodule.txt names the slave module 'no_such_module', which is not in "
                       "resources/"),
])
def test_a_broken_fmu_file_is_a_named_error_not_a_crash(fmu_dir, tmp_path, capsys, damage, expected):
    folder = tmp_path / "fmus"
    shutil.copytree(fmu_dir, folder)
    gearbox = folder / "Gearbox.fmu"
    if damage == "not a zip":
        gearbox.write_text("not an archive")
    elif damage == "truncated":
        gearbox.write_bytes(gearbox.read_bytes()[:2000])
    elif damage == "missing module":
        rewrite_archive(gearbox, {"resources/slavemodule.txt": b"no_such_module\n"})
    else:
        _copy_without(fmu_dir / "Gearbox.fmu", gearbox, damage)
    assert main(["run", "--fmu-dir", str(folder), "--no-build", "--stop", "0.1", "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert "invalid scenario entry components.gearbox.fmu" in err and expected in err, err
    assert main(["validate", str(gearbox)]) == 1  # validate names the problem too
    out = capsys.readouterr().out
    assert "problem" in out and "Traceback" not in out


def test_a_scenario_that_is_not_utf8_is_a_named_error(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes('name = "x"\n# caf\xe9\n'.encode("latin-1"))
    with pytest.raises(ScenarioError, match=r"invalid scenario entry \(file\) = '.*latin1.toml': expected a UTF-8 text "
                                            r"file \(byte 0xe9 on line 2 is not UTF-8\)"):
        load_scenario(path)


def test_a_component_name_ending_in_a_newline_is_refused(tmp_path):
    from orchestrator.inputs.scenario import Component

    with pytest.raises(ScenarioError, match="a component name of letters"):
        Component("gearbox\n", "Gearbox.fmu")


@pytest.mark.parametrize("table, expected", [
    ('ldd_bins = 2000000000', "analysis.ldd_bins = 2000000000: expected a bin count within [1, 100000]"),
])
def test_analysis_sizes_are_bounded(toy_scenario, table, expected):
    from tests.helpers.scenarios import TOY_SCENARIO

    path = toy_scenario(TOY_SCENARIO + f"\n[analysis]\n{table}\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert expected in str(info.value)


def test_the_limits_are_stated_in_the_docs():
    from pathlib import Path

    from orchestrator.inputs import limits

    docs = (Path(__file__).parents[3] / "docs" / "orchestrator.md").read_text()
    for text in ("100 000 000", "100 000 harmonics", "1e-9", "100 000 bins", "1 GiB"):
        assert text in docs, text
    assert limits.MAX_RESULT_VALUES == 100_000_000 and math.isclose(limits.MIN_RELATIVE_STEP, 1e-9)


@pytest.mark.parametrize("damage", ["truncated", "no record"])
def test_a_broken_fmu_in_the_folder_dtcosim_builds_into_is_rebuilt(fmu_dir, tmp_path, damage):
    """An interrupted build of an older version left a broken archive that later runs never rebuilt ("expected a
    readable FMU" until the user deleted it; issue 35.3): in the folder dtcosim builds into it is built again."""
    from orchestrator.provision.project_fmus import ensure_fmus
    from orchestrator.provision.staleness import broken_fmu

    folder = tmp_path / "fmus"
    shutil.copytree(fmu_dir, folder)
    gearbox = folder / "Gearbox.fmu"
    if damage == "truncated":
        gearbox.write_bytes(gearbox.read_bytes()[:3000])
    else:
        _copy_without(fmu_dir / "Gearbox.fmu", gearbox, "resources/dtcosim.json")
    assert broken_fmu(gearbox)
    paths = ensure_fmus(load_scenario(find_scenario("paper-60s")), folder)
    assert paths["gearbox"] == gearbox and broken_fmu(gearbox) is None
    with zipfile.ZipFile(gearbox) as archive:
        assert archive.testzip() is None
