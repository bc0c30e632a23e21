"""``dtcosim validate --host``: prove an FMU's declared requirements complete.

A fresh virtual environment gets exactly the FMUs' declared requirements
(``pip install -r resources/requirements.txt``, the newest releases inside the
declared ranges) plus the host, fmpy, and nothing of dtcosim. There
:mod:`fmus.selftest_driver` runs each FMU once (instantiate, initialise, a few
steps, free) and records which third-party modules the FMU's own code
imported. An FMU passes if it ran and every module it imported is declared:
fmpy brings numpy along by itself, so running alone would not prove a numpy
declaration.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import venv
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

from components.errors import DtcosimError

from .requirements import read_from_fmu

DRIVER = Path(__file__).with_name("selftest_driver.py")
#: What the host side needs besides the FMUs' requirements.
HOST_PACKAGES = ("fmpy",)
#: Communication steps each FMU takes.
STEPS = 10


class SelfTestError(DtcosimError):
    """The self-test could not be set up (no requirements declared, pip failed, the driver crashed)."""


@dataclass(frozen=True)
class HostRun:
    """What one FMU did in the fresh environment.

    Attributes
    ----------
    fmu : Path
    ok : bool
        Ran and imported nothing undeclared.
    error : str or None
        Why it failed.
    imports : tuple of str
        Third-party top-level modules its code imported.
    undeclared : tuple of str
        Those not in its declared requirements.
    messages : tuple of str
        What it logged.
    """

    fmu: Path
    ok: bool
    error: str | None
    imports: tuple[str, ...]
    undeclared: tuple[str, ...]
    messages: tuple[str, ...]


def environment_python(env_dir: Path) -> Path:
    """The interpreter of the virtual environment ``env_dir``."""
    return Path(env_dir) / ("Scripts/python.exe" if os.name == "nt" else "bin/python")


def requirement_lines(fmu_paths: Iterable[Path]) -> list[str]:
    """Every declared package requirement of the FMUs (pip intersects repeated names)."""
    lines: list[str] = []
    for path in fmu_paths:
        req = read_from_fmu(path)
        if req is None:
            raise SelfTestError(f"{path}: declares no requirements (resources/requirements.txt); rebuild it")
        lines += [p.specifier for p in req.packages if p.specifier not in lines]
    return lines


def create_environment(env_dir: Path | str, fmu_paths: Sequence[Path], constraints: Sequence[str] = (),
                       timeout: float = 900.0) -> Path:
    """A virtual environment with the FMUs' requirements and fmpy; reused if ``env_dir`` already holds one.

    Parameters
    ----------
    env_dir : path
        Where the environment lives.
    fmu_paths : sequence of Path
    constraints : sequence of str
        pip constraints (``numpy==2.4.6``) to pin versions inside the declared ranges.
    timeout : float
        Seconds allowed for pip.

    Returns
    -------
    Path
        The environment's interpreter.
    """
    env_dir = Path(env_dir)
    python = environment_python(env_dir)
    if not python.exists():
        venv.EnvBuilder(with_pip=True, system_site_packages=False, clear=True).create(env_dir)
    with tempfile.TemporaryDirectory(prefix="dtcosim_selftest_") as tmp:
        req_file = Path(tmp) / "requirements.txt"
        req_file.write_text("\n".join(requirement_lines(fmu_paths) + list(HOST_PACKAGES)) + "\n", encoding="utf-8")
        command = [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r", str(req_file)]
        if constraints:
            constraint_file = Path(tmp) / "constraints.txt"
            constraint_file.write_text("\n".join(constraints) + "\n", encoding="utf-8")
            command += ["-c", str(constraint_file)]
        proc = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        raise SelfTestError(f"pip could not install the declared requirements into {env_dir}:\n{proc.stderr[-2000:]}")
    return python


def run_fmus(python: Path, fmu_paths: Sequence[Path], steps: int = STEPS, timeout: float = 600.0) -> list[HostRun]:
    """Run each FMU once with ``python`` (no dtcosim on its path) and judge the reports."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    proc = subprocess.run([str(python), str(DRIVER), str(steps), *map(str, fmu_paths)], capture_output=True,
                          text=True, timeout=timeout, env=env, cwd=tempfile.gettempdir())
    try:
        reports = json.loads(proc.stdout)
    except json.JSONDecodeError:
        raise SelfTestError(f"the host self-test driver failed (exit code {proc.returncode}):\n"
                            f"{proc.stderr[-3000:]}") from None
    runs = []
    for path in fmu_paths:
        report = reports[str(path)]
        req = read_from_fmu(path)
        declared = {p.module for p in req.packages + req.optional}
        undeclared = tuple(m for m in report["imports"] if m not in declared)
        error = report["error"]
        if error is None and undeclared:
            error = f"imports {', '.join(undeclared)}, which its requirements do not declare"
        runs.append(HostRun(Path(path), error is None, error, tuple(report["imports"]), undeclared,
                            tuple(m for _, m in report["messages"])))
    return runs


def self_test(fmu_paths: Sequence[Path], env_dir: Path | str | None = None,
              constraints: Sequence[str] = ()) -> list[HostRun]:
    """Create (or reuse) the environment and run every FMU in it; a temporary environment is removed after."""
    if env_dir is not None:
        return run_fmus(create_environment(env_dir, fmu_paths, constraints), fmu_paths)
    with tempfile.TemporaryDirectory(prefix="dtcosim_host_env_") as tmp:
        return run_fmus(create_environment(tmp, fmu_paths, constraints), fmu_paths)
