"""Small studies run in the sweep's own process: same journal, table and re-runs as on Dask, no cluster started;
a study whose measured work is larger hands its remaining points to the cluster."""

from __future__ import annotations

import json
import os
import signal

import pytest

from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import load_study
from orchestrator.study import sweep
from orchestrator.study.journal import read_journal
from orchestrator.study.prepare import prepare_study
from orchestrator.study.report import read_table
from orchestrator.study.sweep import run_sweep
from tests.helpers.studies import SMALL_FAILURE, SMALL_HEAD, SMALL_STUDY, SMALL_TABLES, STAGE3_FORCE_N

# R1 below 7.4 makes Table 6's stage-1 planets implausible (paper-sensitivity allows it the same way)
GRID = SMALL_HEAD + SMALL_TABLES + ('[plausibility]\nallow = ["gearbox.stage1.planet_inertia"]\n'
                                   '[[axes]]\nparameter = "gearbox.R1"\nstart = 6.0\nstop = 10.0\nnum = 6\n')


@pytest.fixture
def no_cluster(monkeypatch):
    """Fail the test if a sweep starts a cluster."""
    def refuse(*args, **kwargs):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(sweep, "_open_client", refuse)


@pytest.mark.parametrize("executor", ["auto", "process"])
def test_a_small_study_runs_here_with_the_journal_and_table_of_a_cluster(write_study, tmp_path, executor, no_cluster):
    prepared = prepare_study(load_study(write_study(SMALL_STUDY)))
    out = tmp_path / "out"
    seen = []
    first = run_sweep(prepared, out, workers=2, progress=seen.append, executor=executor)
    assert (first.total, first.submitted, first.in_process, first.skipped, first.workers) == (4, 4, 4, 0, 0)
    assert (first.ok, first.failed, first.errors, first.interrupted) == (3, 1, 0, False)
    assert [r["index"] for r in seen] == [0, 1, 2, 3]  # in order, one journal record per point as it finished
    rows = read_table(out / "results.csv")
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "failed"] and rows[3]["error"] == SMALL_FAILURE
    for r in rows[:3]:
        assert float(r["gearbox.stage3.F_mesh:mean [N]"]) == pytest.approx(STAGE3_FORCE_N, rel=0.01)
    records = read_journal(out / "journal.jsonl")
    assert {r["worker"].rsplit(":", 1)[1] for r in records} == {str(os.getpid())}
    last = json.loads((out / "study.json").read_text())["last_sweep"]
    assert (last["in_process"], last["workers"]) == (4, 0)
    second = run_sweep(prepared, out, workers=2, executor=executor)
    assert (second.submitted, second.skipped) == (0, 4) and len(read_journal(out / "journal.jsonl")) == 4
    third = run_sweep(prepared, out, workers=1, retry_failed=True, executor=executor)
    assert (third.submitted, third.failed, third.in_process) == (1, 1, 1)


def test_a_study_whose_measured_work_is_larger_hands_the_rest_to_the_cluster(write_study, tmp_path, monkeypatch):
    """Auto measures the first points here; once the pending ones add up to the limit they go to Dask."""
    monkeypatch.setattr(sweep, "MIN_CLUSTER_WORK_S", 0.0)  # the first point alone takes the limit
    handed = []

    def execute(prepared, todo, journal, report, *args, **kwargs):
        handed.extend(todo)

    monkeypatch.setattr(sweep, "_execute", execute)
    prepared = prepare_study(load_study(write_study(GRID)))
    report = run_sweep(prepared, tmp_path / "out", workers=2, plots=False)
    assert report.in_process == 1 and handed == [1, 2, 3, 4, 5]  # measured on the first, the rest on the cluster
    assert [r["index"] for r in read_journal(tmp_path / "out" / "journal.jsonl")] == [0]


@pytest.mark.parametrize("times, here", [
    ([0.9, 0.1, 0.1, 0.1, 0.1, 0.1], 6),  # not 5 pending x 0.9 s: 4 x 0.1 s stay here
    ([0.9, 0.3, 0.1, 0.1, 0.1, 0.1], 2),  # 4 pending x 0.3 s = 1.2 s: the rest goes to the cluster
    ([1.2, 0.1, 0.1, 0.1, 0.1, 0.1], 1),  # the first point took the limit by itself
    ([0.1, 0.1, 0.1, 0.1, 0.1, 0.1], 6),
])
def test_the_estimate_is_the_first_point_then_the_cheapest_after_it(write_study, tmp_path, monkeypatch, times, here):
    """The first point also loads code (numba's cache, the FMUs); the limit here is 1 s."""
    took = iter(times)

    def fake_point(payload, task, progress=None, stop=None):
        return {"key": task.key, "index": task.index, "status": "ok", "measures": {}, "error": None,
                "error_type": None, "worker": "here:1", "task_wall_time_s": next(took)}

    handed = []
    monkeypatch.setattr(sweep, "run_point", fake_point)
    monkeypatch.setattr(sweep, "MIN_CLUSTER_WORK_S", 1.0)
    monkeypatch.setattr(sweep, "_execute", lambda prepared, todo, *a, **k: handed.extend(todo))
    prepared = prepare_study(load_study(write_study(GRID)))
    report = run_sweep(prepared, tmp_path / "out", workers=2, plots=False)
    assert report.in_process == here and handed == list(range(here, 6))


def test_a_stop_signal_lets_the_running_point_end_and_keeps_every_finished_one(write_study, tmp_path, no_cluster):
    prepared = prepare_study(load_study(write_study(GRID)))
    out = tmp_path / "out"

    def progress(record):
        if record["index"] == 1:
            os.kill(os.getpid(), signal.SIGTERM)  # noted; the sweep stops after the point it is in

    report = run_sweep(prepared, out, workers=2, plots=False, progress=progress)
    assert report.interrupted and report.signal == signal.SIGTERM and report.in_process == 2
    assert [r["index"] for r in read_journal(out / "journal.jsonl")] == [0, 1]
    rest = run_sweep(prepared, out, workers=2, plots=False)
    assert rest.submitted == 4 and [r["index"] for r in read_journal(out / "journal.jsonl")] == [0, 1, 2, 3, 4, 5]


def test_an_unknown_executor_is_refused(write_study, tmp_path):
    prepared = prepare_study(load_study(write_study(SMALL_STUDY)))
    with pytest.raises(StudyError, match="executor.*one of auto, process, dask"):
        run_sweep(prepared, tmp_path / "out", executor="threads")
