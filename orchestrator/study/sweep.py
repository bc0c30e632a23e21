"""Running a prepared study on Dask: the sweep loop, re-runs, interruptions.

:func:`run_sweep` runs the points of a :class:`~orchestrator.study.prepare.PreparedStudy`
that the output directory's journal does not already hold, on Dask workers: a
``distributed.LocalCluster`` (processes, one thread each, TLS with temporary
credentials, no dashboard unless asked: :mod:`orchestrator.study.cluster`) by
default, or an existing cluster given its scheduler address. What all points share (base
system, measures, FMU bytes) is scattered once; each task carries one point
(:func:`orchestrator.study.engine.run_point`).

Results are journaled by the client as futures complete (:mod:`orchestrator.study.journal`);
the CSV table and plots are regenerated from the journal when the sweep ends,
also after Ctrl-C.

Re-runs
-------
Running a study again skips every point whose key (see
:mod:`orchestrator.study.prepare`) has an ``ok`` record, and every ``failed``
one: a failure of the point itself (the model rejected a parameter, the solver
or an FMU failed) is deterministic for the same key, so it is not re-tried
unless ``retry_failed`` is set. Records with status ``error`` (a lost worker, an
unexpected exception) are re-tried on the next run.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import math
import os
import signal
import socket
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..atomic_files import describe_os_error
from ..cosim.stop_requests import STOP_SIGNALS, StopRequests
from ..import_safe_signals import install, restore
from ..inputs.study import StudyError
from ..output_folders import check_for_study
from .engine import FAILED, OK, PointInterrupted, PointTask, run_point
from .journal import JOURNAL_FILE, Journal, latest_by_key, read_journal
from .prepare import PreparedStudy

ERROR = "error"
#: how long a sweep waits for the first worker of an existing cluster [s]
WAIT_FOR_WORKERS_S = 60.0
#: where a sweep without ``scheduler`` runs its points: ``auto`` (in this process while the pending points add up
#: to less work than :data:`MIN_CLUSTER_WORK_S`, else on a LocalCluster), ``process`` (always here, one point at a
#: time), ``dask`` (always on a LocalCluster)
EXECUTORS = ("auto", "process", "dask")
#: a study whose pending points add up to less wall time than this [s] runs in the sweep's own process: twice what
#: starting a LocalCluster of 2 workers and loading the study's code and FMUs in them costs before its first point
#: (4.3 s, ``bench_sweep.py --overhead`` on the shared 2-core machine; 10.4 s while it was busier), rounded up: about
#: the least work that 2 workers finish sooner than 1 process
MIN_CLUSTER_WORK_S = 10.0


# --------------------------------------------------------------------- sweep
@dataclass
class SweepReport:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    total : int
        Points of the study.
    skipped : int
        Points the journal already held (not run again).
    submitted : int
        Points run in this sweep.
    ok, failed, errors : int
        Outcomes of the submitted points that finished (``failed``: the point
        itself failed; ``errors``: infrastructure or unexpected errors).
    interrupted : bool
        Stopped by a signal: Ctrl-C, SIGTERM or SIGHUP (finished points are journaled).
    signal : int
        That signal's number (0 if none).
    wall_time_s : float
        The whole call [s] (cluster start-up and output files included).
    compute_time_s : float
        First point started (here) or submitted (to the cluster) to the last result [s].
    workers : int
        Workers of the cluster when the sweep started (0 if none ran).
    in_process : int
        Points run in the sweep's own process (``executor``: small studies, and the first points of
        any study without a ``scheduler`` while their cost is measured).
    out_dir : pathlib.Path
    files : dict of str -> pathlib.Path
        Written files by role (``journal``, ``table``, ``summary``, ``plot:<name>``).
    problems : list of str
        Files that could not be written (a full disk), one line per failure with what is kept and what to
        do; a run file or journal line that cannot be written stops the sweep, and its line also says
        when the table it then could not write either is missing (not a second line).
    stopped_at : str
        The write that stopped the sweep (``"cannot write <file>: No space left on device"``), "" if none.
    """

    total: int
    skipped: int = 0
    submitted: int = 0
    ok: int = 0
    failed: int = 0
    errors: int = 0
    interrupted: bool = False
    signal: int = 0
    wall_time_s: float = 0.0
    compute_time_s: float = 0.0
    workers: int = 0
    in_process: int = 0
    out_dir: Path = Path(".")
    files: dict[str, Path] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    stopped_at: str = ""


def pending_points(prepared: PreparedStudy, records: list[dict], retry_failed: bool = False) -> list[int]:
    """Indices of the points a sweep still has to run, given the journal's records."""
    latest = latest_by_key(records)
    out = []
    for i, key in enumerate(prepared.keys):
        rec = latest.get(key)
        if rec is None or rec.get("status") == ERROR or (rec.get("status") == FAILED and retry_failed):
            out.append(i)
    return out


class _Interrupts:
    """SIGINT, SIGTERM and SIGHUP handling that never splits a journal write: a signal during a write is raised after it.

    Nor an import: a signal that lands in one is delivered again after it
    (:func:`~orchestrator.import_safe_signals.install`).
    """

    def __init__(self, stop: StopRequests | None = None) -> None:
        self.critical = False
        self.pending = False
        self.previous: dict[int, object] = {}
        self.signum: int | None = None
        #: points run in this process: every signal is only noted and passed on to these stop requests, which
        #: the running point checks between its blocks of steps (nothing is raised inside an FMU's code)
        self.stop = stop

    def __enter__(self) -> "_Interrupts":
        self.previous = install(dict.fromkeys(STOP_SIGNALS, self._handler))
        return self

    def __exit__(self, *exc) -> None:
        restore(self.previous)

    def _handler(self, signum, frame) -> None:
        self.signum = self.signum or signum
        if self.stop is not None:
            self.stop.request(signum)
            self.pending = True
        elif self.critical:
            self.pending = True
        else:
            raise KeyboardInterrupt

    @contextlib.contextmanager
    def shielded(self):
        """Signals during the block are only noted (``pending``, ``signum``), never raised: the cluster's shutdown."""
        was = self.critical
        self.critical = True
        try:
            yield
        finally:
            self.critical = was

    @contextlib.contextmanager
    def critical_section(self):
        self.critical = True
        try:
            yield
        finally:
            self.critical = False
            if self.pending:
                self.pending = False
                raise KeyboardInterrupt


def _count(report: SweepReport, status: str) -> None:
    """Count a journaled point's outcome in ``report``."""
    if status == OK:
        report.ok += 1
    elif status == FAILED:
        report.failed += 1
    else:
        report.errors += 1


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _json_value(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _open_client(workers: int | None, scheduler: str | None, dashboard: str | None = None):
    """(client, cluster or None): a new locked-down LocalCluster, or a client of an existing scheduler."""
    from distributed import Client

    from .cluster import connect, locked_down_local_cluster

    if scheduler:
        return connect(scheduler), None
    cluster = locked_down_local_cluster(workers, dashboard)
    return Client(cluster, security=cluster.security), cluster


def _worker_count(client) -> int:
    """Workers connected to the scheduler now."""
    try:
        info = client.scheduler_info(n_workers=-1)  # newer distributed lists only a few workers by default
    except TypeError:
        info = client.scheduler_info()
    return len(info.get("workers", {}))


def _close(client, cluster) -> None:
    """Close the client, then the cluster we started (never an external one) and remove its scratch folder."""
    with contextlib.suppress(Exception):
        client.close(timeout=10)
    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.close(timeout=20)
        remove = getattr(cluster, "remove_scratch", None)
        if remove is not None:
            remove()


@contextlib.contextmanager
def _quiet_dask_logs():
    """Dask's loggers in this process (the LocalCluster's scheduler) at CRITICAL for the block.

    After a stop signal the scheduler logs the cancelled tasks it can no longer gather as
    errors; the sweep says in one line what happened.
    """
    import logging

    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


def run_sweep(
    prepared: PreparedStudy,
    out_dir: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    retry_failed: bool = False,
    progress: Callable[[dict[str, Any]], None] | None = None,
    on_start: Callable[[int, int], None] | None = None,
    plots: bool = True,
    dashboard: str | None = None,
    on_result: Callable[[int, dict[str, Any]], dict[str, Any]] | None = None,
    case_progress: Callable[[dict[str, Any]], None] | None = None,
    executor: str = "auto",
) -> SweepReport:
    """Run the study's pending points, in this process or on Dask, and write the journal, the table and the plots.

    Parameters
    ----------
    prepared : PreparedStudy
    out_dir : path
        Output directory (created): ``journal.jsonl``, ``results.csv``,
        ``study.json``, PNG plots. A folder that holds a run's results or another
        study's is refused (:func:`orchestrator.output_folders.check_for_study`).
    workers : int, optional
        Workers of the LocalCluster (processes with one thread each; default: CPU count).
    scheduler : str, optional
        Address of an existing Dask scheduler (e.g. ``tcp://10.0.0.5:8786``); then
        ``workers`` is ignored and the cluster is left running.
    retry_failed : bool
        Run points whose journal record says ``failed`` again.
    progress : callable(record), optional
        Called with each point's journal record as it is written.
    on_start : callable(pending, skipped), optional
        Called once before the cluster starts.
    plots : bool
        Write the PNG plots.
    dashboard : str, optional
        ``host:port`` of the LocalCluster's Dask dashboard (default: none; see
        :mod:`orchestrator.study.cluster`).
    on_result : callable(point index, worker result) -> dict, optional
        Called with each point's result before its journal record is written (e.g. to
        store the result's ``data`` in a file of its own); the fields it returns are
        added to the record.
    case_progress : callable(event), optional
        Called with the progress events the workers publish while a point runs
        (``{"key", "index", "done", "total"}``; the payload's ``progress_topic``).
    executor : {"auto", "process", "dask"}
        Without ``scheduler``: ``auto`` runs the points in this process, one at a time, for as long
        as the pending ones add up to less than :data:`MIN_CLUSTER_WORK_S` of work, measured on the
        points run so far (the first as a whole, then the cheapest), and hands the rest to a
        LocalCluster as soon as they do not; a small study so pays no cluster. ``process``: all
        here; ``dask``: all on the cluster. With ``scheduler`` the points run there.

    Returns
    -------
    SweepReport
        Also after Ctrl-C (``interrupted``); the journal holds every finished point.
    """
    from .report import write_outputs

    wall0 = time.perf_counter()
    out = Path(out_dir)
    check_for_study(out, prepared.study.name)  # a run's folder or another study's: refused (folders never mix)
    out.mkdir(parents=True, exist_ok=True)
    report = SweepReport(total=len(prepared.points), out_dir=out)
    journal_path = out / JOURNAL_FILE
    with Journal(journal_path) as journal:
        todo = pending_points(prepared, read_journal(journal_path), retry_failed)
        report.skipped = report.total - len(todo)
        if on_start is not None:
            on_start(len(todo), report.skipped)
        if executor not in EXECUTORS:
            raise StudyError("executor", executor, f"one of {', '.join(EXECUTORS)}")
        if todo and scheduler is None and executor != "dask":
            todo = _run_here(prepared, todo, journal, report, progress, on_result, case_progress,
                             None if executor == "process" else MIN_CLUSTER_WORK_S)
        if todo and not report.interrupted and not report.stopped_at:
            _execute(prepared, todo, journal, report, workers, scheduler, progress, dashboard, on_result,
                     case_progress)
    unwritten = ""
    try:
        report.files = write_outputs(prepared, out, report, plots=plots)
    except OSError as exc:  # a full disk while the table or the plots are drawn: the journal has every point
        unwritten = describe_os_error(exc)
    if report.stopped_at:  # one line for the full disk that stopped the sweep, whatever it kept from writing after
        report.problems.append(f"{report.stopped_at}; the sweep stopped, the points finished before are kept in "
                               f"{journal_path}" + ("; the table, plots and study.json are not all written either"
                                                    if unwritten else "")
                               + ": free some space and run the same command again to continue")
    elif unwritten:
        report.problems.append(f"{unwritten}; the table, plots and study.json are not all written; every finished "
                               f"point is kept in {journal_path}: free some space and run the same command with "
                               "--report to write them")
    report.wall_time_s = time.perf_counter() - wall0
    return report


def _error_result(prepared: PreparedStudy, i: int, exc: Exception) -> dict[str, Any]:
    """The result of a point that raised (a lost worker, a bug): recorded as an error, run again next time."""
    return {"key": prepared.keys[i], "index": prepared.points[i].index, "status": ERROR, "measures": {},
            "error": f"{type(exc).__name__}: {exc}", "error_type": type(exc).__name__}


def _keep(prepared: PreparedStudy, i: int, result: dict[str, Any], journal: Journal, report: SweepReport,
          interrupts: _Interrupts, on_result, progress) -> bool:
    """Journal a finished point (with what ``on_result`` adds) and count it.

    Returns False when the journal or the run's file cannot be written (a full disk): nothing more can
    be kept, so the sweep stops. A signal during the write is raised after it (a KeyboardInterrupt).
    """
    point = prepared.points[i]
    study = prepared.study
    record = {
        "key": prepared.keys[i], "index": point.index, "study": study.name, "engine": study.engine,
        "status": result["status"],
        "parameters": {k: _json_value(v) for k, v in point.parameters.items()},
        "measures": result.get("measures", {}), "error": result.get("error"),
        "error_type": result.get("error_type"), "worker": result.get("worker"),
        "task_wall_time_s": result.get("task_wall_time_s"), "code_version": prepared.identity["code"],
        "finished_at": _now(),
    }
    try:
        # storing a run's data, journaling it and counting it is one step: a signal during it is raised after all
        # three (raised between journal and count, the sweep would say one point fewer was kept)
        with interrupts.critical_section():
            if on_result is not None and record["status"] == OK:
                record.update(on_result(i, result))
            journal.append(record)
            _count(report, record["status"])
    except OSError as exc:  # a full disk: nothing more can be kept, so nothing more is run
        report.stopped_at = describe_os_error(exc)  # told once by run_sweep, with the table
        return False
    if progress is not None:
        progress(record)
    return True


def _run_here(prepared: PreparedStudy, todo: list[int], journal: Journal, report: SweepReport, progress,
              on_result, case_progress, limit_s: float | None) -> list[int]:
    """Run points in this process, one at a time; returns the points left for a cluster (see ``executor``).

    With ``limit_s`` (``auto``): after each point, the pending ones' work is estimated from the
    points run here (after the first, which also loads the code and FMUs: only whether it took the
    limit by itself; then the cheapest point after it times the pending ones); once it reaches
    ``limit_s`` the rest is returned. Stop signals are only noted and
    passed to the running point (a co-simulation stops between blocks of steps): a point cut short
    is not journaled, the sweep ends as interrupted after the point in progress.
    """
    stop = StopRequests(enabled=False)  # the requests of _Interrupts' handler, checked by the running point
    times: list[float] = []
    left = list(todo)
    t0 = time.perf_counter()
    with _Interrupts(stop) as interrupts:
        try:
            while left:
                if limit_s is not None and times:
                    # the first point also loads the code and the FMUs: alone it decides only when it took the
                    # limit by itself; from the second on, the cheapest point after it gives the cost of the rest
                    left_s = times[0] if len(times) == 1 else min(times[1:]) * len(left)
                    if left_s >= limit_s:
                        return left
                i = left[0]
                task = PointTask(prepared.keys[i], prepared.points[i].index, dict(prepared.points[i].parameters))
                wall0 = time.perf_counter()
                try:
                    result = run_point(prepared.payload, task, case_progress, stop)
                except PointInterrupted:
                    raise KeyboardInterrupt from None
                except Exception as exc:  # a bug: recorded as an error, re-tried next time
                    result = _error_result(prepared, i, exc)
                    result["worker"] = f"{socket.gethostname()}:{os.getpid()}"
                    result["task_wall_time_s"] = time.perf_counter() - wall0
                times.append(result["task_wall_time_s"])
                left.pop(0)
                report.submitted += 1
                report.in_process += 1
                if not _keep(prepared, i, result, journal, report, interrupts, on_result, progress):
                    return []
                if stop.requested:  # noted while the point ran: it finished anyway and is kept
                    raise KeyboardInterrupt
        except KeyboardInterrupt:
            report.interrupted = True
            report.signal = interrupts.signum or signal.SIGINT
            return []
        finally:
            report.compute_time_s += time.perf_counter() - t0
    return []


def _execute(prepared: PreparedStudy, todo: list[int], journal: Journal, report: SweepReport,
             workers: int | None, scheduler: str | None, progress, dashboard: str | None = None, on_result=None,
             case_progress=None) -> None:
    from distributed import as_completed

    study = prepared.study
    futures: dict = {}
    t0 = None
    with _Interrupts() as interrupts:
        client = cluster = None
        quiet = contextlib.ExitStack()
        try:
            # a signal during the cluster's start-up is raised once it is up (and it is closed below): raised
            # half-way, it left a cluster nobody closes (an atexit AssertionError, workers' heartbeat errors)
            with interrupts.critical_section():
                client, cluster = _open_client(workers, scheduler, dashboard)
            report.workers = _worker_count(client)
            if report.workers == 0:  # an existing cluster whose workers have not connected (yet)
                try:
                    client.wait_for_workers(1, timeout=WAIT_FOR_WORKERS_S)
                except TimeoutError:
                    raise StudyError("--scheduler", scheduler, f"a cluster with at least one worker (none connected "
                                     f"within {WAIT_FOR_WORKERS_S:g} s)") from None
                report.workers = _worker_count(client)
            topic = prepared.payload.progress_topic
            if case_progress is not None and topic:
                client.subscribe_topic(topic, lambda event: case_progress(event[1]))
            payload = client.scatter([prepared.payload], hash=False)[0]
            t0 = time.perf_counter()
            run_id = uuid.uuid4().hex[:8]
            for i in todo:
                point = prepared.points[i]
                task = PointTask(prepared.keys[i], point.index, dict(point.parameters))
                fut = client.submit(run_point, payload, task, key=f"{study.name}-{point.index}-{run_id}", pure=False)
                futures[fut] = i
            report.submitted += len(futures)
            for fut in as_completed(list(futures)):
                i = futures.pop(fut)
                try:
                    result = fut.result()
                except Exception as exc:  # a lost worker, KilledWorker, a bug: re-tried next time
                    result = _error_result(prepared, i, exc)
                fut.release()
                if not _keep(prepared, i, result, journal, report, interrupts, on_result, progress):
                    with interrupts.shielded(), contextlib.suppress(Exception):
                        client.cancel(list(futures))
                    break
        except KeyboardInterrupt:
            report.interrupted = True
            report.signal = interrupts.signum or signal.SIGINT
            quiet.enter_context(_quiet_dask_logs())
            if client is not None:
                with interrupts.shielded(), contextlib.suppress(Exception):
                    client.cancel(list(futures))
        finally:
            if t0 is not None:
                report.compute_time_s += time.perf_counter() - t0
            with interrupts.shielded(), quiet:  # a signal while the cluster closes is noted, never raised
                if interrupts.pending:
                    quiet.enter_context(_quiet_dask_logs())
                if client is not None:
                    _close(client, cluster)
            if interrupts.pending:  # a signal during the shutdown
                interrupts.pending = False
                report.interrupted = True
                report.signal = report.signal or interrupts.signum or signal.SIGINT
