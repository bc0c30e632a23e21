"""A host whose Python cannot import what an FMU needs gets NULL from fmi2Instantiate and a message naming it."""

from __future__ import annotations

import json
import shutil
import subprocess
import zipfile

import pytest

from fmus.model_description import rewrite_archive
from tests.helpers.fmu_hosts import DRIVERS, SYSTEM_ENV, c_host, c_host_args, run_python

HIDE_NUMPY = DRIVERS / "hide_numpy"
ERROR, WARNING = 3, 1


def instantiate(python, fmu, attempts=3, logging_on=True, env=None):
    proc = run_python(python, str(DRIVERS / "instantiate.py"), str(fmu), str(attempts), "1" if logging_on else "0",
                      env=env)
    assert proc.returncode == 0, proc.stderr[-3000:]  # the fmpy host process survived
    return json.loads(proc.stdout.splitlines()[-1]), proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("name", ["WindSource", "Gearbox", "GeneratorRotor"])
def test_hidden_numpy_gives_null_and_a_logged_message_naming_it(fmu_path, this_python, name):
    report, stderr = instantiate(this_python, fmu_path(name), env={"PYTHONPATH": str(HIDE_NUMPY)})
    assert [a["ok"] for a in report["attempts"]] == [False, False, False]
    assert all(a["error"] == "Failed to instantiate model" for a in report["attempts"])  # fmpy: NULL instance
    errors = [m for s, m in report["messages"] if s == ERROR]
    assert len(errors) == 3
    for message in errors:
        assert f"dtcosim {name} FMU cannot start: Python module 'numpy' cannot be imported" in message
        assert "numpy>=2.4,<3" in message and "resources/requirements.txt" in message
    assert stderr.count(f"dtcosim {name} FMU cannot start: Python module 'numpy'") == 3


@pytest.mark.slow
def test_without_logging_the_message_is_still_on_stderr(fmu_path, this_python):
    report, stderr = instantiate(this_python, fmu_path("Gearbox"), attempts=1, logging_on=False,
                                 env={"PYTHONPATH": str(HIDE_NUMPY)})
    assert report["attempts"][0]["ok"] is False and report["messages"] == []  # no logger call with logging off
    assert "Python module 'numpy' cannot be imported" in stderr


@pytest.mark.slow
def test_the_same_host_runs_the_fmu_when_numpy_is_importable(fmu_path, this_python):
    report, stderr = instantiate(this_python, fmu_path("Gearbox"), attempts=2)
    assert [a["ok"] for a in report["attempts"]] == [True, True]
    assert "cannot start" not in stderr


def _with_requirements(src, dst, edit):
    shutil.copy(src, dst)
    with zipfile.ZipFile(dst) as archive:
        text = archive.read("resources/requirements.txt").decode()
    rewrite_archive(dst, {"resources/requirements.txt": edit(text).encode()})
    return dst


@pytest.mark.slow
def test_an_untested_numpy_version_runs_with_a_logged_warning(fmu_path, this_python, tmp_path):
    fmu = _with_requirements(fmu_path("WindSource"), tmp_path / "WindSource.fmu",
                             lambda t: "\n".join("numpy>=1.20,<2  # tested: 1.26.4 (import numpy)"
                                                 if line.startswith("numpy") else line for line in t.splitlines()))
    report, stderr = instantiate(this_python, fmu, attempts=1)
    assert report["attempts"][0]["ok"] is True
    warnings = [m for s, m in report["messages"] if s == WARNING]
    assert any("dtcosim WindSource FMU: numpy" in m and "outside the tested range numpy>=1.20,<2" in m for m in warnings)
    assert "[warning] dtcosim WindSource FMU: numpy" in stderr


@pytest.mark.slow
def test_a_too_old_python_gives_null_and_a_message(fmu_path, this_python, tmp_path):
    fmu = _with_requirements(fmu_path("WindSource"), tmp_path / "WindSource.fmu",
                             lambda t: t.replace("requires-python: >=3.11,<3.12", "requires-python: >=3.99,<3.100"))
    report, _ = instantiate(this_python, fmu, attempts=1)
    assert report["attempts"][0]["ok"] is False
    assert any("cannot start: it requires Python >=3.99,<3.100" in m for s, m in report["messages"] if s == ERROR)


@pytest.mark.slow
def test_c_host_gets_null_and_the_message(fmu_path, tmp_path):
    """A C host (drivers/c_host.c) with numpy hidden from the FMU's Python: NULL, the message, a clean exit."""
    args = c_host_args(c_host(tmp_path), fmu_path("Gearbox"), tmp_path / "Gearbox", 10, "shaft_torque",
                       ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen"))
    result = subprocess.run(args, capture_output=True, text=True, timeout=120,
                            env={**SYSTEM_ENV, "PYTHONPATH": str(HIDE_NUMPY)})  # its sitecustomize blocks numpy
    assert result.returncode == 3, result.stderr[-3000:]  # the host's own "fmi2Instantiate failed" exit
    assert "fmi2Instantiate failed" in result.stderr
    assert "[fmu1 status 3] import of the slave module: ImportError: dtcosim Gearbox FMU cannot start: Python " \
        "module 'numpy' cannot be imported" in result.stderr  # through the FMI logger ...
    assert result.stderr.count("dtcosim Gearbox FMU cannot start: Python module 'numpy'") == 2  # ... and on stderr (the guard)
