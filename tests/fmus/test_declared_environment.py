"""The declared requirements are complete: the FMUs run in a fresh environment holding only them (and fmpy)."""

from __future__ import annotations

import csv
import shutil
import zipfile

import numpy as np
import pytest

from components.compile.aot import ENVIRONMENT_VARIABLE as AOT_VARIABLE
from components.compile.aot import missing
from components.compile.choice import requested_kernel
from fmus.model_description import rewrite_archive
from fmus.selftest import environment_python, run_fmus
from orchestrator.cosim.compiled_kernels import aot_kernels
from tests.helpers.fmu_hosts import load_driver, run_python
from tests.helpers.scenarios import dtcosim

H = 1.0e-3
#: (column of `dtcosim run`'s timeseries.csv, key of the fmpy loop)
SIGNALS = (("wind.omega", "WindSource.omega"), ("gearbox.shaft_torque", "Gearbox.shaft_torque"),
           ("gearbox.omega_out", "Gearbox.omega_out"), ("gearbox.stage1.F_sp[1]", "Gearbox.stage1.F_sp[1]"),
           ("gearbox.torque_rotor", "Gearbox.torque_rotor"), ("generator.omega", "GeneratorRotor.omega"))


def read_timeseries(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    names = [h.split(" [")[0] for h in rows[0]]
    data = np.array([[float(x) for x in row] for row in rows[1:]])
    return {n: data[:, i] for i, n in enumerate(names)}


@pytest.mark.slow
def test_environment_has_nothing_but_the_declared_requirements_and_fmpy(requirements_python):
    for module in ("components", "fmus", "orchestrator", "scipy"):
        assert run_python(requirements_python, "-c", f"import {module}").returncode != 0, module
    assert run_python(requirements_python, "-c", "import numpy, fmpy").returncode == 0


@pytest.mark.slow
def test_one_second_cosimulation_agrees_with_dtcosim_run(fmu_dir, requirements_python, tmp_path):
    out = tmp_path / "loop.npz"
    # the numpy path there (not the kernels compiled ahead of time, which need no numba either: test_hosts.py)
    loop = run_python(requirements_python, load_driver("fmu_loop").__file__, str(fmu_dir), "1.0", str(H), str(out),
                      "scenario", env={AOT_VARIABLE: "0"})
    assert loop.returncode == 0, loop.stderr[-3000:]
    bare = np.load(out)
    assert list(bare["modules"]) and all(m.startswith("_dtcosim_") for m in bare["modules"])
    # the declared environment has numpy but not the optional numba: the FMU runs its numpy path, as does this run
    run = dtcosim("run", "--stop", "1", "--step", str(H), "--output-interval", str(H), "--no-plots", "--fmu-dir", str(fmu_dir),
                  "--out", str(tmp_path / "run"), cwd=tmp_path,
                  env={"DTCOSIM_FMU_DIR": str(fmu_dir), "DTCOSIM_KERNEL": "numpy"}, timeout=600)
    assert run.returncode == 0, run.stderr
    series = read_timeseries(tmp_path / "run" / "timeseries.csv")
    np.testing.assert_allclose(series["time"], bare["time"], rtol=0, atol=1e-15)
    for column, key in SIGNALS:
        reference = series[column]
        assert np.max(np.abs(bare[key] - reference)) <= 1.0e-12 * np.max(np.abs(reference)), column
    torque = series["gearbox.shaft_torque"]  # a real signal, not zeros: the generator's load from the start (issue 29)
    assert abs(torque[0] - 25.4e3) < 1.0 and np.ptp(torque) > 1.0


@pytest.mark.slow
def test_validate_host_runs_each_fmu_in_the_declared_environment(fmu_dir, requirements_python, capsys):
    from orchestrator.commands.cli import main

    env_dir = requirements_python.parent.parent
    assert environment_python(env_dir) == requirements_python
    assert main(["validate", str(fmu_dir), "--host", "--venv", str(env_dir)]) == 0
    out = capsys.readouterr().out
    assert out.count("host self-test ok (a bare fmpy loop without dtcosim; imports ") == 5  # the five preset FMUs
    assert out.count(", all declared)") == 5
    if requested_kernel() == "numpy":  # DTCOSIM_KERNEL=numpy reaches the FMUs: they do not even try numba
        assert "imports numba" not in out and out.count("imports numpy, all declared") == 5
    elif not missing(aot_kernels()):  # the kernels compiled ahead of time: no numba needed, none tried
        assert "imports numba" not in out and out.count("imports numpy, all declared") == 5
    else:  # numba: optional, tried (and missing in that environment)
        assert "imports numba, numpy, all declared" in out


@pytest.mark.slow
def test_self_test_fails_an_fmu_that_does_not_declare_numpy(fmu_path, requirements_python, tmp_path):
    fmu = tmp_path / "GeneratorRotor.fmu"
    shutil.copy(fmu_path("GeneratorRotor"), fmu)
    with zipfile.ZipFile(fmu) as archive:
        text = archive.read("resources/requirements.txt").decode()
    rewrite_archive(fmu, {"resources/requirements.txt": "".join(
        line for line in text.splitlines(keepends=True) if not line.startswith("numpy")).encode()})
    (result,) = run_fmus(requirements_python, [fmu])
    assert not result.ok
    assert result.imports == ("numpy",) and result.undeclared == ("numpy",)
    assert result.error == "imports numpy, which its requirements do not declare"
