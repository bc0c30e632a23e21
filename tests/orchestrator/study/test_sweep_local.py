"""Sweeps on a LocalCluster and in the sweep's own process: a failing point is recorded, completed points are never
run twice, Ctrl-C loses nothing."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from orchestrator.inputs.study_file import load_study
from orchestrator.study.journal import read_journal
from orchestrator.study.prepare import prepare_study
from orchestrator.study.report import read_table
from orchestrator.study.sweep import run_sweep
from tests.helpers.studies import (
    SMALL_FAILURE,
    SMALL_HEAD,
    SMALL_STUDY,
    SMALL_TABLES,
    STAGE3_FORCE_N,
)

pytestmark = pytest.mark.slow


def test_two_by_two_with_an_invalid_point_on_two_workers(write_study, tmp_path):
    prepared = prepare_study(load_study(write_study(SMALL_STUDY)))
    out = tmp_path / "out"
    seen = []
    first = run_sweep(prepared, out, workers=2, progress=seen.append, executor="dask")
    assert (first.total, first.submitted, first.skipped, first.workers) == (4, 4, 0, 2)
    assert (first.ok, first.failed, first.errors, first.interrupted) == (3, 1, 0, False)
    assert sorted(r["index"] for r in seen) == [0, 1, 2, 3]  # one journal record per point, as each finished

    rows = read_table(out / "results.csv")
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "failed"]
    assert rows[3]["error"] == SMALL_FAILURE and rows[3]["gearbox.R1"] == "9.0"
    assert rows[3]["I_max_acc [rad/s2]"] == ""
    for r in rows[:3]:
        assert float(r["gearbox.stage3.F_mesh:mean [N]"]) == pytest.approx(STAGE3_FORCE_N, rel=0.01)
        assert float(r["steps [1]"]) > 100 and float(r["cpu_time [s]"]) > 0
    workers = {r["worker"] for r in read_journal(out / "journal.jsonl")}
    assert all(w and w.rsplit(":", 1)[1] != str(os.getpid()) for w in workers)  # ran in worker processes

    journal = (out / "journal.jsonl").read_bytes()
    table = (out / "results.csv").read_text()
    second = run_sweep(prepared, out, workers=2, executor="dask")
    assert (second.submitted, second.skipped, second.workers) == (0, 4, 0)  # nothing run, no cluster started
    assert (out / "journal.jsonl").read_bytes() == journal  # not one record added
    assert (out / "results.csv").read_text() == table

    third = run_sweep(prepared, out, workers=1, retry_failed=True)
    assert (third.submitted, third.failed) == (1, 1)  # only the failed point runs again, and fails again
    records = read_journal(out / "journal.jsonl")
    assert [r["index"] for r in records[4:]] == [3] and records[4]["error"] == SMALL_FAILURE


@pytest.mark.parametrize("executor", ["dask", "auto"])  # auto: this small study runs in the command's own process
def test_ctrl_c_keeps_every_finished_point_and_the_next_run_completes_the_rest(write_study, tmp_path, executor):
    # R1 below 7.4 makes Table 6's stage-1 planets implausible (paper-sensitivity allows it the same way)
    text = SMALL_HEAD + SMALL_TABLES.replace("stop = 0.02", "stop = 0.3") + (
        '[plausibility]\nallow = ["gearbox.stage1.planet_inertia"]\n'
        '[[axes]]\nparameter = "gearbox.R1"\nstart = 6.0\nstop = 10.0\nnum = 12\n')
    path = write_study(text)
    out = tmp_path / "out"
    exe = Path(sys.executable).parent / "dtcosim"
    # a new session: Ctrl-C on a terminal signals the whole foreground process group, workers included
    proc = subprocess.Popen([str(exe), "sweep", str(path), "--workers", "1", "--out", str(out), "--no-plots",
                             "--executor", executor],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    journal = out / "journal.jsonl"
    deadline = time.monotonic() + 120
    while len(read_journal(journal)) < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    kept = read_journal(journal)
    assert 2 <= len(kept) < 12
    assert all(json.loads(line) for line in journal.read_text().splitlines() if line)  # no torn line
    rows = read_table(out / "results.csv")
    assert [r["status"] for r in rows].count("ok") == len(kept)
    assert [r["status"] for r in rows].count("pending") == 12 - len(kept)

    report = run_sweep(prepare_study(load_study(path)), out, workers=2, plots=False)
    assert report.submitted == 12 - len(kept) and report.ok == report.submitted
    records = read_journal(journal)
    assert len(records) == 12 and len({r["key"] for r in records}) == 12  # every point exactly once


def _on_terminal(args: list[str], cwd: Path) -> str:
    """Run dtcosim with stdout and stderr on a pseudo-terminal; return everything it printed."""
    import pty

    master, slave = pty.openpty()
    proc = subprocess.Popen([str(Path(sys.executable).parent / "dtcosim"), *args], cwd=cwd, stdout=slave,
                            stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    shown = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:
            break
        if not chunk:
            break
        shown += chunk
    assert proc.wait(timeout=120) == 0, shown.decode("utf-8", "replace")
    os.close(master)
    return shown.decode("utf-8", "replace")


def test_progress_bar_on_a_terminal_quiet_and_check(write_study, tmp_path):
    path = write_study(SMALL_STUDY)
    out = str(tmp_path / "out")
    shown = _on_terminal(["sweep", str(path), "--workers", "2", "--out", out, "--no-plots"], tmp_path)
    assert "small: 100%" in shown and "4/4" in shown and "failed=1" in shown
    assert "4 of 4 submitted points finished (3 ok, 1 failed, 0 errors)" in shown
    assert "warning: 1 points failed" in shown
    quiet = _on_terminal(["sweep", str(path), "--out", out, "--quiet"], tmp_path).strip().splitlines()
    assert len(quiet) == 1 and quiet[0].startswith("dtcosim sweep: warning: 1 points failed")  # warnings only
    check = _on_terminal(["sweep", str(path), "--out", out, "--check", "--retry-failed"], tmp_path)
    assert "small: valid" in check and "4 points" in check and "1 to run" in check


def test_a_stop_signal_while_a_result_is_stored_is_raised_after_its_journal_record(write_study, tmp_path):
    """A SIGTERM that landed in ``on_result`` (a load set storing a run: numpy's savez) interrupted the write and
    reached the user as a ValueError traceback from zipfile; storing and journaling are now one critical step."""
    prepared = prepare_study(load_study(write_study(SMALL_STUDY)))
    out = tmp_path / "out"
    stored = []

    def on_result(i, result):
        if not stored:
            os.kill(os.getpid(), signal.SIGTERM)  # delivered while the result is being stored
        stored.append(i)
        return {"stored": True}

    report = run_sweep(prepared, out, workers=1, plots=False, on_result=on_result)
    assert report.interrupted and report.signal == signal.SIGTERM
    records = read_journal(out / "journal.jsonl")
    assert len(stored) == 1 and [r["index"] for r in records] == stored  # the stored run is journaled, then the stop
    assert records[0]["stored"] is True and records[0]["status"] == "ok"
