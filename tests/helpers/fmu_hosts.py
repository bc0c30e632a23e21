"""Helpers of the FMU tests: an FMI instance driven through fmpy with its log messages captured."""

from __future__ import annotations

import importlib.util
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

DRIVERS = Path(__file__).parent / "drivers"
FMI_ERROR, FMI_FATAL = 3, 4

_extracted: dict[Path, str] = {}


def load_driver(name: str) -> ModuleType:
    """Import a driver script of ``drivers/`` as a module."""
    key = f"dtcosim_test_driver_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, DRIVERS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        spec.loader.exec_module(module)
    return sys.modules[key]


class Instance:
    """One FMU instance with variables by name and the FMI log messages in :attr:`messages`.

    Parameters
    ----------
    path : Path
        The ``.fmu`` file (extracted once per path and session).
    name : str
        Instance name.
    logging_on : bool
        ``loggingOn`` of fmi2Instantiate (pythonfmu forwards messages only when true).
    """

    def __init__(self, path: Path, name: str = "instance", logging_on: bool = True) -> None:
        path = Path(path)
        self.md = read_model_description(str(path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        if path not in _extracted:
            _extracted[path] = extract(str(path))
        self.messages: list[tuple[int, str]] = []
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=_extracted[path],
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(callbacks=self._callbacks, loggingOn=logging_on)
        self.freed = False

    def _log(self, env, instance, status, category, message) -> None:
        self.messages.append((int(status), message.decode("utf-8", "replace") if message else ""))

    def error_messages(self) -> list[str]:
        """Messages logged with status error or fatal."""
        return [m for s, m in self.messages if s >= FMI_ERROR]

    def vr(self, name: str) -> int:
        return self.variables[name].valueReference

    def set(self, **values) -> None:
        """Set variables by name (Real, Integer or Boolean)."""
        for name, value in values.items():
            kind = self.variables[name].type
            if kind == "Real":
                self.fmu.setReal([self.vr(name)], [float(value)])
            elif kind == "Integer":
                self.fmu.setInteger([self.vr(name)], [int(value)])
            else:
                self.fmu.setBoolean([self.vr(name)], [bool(value)])

    def get(self, *names: str) -> list[float]:
        return self.fmu.getReal([self.vr(n) for n in names])

    def real_outputs(self) -> dict[str, float]:
        names = [v.name for v in self.md.modelVariables if v.causality == "output" and v.type == "Real"]
        return dict(zip(names, self.get(*names)))

    def enter(self, start_time: float = 0.0, **values) -> None:
        """setupExperiment, enterInitializationMode and set ``values``."""
        self.fmu.setupExperiment(startTime=start_time)
        self.fmu.enterInitializationMode()
        self.set(**values)

    def initialize(self, start_time: float = 0.0, **values) -> None:
        """Enter, set ``values`` and exit initialisation mode."""
        self.enter(start_time, **values)
        self.fmu.exitInitializationMode()

    def step(self, t: float, h: float) -> None:
        self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)

    def free(self) -> None:
        if not self.freed:
            self.fmu.freeInstance()
            self.freed = True


def gearbox_motion(t: float, ratio: float, omega0: float = 16.0 * math.pi / 30.0) -> dict[str, float]:
    """A smooth, kinematically consistent rotor/generator motion for driving the Gearbox alone.

    Rotor speed ``omega0 (1 + 0.02 sin 3t)``; the generator follows ``ratio`` times the
    rotor plus a twist ``0.5 sin 5t`` rad (about 3 kN m through shaft 3).
    """
    omega_rotor = omega0 * (1.0 + 0.02 * math.sin(3.0 * t))
    phi_rotor = omega0 * (t + 0.02 * (1.0 - math.cos(3.0 * t)) / 3.0)
    return {
        "omega_rotor": omega_rotor,
        "phi_rotor": phi_rotor,
        "omega_gen": ratio * omega_rotor + 2.5 * math.cos(5.0 * t),
        "phi_gen": ratio * phi_rotor + 0.5 * math.sin(5.0 * t),
    }


def run_python(python: Path | str, *args: str, env: dict | None = None, timeout: float = 300.0):
    """Run a Python script in a subprocess; returns the CompletedProcess (text output)."""
    full_env = dict(os.environ)
    full_env.pop("PYTHONPATH", None)
    full_env.update(env or {})
    return subprocess.run([str(python), *args], capture_output=True, text=True, env=full_env, timeout=timeout,
                          cwd="/")


#: the environment of a C host started from a desktop: no Python anywhere, the system's PATH only
SYSTEM_ENV = {"PATH": "/usr/bin:/bin"}


def c_host(tmp_path: Path) -> Path:
    """``drivers/c_host.c`` compiled into ``tmp_path`` (skips the test without a C compiler)."""
    import pytest

    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler")
    host = tmp_path / "c_host"
    if not host.exists():
        subprocess.run([compiler, "-O1", "-o", str(host), str(DRIVERS / "c_host.c"), "-ldl"], check=True,
                       capture_output=True)
    return host


def c_host_args(host: Path, fmu: Path, folder: Path, steps: int, output: str, inputs: tuple[str, ...] = ()) -> list[str]:
    """The command line of ``c_host`` for an FMU unpacked into ``folder``: its binary, resources, GUID, VRs."""
    import zipfile

    from fmpy import read_model_description

    if not folder.exists():
        with zipfile.ZipFile(fmu) as archive:
            archive.extractall(folder)
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    model = md.coSimulation.modelIdentifier
    return [str(host), str(folder / "binaries" / "linux64" / f"{model}.so"), (folder / "resources").as_uri(), md.guid,
            str(steps), str(vr[output])] + [str(vr[n]) for n in inputs]
