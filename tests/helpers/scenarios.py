"""Helpers of the scenario and CLI tests: scenario files, the `dtcosim` console script, a toy scenario."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def write_scenario(folder: Path, text: str, name: str = "scenario.toml") -> Path:
    """Write a scenario TOML file into ``folder``."""
    path = folder / name
    path.write_text(text)
    return path


def dtcosim(*args: str, cwd: Path, env: dict | None = None, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run the installed ``dtcosim`` console script."""
    exe = Path(sys.executable).parent / "dtcosim"
    full_env = dict(os.environ)
    full_env.update(env or {})
    return subprocess.run([str(exe), *args], cwd=cwd, env=full_env, capture_output=True, text=True, timeout=timeout)


#: a valid toy scenario: sine -> integrator, plus an unconnected ToyFailer (Integer parameter)
TOY_SCENARIO = """
name = "toy"
[simulation]
stop = 0.1
step = 0.01

[components.src]
fmu = "ToySine.fmu"
[components.src.parameters]
amplitude = 2.0

[components.int]
fmu = "ToyIntegrator.fmu"

[components.fail]
fmu = "ToyFailer.fmu"
[components.fail.parameters]
mode = 0

[[connections]]
from = "src.y"
to = "int.u"

[record]
variables = ["src.y", "int.x", "int.u_seen", "int.t_seen"]
"""
