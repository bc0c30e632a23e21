"""Sweeps and load sets on a full disk, under signals during the cluster's start-up, with a private scratch space
(issue 35.9 and its "what must be true" 2-3): one line each, nothing left half-written, nothing in a shared folder.

A full disk is an OSError injected where the file is written (deterministic); the signal is raised by the
process itself inside the LocalCluster's constructor, after its processes have started.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from orchestrator.commands import cli
from orchestrator.inputs.study_file import load_study
from orchestrator.study import plots as study_plots
from orchestrator.study.engine import PointTask, run_point
from orchestrator.study.journal import Journal
from orchestrator.study.prepare import prepare_study
from tests.helpers.failing_files import FullAt
from tests.helpers.stop_signals import as_from_a_terminal
from tests.helpers.studies import SMALL_HEAD, SMALL_TABLES

ROOT = Path(__file__).resolve().parents[3]
GRID = SMALL_HEAD + SMALL_TABLES + (
    '[[axes]]\nparameter = "gearbox.R1"\nvalues = [8.0, 9.0]\n'
    '[[axes]]\nparameter = "gearbox.stage3.lambda"\nvalues = [1.0e5, 6.0e5]\n'
    '[[plots]]\nmeasure = "I_max_acc"\nfile = "imax.png"\n')


def _journal_every_point(prepared, out: Path) -> None:
    """Every point run in this process into the journal: a sweep then has nothing to run (no cluster)."""
    with Journal(out / "journal.jsonl") as j:
        for i, p in enumerate(prepared.points):
            j.append({**run_point(prepared.payload, PointTask(prepared.keys[i], p.index, dict(p.parameters))),
                      "parameters": dict(p.parameters)})


@contextlib.contextmanager
def _no_space(path):
    raise OSError(errno.ENOSPC, "No space left on device", str(path))
    yield  # pragma: no cover


@pytest.mark.parametrize("extra, told", [
    ([], "the table, plots and study.json are not all written; every finished point is kept in"),
    (["--report"], None),  # the report alone: the file and the reason
])
def test_a_full_disk_while_the_plots_are_drawn_is_one_line(write_study, tmp_path, monkeypatch, capsys, extra, told):
    path = write_study(GRID)
    out = tmp_path / "out"
    _journal_every_point(prepare_study(load_study(path)), out)
    monkeypatch.setattr(study_plots, "atomic_path", _no_space)
    assert cli.main(["sweep", str(path), "--out", str(out), "-q", *extra]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    if told:
        assert err[0].startswith(f"dtcosim sweep: error: cannot write {out / 'imax.png'}: No space left on device; ")
        assert told in err[0] and "run the same command with --report" in err[0]
    else:
        assert err[0] == f"dtcosim sweep: error: {out / 'imax.png'}: No space left on device"
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []  # no temporary file left


@pytest.mark.parametrize("full_at", ["results.csv", "study.json"])
def test_a_full_disk_at_the_table_or_summary_names_the_file_and_leaves_no_temporary_file(
        write_study, tmp_path, monkeypatch, capsys, full_at):
    """The table and study.json went through a writer of their own: 'error: No space left on device' naming no
    file, and results.csv.tmp left behind (seen on a small tmpfs; the load sets' lifetime files the same)."""
    path = write_study(GRID)
    out = tmp_path / "out"
    _journal_every_point(prepare_study(load_study(path)), out)
    monkeypatch.setattr(os, "replace", FullAt(full_at))
    assert cli.main(["sweep", str(path), "--out", str(out), "-q", "--report"]) == 1
    assert capsys.readouterr().err.strip().splitlines() == [
        f"dtcosim sweep: error: {out / full_at}: No space left on device"]
    assert not [p.name for p in out.iterdir() if "tmp" in p.name]


def test_a_journal_line_that_does_not_fit_is_cut_off_and_names_the_journal(tmp_path, monkeypatch):
    """A full disk while a sweep journals a point: the sweep's one line was replaced by a bare 'error: No space left
    on device', raised again when the journal was closed with the half line still in its buffer."""
    from orchestrator.study import journal as journal_module
    from orchestrator.study.journal import read_journal

    path = tmp_path / "journal.jsonl"
    real_write = journal_module._write_all

    def half_then_full(fd, data):
        real_write(fd, data[:10])
        raise OSError(errno.ENOSPC, "No space left on device")

    with Journal(path) as journal:
        journal.append({"key": "a", "status": "ok"})
        monkeypatch.setattr(journal_module, "_write_all", half_then_full)
        with pytest.raises(OSError, match="No space left on device") as info:
            journal.append({"key": "b", "status": "ok"})
        assert info.value.filename == str(path)
        monkeypatch.undo()
        journal.append({"key": "c", "status": "ok"})
    assert [r["key"] for r in read_journal(path)] == ["a", "c"]
    assert path.read_bytes().count(b"\n") == 2  # no torn line between them


def test_a_full_disk_while_a_run_file_is_stored_leaves_no_partial_file(tmp_path, monkeypatch):
    """Issue 35.9: ENOSPC in the middle of a load set's run file left ``runs/<run>.npz.part``."""
    from orchestrator.study import lifetime_results

    plc = SimpleNamespace(channels=[SimpleNamespace(column="gearbox.shaft_torque")], keys=["k0"])
    channel = {"ranges": [1.0, 2.0], "means": [0.0, 0.0], "counts": [1.0, 0.5], "levels": {"edges": [0.0, 1.0]},
               "mean": 0.0, "std": 1.0, "min": -1.0, "max": 1.0}
    result = {"data": {"channels": {"gearbox.shaft_torque": channel}, "analysed_time_s": 10.0, "window_s": [0, 10]}}

    def half_written(fh, **arrays):
        fh.write(b"PK\x03\x04 half a run file")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(np, "savez_compressed", half_written)
    with pytest.raises(OSError, match="No space left on device") as info:
        lifetime_results.store_run_data(plc, tmp_path)(0, result)
    assert info.value.filename == str(tmp_path / "runs" / "0000-k0.npz")
    assert list((tmp_path / "runs").iterdir()) == []


@pytest.mark.parametrize("workers", ["0", "1", str(max(4, 4 * (os.cpu_count() or 1))),
                                     str(max(4, 4 * (os.cpu_count() or 1)) + 1), "100000"])
def test_workers_have_an_upper_bound_that_the_error_states(write_study, tmp_path, capsys, workers):
    from orchestrator.commands.cluster_options import max_workers

    path = write_study(GRID)
    assert max_workers() == max(4, 4 * (os.cpu_count() or 1))
    ok = 1 <= int(workers) <= max_workers()
    code = cli.main(["sweep", str(path), "--out", str(tmp_path / "o"), "--check", "--workers", workers])
    err = capsys.readouterr().err
    if ok:
        assert code == 0, err
    else:
        assert code == 1 and err.strip() == (
            f"dtcosim sweep: error: invalid study entry --workers = {workers}: expected an integer from 1 to "
            f"{max_workers()} (4 x the {os.cpu_count()} CPUs of this machine: each worker is a process of 150-300 MB, "
            "and more than the cores only take turns; for more, start a cluster and give --scheduler)")


@pytest.mark.slow
def test_the_local_cluster_keeps_its_scratch_space_private_and_removes_it(tmp_path):
    from distributed import Client

    from orchestrator.study.cluster import locked_down_local_cluster

    cluster = locked_down_local_cluster(workers=1)
    scratch = Path(cluster.scratch)
    try:
        assert stat.S_IMODE(scratch.stat().st_mode) == 0o700 and scratch.name.startswith("dtcosim-dask-")
        with Client(cluster, security=cluster.security) as client:
            places = client.run(lambda dask_worker: dask_worker.local_directory)
        assert places and all(Path(p).is_relative_to(scratch) for p in places.values()), places
    finally:
        cluster.close()
        cluster.remove_scratch()
    assert not scratch.exists()


# a sweep that receives a stop signal while its LocalCluster starts a worker: the signal arrives from the cluster's
# event-loop thread while the main thread waits for the cluster to come up
SIGNAL_IN_START_UP = """
import os, signal, sys
sys.path.insert(0, {root!r})
from distributed import nanny
from orchestrator.commands import cli

start = nanny.Nanny.start_unsafe

async def signalled_start(self):
    os.kill(os.getpid(), signal.{signame})
    return await start(self)

nanny.Nanny.start_unsafe = signalled_start
cli.end_process(cli.main(["sweep", {study!r}, "--workers", "1", "--out", {out!r}, "-q", "--no-plots",
                          "--executor", "dask"]))
"""


@pytest.mark.slow
@pytest.mark.parametrize("signame, status", [("SIGTERM", 143), ("SIGHUP", 129)])
def test_a_signal_during_the_cluster_start_up_is_one_line(write_study, tmp_path, signame, status):
    """It left a cluster nobody closed: an atexit AssertionError, or the workers' heartbeat errors."""
    path = write_study(GRID)
    out = tmp_path / "out"
    code = SIGNAL_IN_START_UP.format(root=str(ROOT), signame=signame, study=str(path), out=str(out))
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300,
                          cwd=tmp_path, start_new_session=True, preexec_fn=as_from_a_terminal())
    assert proc.returncode == status, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"dtcosim sweep: interrupted; 0 finished points kept in {out / 'journal.jsonl'}; run the same command again "
        "to continue"], proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("table_fits", [True, False])
def test_a_full_disk_while_a_result_is_kept_stops_the_sweep_with_one_line(write_study, tmp_path, monkeypatch,
                                                                          table_fits):
    from orchestrator.study.sweep import run_sweep

    prepared = prepare_study(load_study(write_study(GRID)))
    out = tmp_path / "out"

    def no_space(i, result):
        raise OSError(errno.ENOSPC, "No space left on device", str(out / "runs" / f"{i}.npz"))

    if not table_fits:  # the disk stays full: the table cannot be written after the stop either
        monkeypatch.setattr(os, "replace", FullAt("results.csv"))
    report = run_sweep(prepared, out, workers=1, plots=False, on_result=no_space)
    assert report.ok == 0 and not report.interrupted and len(report.problems) == 1, report.problems
    assert report.problems[0].startswith(f"cannot write {out / 'runs'}/") and "the sweep stopped" in report.problems[0]
    assert ("the table, plots and study.json are not all written either" in report.problems[0]) != table_fits
    assert (out / "results.csv").exists() == table_fits and (out / "journal.jsonl").read_text() == ""


@pytest.mark.parametrize("table_fits", [True, False])
def test_a_sweep_stopped_by_a_full_disk_is_one_line_whether_its_table_is_written_or_not(
        write_study, tmp_path, monkeypatch, capsys, table_fits):
    """The stop and the table it then could not write either were two error lines for one full disk."""
    from orchestrator.study import sweep

    path = write_study(GRID)
    out = tmp_path / "out"
    journal = out / "journal.jsonl"

    def stopped_at_the_journal(prepared, todo, journal_file, report, *args):  # as _execute stops on ENOSPC
        report.stopped_at = f"cannot write {journal}: No space left on device"

    monkeypatch.setattr(sweep, "_execute", stopped_at_the_journal)
    if not table_fits:
        monkeypatch.setattr(os, "replace", FullAt("results.csv"))
    # on the cluster's path (_execute): a study this small would run in the command's own process
    assert cli.main(["sweep", str(path), "--out", str(out), "-q", "--no-plots", "--executor", "dask"]) == 1
    either = "" if table_fits else "; the table, plots and study.json are not all written either"
    assert capsys.readouterr().err.strip().splitlines() == [
        f"dtcosim sweep: error: cannot write {journal}: No space left on device; the sweep stopped, the points "
        f"finished before are kept in {journal}{either}: free some space and run the same command again to continue"]
    assert (out / "results.csv").exists() == table_fits


@pytest.mark.slow
def test_a_signal_while_a_point_is_journaled_is_counted_with_the_point(write_study, tmp_path, monkeypatch):
    """A SIGTERM that landed between a point's journal line and its count: the sweep said "48 finished points kept"
    of a journal that held 49 (seen sending SIGTERM to paper-sensitivity as its last point finished)."""
    import signal

    from orchestrator.study.journal import read_journal
    from orchestrator.study.sweep import run_sweep

    real_append = Journal.append
    appended = []

    def append_then_signal(self, record):
        real_append(self, record)
        appended.append(record["key"])
        if len(appended) == 2:
            signal.raise_signal(signal.SIGTERM)  # handled at once: the sweep notes it and raises it after the step

    monkeypatch.setattr(Journal, "append", append_then_signal)
    path = write_study(GRID)
    report = run_sweep(prepare_study(load_study(path)), tmp_path / "out", workers=1, plots=False)
    assert report.interrupted and report.signal == signal.SIGTERM
    assert report.ok + report.failed + report.errors == len(read_journal(tmp_path / "out" / "journal.jsonl")) == 2
