"""One run at a time in an output folder (issue 35.2): two runs into one --out corrupted each other's files
(an unparseable timeseries.csv, one seed's statistics beside another's data); the second is now refused."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from orchestrator.run.run_folder import OutputFolderError, RunFolder


def test_a_second_run_into_a_folder_in_use_is_refused_naming_the_holder(tmp_path):
    first = RunFolder.prepare(tmp_path / "out", {"scenario": "a"})
    with pytest.raises(OutputFolderError, match=rf"--out = '.*out': expected a folder no other run is writing into "
                                                rf"\(the run with pid {os.getpid()} holds it"):
        RunFolder.prepare(tmp_path / "out", {"scenario": "b"})
    with pytest.raises(OutputFolderError, match=f"the run with pid {os.getpid()} holds it"):
        RunFolder.check(tmp_path / "out")  # before the command says what it will replace
    first.release()
    second = RunFolder.prepare(tmp_path / "out", {"scenario": "b"})  # free again
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["summary.json"]  # no lock file of its own
    second.release()


@pytest.mark.slow
def test_two_dtcosim_runs_into_one_folder(tmp_path):
    exe = Path(sys.executable).parent / "dtcosim"
    out = tmp_path / "out"
    first = subprocess.Popen([str(exe), "run", "mesh-stiffness", "--no-plots", "-q", "--out", str(out)], cwd=tmp_path,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not (out / "timeseries.csv.partial").exists() and first.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    second = subprocess.run([str(exe), "run", "paper-60s", "--no-plots", "-q", "--out", str(out)], cwd=tmp_path,
                            capture_output=True, text=True, timeout=300)
    first_err = first.communicate(timeout=600)[1]
    if first.returncode == 0 and "holds it" not in second.stderr and second.returncode == 0:
        pytest.skip("the first run ended before the second started")
    assert second.returncode == 1 and f"the run with pid {first.pid} holds it" in second.stderr, second.stderr
    assert "replacing the previous run" not in second.stderr  # it said so, then replaced nothing
    assert first.returncode == 0, first_err
    import json
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "mesh-stiffness" and summary["status"] == "complete"
