"""Runs that stop, at any stage and for any reason, leave an honest summary and only whole files.

SIGINT, SIGTERM and SIGHUP mid-run, SIGKILL, a full disk (a small tmpfs and a
file-size limit), an unwritable output folder, a failing initialisation, a run
into a folder a previous run used, Ctrl-C at every stage of the command.
"""

from __future__ import annotations

import json
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from orchestrator.result_files import read_timeseries
from tests.helpers.scenarios import dtcosim
from tests.helpers.stop_signals import as_from_a_terminal

pytestmark = pytest.mark.slow

EXE = str(Path(sys.executable).parent / "dtcosim")


def start(fmu_dir, out, *extra, preexec_fn=None) -> subprocess.Popen:
    """``dtcosim run`` of the paper's scenario in the background."""
    # at H = 1 ms, every step sampled: one row per step, blocks of 250 rows
    return subprocess.Popen([EXE, "run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--no-plots", "-q",
                             "--step", "0.001", "--output-interval", "0.001", *extra],
                            cwd=out.parent, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=as_from_a_terminal(preexec_fn))


def wait_until_stepping(proc: subprocess.Popen, out: Path, rows: int = 600, timeout: float = 300.0) -> None:
    """Wait until the streamed results file holds at least ``rows`` rows (the run is well into stepping)."""
    partial = out / "timeseries.csv.partial"
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise AssertionError(f"the run ended early ({proc.returncode}): {proc.stderr.read()}")
        if partial.exists() and partial.read_bytes().count(b"\n") > rows:
            return
        time.sleep(0.05)
    raise AssertionError("the run did not reach its stepping loop")


def summary_of(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGHUP, 129)])
def test_a_stop_signal_mid_run_keeps_the_partial_results_with_an_honest_summary(fmu_dir, tmp_path, signum, status):
    out = tmp_path / "run"
    proc = start(fmu_dir, out)
    wait_until_stepping(proc, out)
    proc.send_signal(signum)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == status, stderr
    summary = summary_of(out)
    name = signal.Signals(signum).name
    assert summary["status"] == "stopped" and summary["complete"] is False and summary["interrupted"] is True
    assert summary["signal"] == name and summary["stage"] == "stepping"
    t_stop = summary["stopped_at"]
    assert 0.5 < t_stop < 60.0 and f"at t = {t_stop:.6g} s" in summary["error"]
    assert summary["files"] == {"timeseries": "timeseries.csv", "summary": "summary.json"}
    assert "files_incomplete" not in summary
    header, data = read_timeseries(out / "timeseries.csv")
    assert data.shape[0] == summary["samples"] == round(t_stop / 1e-3) + 1 and np.all(np.isfinite(data))
    assert sorted(p.name for p in out.iterdir()) == ["summary.json", "timeseries.csv"]
    lines = [line for line in stderr.strip().splitlines() if not line.startswith("dtcosim run: note: ")]
    assert len(lines) == 1 and "interrupted" in lines[0] and "Traceback" not in stderr, stderr


def test_after_sigkill_the_summary_says_running_and_the_streamed_file_reads_to_its_last_block(fmu_dir, tmp_path):
    out = tmp_path / "killed"
    proc = start(fmu_dir, out)
    wait_until_stepping(proc, out)
    proc.kill()
    proc.communicate(timeout=60)
    summary = summary_of(out)
    assert summary["status"] == "running" and summary["complete"] is False and summary["files"] == {}
    assert summary["files_incomplete"]["timeseries"]["file"] == "timeseries.csv.partial"
    assert not (out / "timeseries.csv").exists()
    header, data = read_timeseries(out / "timeseries.csv.partial")
    n = data.shape[0]
    assert n > 600 and (n - 1) % 250 == 0  # row 0, then whole blocks of 250 steps
    np.testing.assert_allclose(data[:, 0], np.arange(n) * 1e-3, rtol=0, atol=1e-12)
    # the next run into the same folder clears what the killed one left
    proc = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--stop", "0.2", "--no-plots", "-q",
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "replacing the previous run" in proc.stderr and not (out / "timeseries.csv.partial").exists()
    assert summary_of(out)["status"] == "complete"


def _file_size_limit(limit: int):
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def _check_disk_full(proc, out, reason):
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 1, stderr
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["complete"] is False and summary["stage"] == "writing"
    kept = summary["files_incomplete"]["timeseries"]
    assert kept["file"] == "timeseries.csv.partial" and reason in kept["reason"]
    assert "timeseries.csv.partial" in kept["reason"]  # the message names the file
    header, data = read_timeseries(out / "timeseries.csv.partial")
    assert data.shape[0] == kept["rows"] > 250 and (data.shape[0] - 1) % 250 == 0
    assert (out / "timeseries.csv.partial").read_bytes().endswith(b"\n")  # cut back to the last whole block
    assert summary["stopped_at"] == pytest.approx((data.shape[0] - 1) * 1e-3 + 0.25, abs=1e-9)
    assert reason in stderr and "Traceback" not in stderr
    assert "timeseries" not in summary["files"]


def test_a_file_size_limit_keeps_what_was_written_and_says_so(fmu_dir, tmp_path):
    out = tmp_path / "limited"
    out.mkdir()
    proc = start(fmu_dir, out, "--stop", "10", preexec_fn=_file_size_limit(2_000_000))
    _check_disk_full(proc, out, "File too large")


def _never_unpacked(fmu_dir: Path, folder: Path) -> Path:
    """Copies of the FMUs of ``fmu_dir`` in ``folder``, each with a zip comment of its own: content no run has
    unpacked into the user cache yet (orchestrator.cosim.unpacked_fmus), the same FMUs otherwise."""
    folder.mkdir()
    for fmu in fmu_dir.glob("*.fmu"):
        copy = folder / fmu.name
        shutil.copyfile(fmu, copy)
        with zipfile.ZipFile(copy, "a") as archive:
            archive.comment = f"{folder} {time.time_ns()}".encode()
    return folder


def test_an_fmu_that_cannot_be_extracted_is_a_named_error_before_stepping(fmu_dir, tmp_path):
    """A file-size limit below the Gearbox's compiled module (0.85 MB): the extraction fails, one clear line."""
    out = tmp_path / "limited"
    out.mkdir()
    fmus = _never_unpacked(fmu_dir, tmp_path / "fmus")
    proc = start(fmus, out, "--stop", "1", preexec_fn=_file_size_limit(300_000))
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 1, stderr
    assert "cannot extract the FMU" in stderr and "File too large" in stderr and "Traceback" not in stderr, stderr
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["stage"] == "initialisation" and summary["complete"] is False


def test_a_full_disk_keeps_what_was_written_and_says_so(fmu_dir, tmp_path):
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(disk)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here: {mounted.stderr.decode().strip()}")
    try:
        out = disk / "run"
        proc = start(fmu_dir, out, "--stop", "10")
        _check_disk_full(proc, out, "No space left on device")
    finally:
        subprocess.run(["umount", "-l", str(disk)], capture_output=True)


@pytest.mark.parametrize("where, expected", [
    ("file", "expected a folder for the results (this is a file)"),
    ("/sys/dtcosim-results", "expected a folder dtcosim can write"),
])
def test_an_output_folder_that_cannot_take_results_is_refused_before_anything_runs(fmu_dir, tmp_path, where,
                                                                                    expected):
    out = tmp_path / "a-file" if where == "file" else Path(where)
    if where == "file":
        out.write_text("not a folder")
    proc = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--stop", "0.1", "-q", cwd=tmp_path)
    assert proc.returncode == 1
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith(f"dtcosim run: error: invalid command-line entry --out = '{out}': {expected}"), last
    assert "Traceback" not in proc.stderr


def test_a_failing_initialisation_leaves_a_summary_that_says_where_and_why(fmu_dir, tmp_path):
    out = tmp_path / "init"
    # a mean rotor speed at the limit of magnitudes gives the generator an initial speed (ratio 100 x) beyond
    # it: known only once the gearbox reports its output speed during initialisation, not checkable before
    proc = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--set", "wind.omega0=1e30",
                   "--allow-implausible", "wind.omega0", "-q",
                   cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["complete"] is False and summary["stage"] == "initialisation"
    assert summary["samples"] == 0 and summary["files"] == {"summary": "summary.json"}
    assert "FMU 'generator'" in summary["error"]
    # ratio x 1e30 = 1e32 to round-off (its last digits follow the machine's floating-point code)
    assert re.search(r"invalid parameter initial_speed = (1\.0|9\.9)\d*e\+3[12]: expected a finite real number",
                     summary["error"]), summary["error"]
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]
    lines = proc.stderr.strip().splitlines()
    assert "nothing was simulated" in lines[-1] and "Traceback" not in proc.stderr


def test_a_run_into_a_used_folder_never_leaves_files_of_two_runs(fmu_dir, tmp_path):
    out = tmp_path / "used"
    first = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--stop", "0.5", "-q", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert any(p.suffix == ".png" for p in out.iterdir())
    (out / "my-notes.txt").write_text("not dtcosim's")  # a file no run wrote is kept
    proc = start(fmu_dir, out)
    wait_until_stepping(proc, out)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=120)
    assert proc.returncode == 143
    assert sorted(p.name for p in out.iterdir()) == ["my-notes.txt", "summary.json", "timeseries.csv"]
    summary = summary_of(out)
    assert summary["status"] == "stopped" and summary["stop_s"] == 60.0


@pytest.mark.parametrize("delay_s", [0.3, 1.5, 4.0])
def test_ctrl_c_at_any_stage_exits_130_with_one_line(fmu_dir, tmp_path, delay_s):
    out = tmp_path / "any-stage"
    # 300 s at H = 1 ms: the run lasts long enough for every delay to land before its end (60 s of it took
    # under 4 s once the start-up got faster)
    proc = subprocess.Popen([EXE, "run", "--fmu-dir", str(fmu_dir), "--out", str(out), "-q", "--step", "0.001",
                             "--output-interval", "0.001", "--stop", "300", "--window", "5", "60"], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=as_from_a_terminal())
    time.sleep(delay_s)  # start-up, imports, FMU loading, instantiation, stepping: wherever it is
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    lines = [line for line in stderr.strip().splitlines() if not line.startswith("dtcosim run: note: ")]
    assert len(lines) == 1 and "interrupted" in lines[0] and "Traceback" not in stderr, stderr
