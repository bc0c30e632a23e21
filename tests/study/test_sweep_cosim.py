"""A co-simulation sweep through Dask: the FMUs travel to the workers as bytes."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from orchestrator.study import load_study
from orchestrator.study_report import read_table
from orchestrator.study_prepare import prepare_study
from orchestrator.sweep import run_sweep

pytestmark = pytest.mark.slow

COSIM_STUDY = """
name = "cosim-seeds"
engine = "cosim"
seeds = [1, 2]
measures = ["I_max_acc", "cpu_time", "wall_time", "gearbox.stage1.F_sp[1]:mean", "generator.omega:std"]

[base]
scenario = "{scenario}"

[simulation]
stop = 0.4
step = 2.0e-3
output_interval = 2.0e-3

[[axes]]
parameter = "gearbox.shaft3.stiffness"
values = [2000.0, 5729.6]
"""


def test_cosim_sweep_runs_from_shipped_fmu_bytes(write_study, study_fmu_dir, tmp_path):
    from orchestrator.scenario import find_scenario

    # the base scenario and its FMUs in a directory of their own, deleted before the sweep runs:
    # the workers can only use the bytes that travel with the tasks
    own = tmp_path / "base"
    own.mkdir()
    shutil.copy(find_scenario("paper-60s"), own / "paper.toml")
    for fmu in study_fmu_dir.glob("*.fmu"):
        shutil.copy(fmu, own / fmu.name)
    prepared = prepare_study(load_study(write_study(COSIM_STUDY.format(scenario=own / "paper.toml"))), build=False)
    assert set(prepared.payload.fmu_blobs) == {i.sha256 for i in prepared.payload.system.interfaces.values()}
    shutil.rmtree(own)

    report = run_sweep(prepared, tmp_path / "out", workers=2, plots=False)
    assert (report.submitted, report.ok, report.failed, report.errors) == (4, 4, 0, 0)
    rows = read_table(tmp_path / "out" / "results.csv")
    assert [(float(r["gearbox.shaft3.stiffness"]), int(r["wind.seed"])) for r in rows] == [
        (2000.0, 1), (2000.0, 2), (5729.6, 1), (5729.6, 2)]
    force = np.array([float(r["gearbox.stage1.F_sp[1]:mean [N]"]) for r in rows])
    std = np.array([float(r["generator.omega:std [rad/s]"]) for r in rows])
    assert np.all(force > 1e5) and np.all(std > 0)
    assert std[0] != std[1] and force[0] != force[2]  # seeds and stiffness change the runs
    # the co-simulation samples omega_out every 2 ms: I_max_acc is a finite difference on that grid
    assert all(0 < float(r["I_max_acc [rad/s2]"]) < 1e4 for r in rows)
