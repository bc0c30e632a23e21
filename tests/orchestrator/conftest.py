"""Fixtures of the orchestrator tests: toy FMUs, the project's FMUs, the paper's 60 s run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from orch_helpers import TOY_SCENARIO, dtcosim, write_scenario
from toy_fmus import build_toys


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


@pytest.fixture
def toy_scenario(toy_dir, tmp_path):
    """``make(text=TOY_SCENARIO)`` -> path of a scenario file next to copies of the toy FMUs."""
    import shutil

    for fmu in toy_dir.glob("*.fmu"):
        shutil.copy(fmu, tmp_path / fmu.name)

    def make(text: str = TOY_SCENARIO, name: str = "scenario.toml") -> Path:
        return write_scenario(tmp_path, text, name)

    return make
