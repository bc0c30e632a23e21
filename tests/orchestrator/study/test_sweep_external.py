"""The same small sweep against a separately started `dask scheduler` + `dask worker` on loopback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from orchestrator.study.journal import read_journal
from orchestrator.study.report import read_table
from tests.helpers.studies import SMALL_FAILURE, SMALL_STUDY, free_port, run_cli

pytestmark = pytest.mark.slow


def _wait_for_workers(address: str, n: int, timeout: float) -> None:
    from distributed import Client

    with Client(address, timeout="30s") as client:
        client.wait_for_workers(n, timeout=timeout)


def _stop(proc: subprocess.Popen) -> None:
    """SIGTERM (dask's clean shutdown), then SIGKILL if it hangs; the exit code is not checked."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


def test_sweep_on_an_existing_cluster(write_study, tmp_path):
    bindir = Path(sys.executable).parent
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = tmp_path / "logs"
    logs.mkdir()
    env = dict(os.environ)
    scheduler = subprocess.Popen(
        [str(bindir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        stdout=subprocess.DEVNULL, stderr=open(logs / "scheduler.log", "w"), env=env, cwd=tmp_path)
    worker = None
    try:
        worker = subprocess.Popen(
            [str(bindir / "dask"), "worker", address, "--host", "127.0.0.1", "--nworkers", "1", "--nthreads", "1",
             "--no-dashboard", "--name", "external-worker"],
            stdout=subprocess.DEVNULL, stderr=open(logs / "worker.log", "w"), env=env, cwd=tmp_path)
        _wait_for_workers(address, 1, timeout=60)

        path = write_study(SMALL_STUDY)
        out = tmp_path / "out"
        proc = run_cli("sweep", str(path), "--scheduler", address, "--out", str(out), cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        assert f"on scheduler {address}" in proc.stderr and "on 1 workers" in proc.stdout
        rows = read_table(out / "results.csv")
        assert [r["status"] for r in rows] == ["ok", "ok", "ok", "failed"]
        assert rows[3]["error"] == SMALL_FAILURE
        pids = {int(r["worker"].rsplit(":", 1)[1]) for r in read_journal(out / "journal.jsonl")}
        worker_processes = {p.pid for p in psutil.Process(worker.pid).children(recursive=True)} | {worker.pid}
        assert pids <= worker_processes  # every point ran in the external worker's process

        again = run_cli("sweep", str(path), "--scheduler", address, "--out", str(out), cwd=tmp_path)
        assert again.returncode == 0, again.stderr
        assert "0 to run" in again.stderr and len(read_journal(out / "journal.jsonl")) == 4
        assert worker.poll() is None and scheduler.poll() is None  # the sweep leaves an external cluster running
    finally:
        if worker is not None:
            _stop(worker)
        _stop(scheduler)
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and (worker.poll() is None or scheduler.poll() is None):
        time.sleep(0.1)
    assert worker.poll() is not None and scheduler.poll() is not None
