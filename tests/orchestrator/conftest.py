"""Fixtures of the orchestrator tests: toy FMUs, the project's FMUs, the paper's 60 s run."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from toy_fmus import build_toys

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def toy_dir(tmp_path_factory) -> Path:
    """Directory with the toy FMUs (ToySine.fmu, ToyIntegrator.fmu, ...), built once."""
    out = tmp_path_factory.mktemp("toys")
    build_toys(out)
    return out


@pytest.fixture(scope="session")
def paper_fmu_dir(tmp_path_factory) -> Path:
    """The project's three FMUs built once into a session directory."""
    from fmus.build import build_all

    out = tmp_path_factory.mktemp("paper-fmus")
    build_all(out)
    return out


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


@pytest.fixture(scope="session")
def paper_run(tmp_path_factory):
    """``dtcosim run`` with no arguments, once per session, into a fresh directory.

    ``DTCOSIM_FMU_DIR`` points to an empty directory, so the run also builds the
    missing FMUs. Returns ``(results directory, summary dict, completed process)``.
    """
    work = tmp_path_factory.mktemp("paper-run")
    fmu_dir = work / "fmus"
    fmu_dir.mkdir()
    proc = dtcosim("run", cwd=work, env={"DTCOSIM_FMU_DIR": str(fmu_dir)}, timeout=900)
    assert proc.returncode == 0, proc.stderr
    out = work / "results" / "paper-60s"
    summary = json.loads((out / "summary.json").read_text())
    return out, summary, proc


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


@pytest.fixture
def toy_scenario(toy_dir, tmp_path):
    """``make(text=TOY_SCENARIO)`` -> path of a scenario file next to copies of the toy FMUs."""
    import shutil

    for fmu in toy_dir.glob("*.fmu"):
        shutil.copy(fmu, tmp_path / fmu.name)

    def make(text: str = TOY_SCENARIO, name: str = "scenario.toml") -> Path:
        return write_scenario(tmp_path, text, name)

    return make
