"""Runs that stop early: an FMU failing mid-run and Ctrl-C leave partial results with complete = false."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.result_files import find_timeseries, read_timeseries
from tests.helpers.scenarios import TOY_SCENARIO, dtcosim, write_scenario

pytestmark = pytest.mark.slow

PAPER = load_scenario(find_scenario("paper-60s")).simulation  # the packaged step and output interval

#: the paper scenario with the generator yanked at t = 1 s (counter torque 1e30 x 25.4 kN m, the largest factor a
#: scenario admits): the Gearbox, which integrates the generator inertia against that counter torque (the
#: scenario's inertia interface), discards the step from t = 1 s ("step size ... below h_min"), with either kernel. (Loose tolerances made it diverge at some time
#: that depended on the last bits of the wind signal: not a reliable failure.)
YANKED_GENERATOR = find_scenario("paper-60s").read_text().replace('name = "paper-60s"', 'name = "yanked"') + """
[[events]]
kind = "torque_step"
start = 1.0
factor = 1.0e30
"""


def test_gearbox_failing_mid_run_leaves_partial_results(fmu_dir, tmp_path):
    out = tmp_path / "diverged"
    scenario = write_scenario(tmp_path, YANKED_GENERATOR, "yanked.toml")
    # a torque step of 1e30 x rated is refused as implausible before any run; kept here to fail mid-run
    proc = dtcosim("run", str(scenario), "--stop", "3", "--fmu-dir", str(fmu_dir), "--out", str(out),
                   "--allow-implausible", "generator.event1.factor", cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False
    t_stop = summary["stopped_at"]
    assert t_stop == pytest.approx(1.0)
    error = summary["error"]
    assert "FMU 'gearbox'" in error and "fmi2DoStep" in error and "discard" in error and f"t = {t_stop:g} s" in error
    assert "failed" in error and "below h_min" in error  # the FMU's own message is included
    header, data = read_timeseries(out / "timeseries.csv")
    assert data.shape[0] == round(t_stop / PAPER.output_interval_s) + 1
    assert data[-1, 0] == pytest.approx(t_stop) and np.all(np.isfinite(data))
    assert (out / "contact_forces.png").exists()
    assert "partial results written" in proc.stderr


def test_fmu_exception_is_reported_with_its_message(toy_scenario, tmp_path):
    text = TOY_SCENARIO.replace("mode = 0", "mode = 1\nfail_at = 0.05")
    path = toy_scenario(text)
    proc = dtcosim("run", str(path), "--out", str(tmp_path / "out"), "-q", cwd=tmp_path)
    assert proc.returncode == 1
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["complete"] is False and summary["stopped_at"] == pytest.approx(0.05)
    assert "FMU 'fail'" in summary["error"] and "fatal" in summary["error"]
    assert "toy failure at t=0.05" in summary["error"]
    header, data = read_timeseries(tmp_path / "out" / "timeseries.csv")
    assert data.shape[0] == 6


def test_ctrl_c_stops_the_run_and_writes_partial_results(fmu_dir, tmp_path):
    out = tmp_path / "interrupted"
    exe = Path(sys.executable).parent / "dtcosim"
    # 600 s at H = 1 ms: tens of seconds of stepping, so the signal arrives while stepping
    proc = subprocess.Popen([str(exe), "run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--no-plots",
                             "--stop", "600", "--step", "0.001", "--output-interval", "0.001"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    note = proc.stderr.readline()  # the scenario's window [5, 60] s ended at its stop: it follows the new one
    assert "analysis window moved from [5, 60] s to [5, 600] s" in note, note
    # (the gearbox <-> generator loop's one-step delay is in summary.json and run --check, not on every run)
    header = proc.stderr.readline()  # printed before the FMUs are instantiated
    assert "3 FMUs" in header, header
    time.sleep(8.0)  # past instantiation (numba's cache load included) and initialisation, well before 600 s
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False and summary["interrupted"] is True
    assert 0.0 < summary["stopped_at"] < 600.0
    assert "interrupted" in summary["error"]
    # 600 001 samples x 22 variables: the binary results file by default (orchestrator.inputs.results_format)
    assert summary["files"]["timeseries"] == "timeseries.parquet" == find_timeseries(out).name
    header, data = read_timeseries(find_timeseries(out))
    assert data.shape[0] == round(summary["stopped_at"] / 1e-3) + 1
    assert np.all(np.isfinite(data))
