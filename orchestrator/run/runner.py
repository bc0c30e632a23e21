"""One scenario run from start to files: co-simulation, results, plots, optional reference.

Used by ``dtcosim run`` and by the tests; everything a run writes goes into one
output directory (default ``results/<scenario name>/``).
"""

from __future__ import annotations

import contextlib
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..atomic_files import describe_os_error
from ..cosim.master import CoSimulation
from ..cosim.outcome import RunOutcome
from ..cosim.physics_view import PhysicsUnavailable, physics_view
from ..cosim.stop_requests import StopRequests, exit_status
from ..cosim.resolved import ResolvedSystem
from ..errors import FmuStepError, InitializationError, RunInterrupted, signal_name
from ..inputs.scenario import Scenario
from ..inputs.scenario_file import load_scenario
from .analyses import RunAnalyses, analyse_run
from .comparison import compare, format_comparison, run_reference
from .derived import Skipped, generator_vs_ideal
from .memory import release_between_phases
from .plots import plot_run
from .recorded import compare_recorded, plot_contact_loss_counts, plot_recorded
from .results import build_summary, result_columns, results_writer
from .run_folder import RunFolder
from .writers import ResultWriter


def signal_number(name: str) -> int:
    """``"SIGTERM"`` -> 15."""
    return int(signal.Signals[name])


def load_any(path: str | Path, step_s: float | None = None, stop_s: float | None = None,
             report: Callable[[str], None] | None = None) -> Scenario:
    """A scenario from a TOML file or an SSP (``.ssp`` archive, ``.ssd`` file or SSP directory).

    ``step_s``, ``stop_s`` (``--step``, ``--stop``) are what an SSP without them uses;
    ``report`` receives the SSP import's notes (:func:`orchestrator.interop.ssp.import_ssp`).
    """
    from ..interop.ssp import import_ssp, is_ssp

    if is_ssp(path):
        return import_ssp(path, step_s=step_s, stop_s=stop_s, report=report)
    return load_scenario(Path(path))


@dataclass
class RunReport:
    """What :func:`run_scenario` did.

    Attributes
    ----------
    outcome : RunOutcome
        Also for a run that stopped before its first step (no rows, ``stage`` says where).
    summary : dict
        The content of ``summary.json``.
    files : dict of str -> pathlib.Path
        Whole files written, by role (``timeseries``, ``summary``, ``plot:<name>``).
    comparison_text : str
        The co-simulation vs monolithic table ("" without ``compare_reference``).
    problems : list of str
        What went wrong after the co-simulation (a file that could not be written); empty if nothing.
    replaced : list of str
        Files of a previous run in the output folder that this run removed.
    exit_status : int
        0 complete, ``128 + signal`` when stopped by a signal, 1 otherwise.
    """

    outcome: RunOutcome
    summary: dict[str, Any]
    files: dict[str, Path] = field(default_factory=dict)
    comparison_text: str = ""
    problems: list[str] = field(default_factory=list)
    replaced: list[str] = field(default_factory=list)
    exit_status: int = 0


def _stage_of(exc: FmuStepError | InitializationError) -> str:
    if isinstance(exc, FmuStepError) and exc.function in ("fmi2Instantiate", "fmi2SetupExperiment"):
        return "instantiation"
    return "initialisation"


def run_scenario(system: ResolvedSystem, out_dir: str | Path, *, compare_reference: bool = False, plots: bool = True,
                 progress: Callable[[int, int], None] | None = None, handle_sigint: bool = True,
                 profile: bool = False, results_format: str | None = None) -> RunReport:
    """Run a checked scenario and write ``timeseries.csv`` (or ``.parquet``), ``summary.json``, the analyses, the plots.

    The analyses (:func:`orchestrator.run.analyses.analyse_run`: contact loss, fatigue
    loads, contact-force spectra) add ``contact_loss.csv``, ``fatigue_del.csv``,
    ``fatigue_ldd.csv`` and their plots.

    What survives a stop
    --------------------
    The folder is checked and the previous run's files are removed first
    (:class:`~orchestrator.run.run_folder.RunFolder`); ``summary.json`` says
    ``"status": "running"`` from then on and lists each file once it is whole.
    The samples are streamed into ``timeseries.csv.partial`` (``timeseries.parquet.partial``,
    an Arrow IPC stream, for the binary format) block by block and made
    ``timeseries.csv`` (``.parquet``) when the co-simulation ends. SIGINT, SIGTERM
    and SIGHUP stop the run between blocks of steps (or before the next FMU is
    instantiated, or before the next result file); an FMU failure, a failed
    initialisation and a write error (full disk) stop it too. Every stop ends
    with a ``summary.json`` saying ``complete: false``, the ``stage``, where
    (``stopped_at``) and why (``error``), and which files are whole (``files``)
    or not (``files_incomplete``). After SIGKILL the summary still says
    ``running`` and the ``.partial`` file is readable up to its last block
    (:func:`orchestrator.result_files.read_timeseries`).

    Parameters
    ----------
    system : ResolvedSystem
    out_dir : path
        Created if missing; the files of a previous run in it are removed.
    compare_reference : bool
        Also run the monolithic reference on the same scenario and report every
        statistic of both (``summary.json`` key ``comparison``).
    plots : bool
        Write the PNG plots.
    progress : callable(done, total), optional
        Progress callback (communication steps).
    handle_sigint : bool
        Stop cleanly on SIGINT, SIGTERM and SIGHUP (partial results, ``complete: false``).
    profile : bool
        Time every FMI call per FMU (``summary.json`` key ``profile``).
    results_format : {"auto", "csv", "parquet"}, optional
        The results file (:mod:`orchestrator.inputs.results_format`); default: the
        scenario's ``[record] format``. ``summary.json`` says which
        (``results_format``, ``files.timeseries``).

    Returns
    -------
    RunReport
        Results are written also when the run stops early; ``outcome.complete`` tells.

    Raises
    ------
    OutputFolderError
        If ``out_dir`` is a file or cannot be written (before anything runs).
    """
    wall0 = time.perf_counter()
    sc = system.scenario
    # the stop handling is in place before the folder holds any file: a signal from here on ends the run with a
    # summary that says so (a signal while the folder is prepared stops the run before its first FMU steps)
    with StopRequests(enabled=handle_sigint) as stop:
        folder = RunFolder.prepare(out_dir, {"scenario": sc.name, "description": sc.description,
                                             "scenario_file": sc.source})
        try:
            return _run_in(folder, stop, system, wall0, compare_reference=compare_reference, plots=plots,
                           progress=progress, profile=profile, results_format=results_format)
        except BaseException as exc:  # a second signal, a bug: the summary says how the run ended, never "running"
            folder.abandon(exc)
            raise
        finally:
            folder.release()


def _run_in(folder: RunFolder, stop: StopRequests, system: ResolvedSystem, wall0: float, *, compare_reference: bool,
            plots: bool, progress, profile: bool, results_format: str | None) -> RunReport:
    """:func:`run_scenario` once the folder is prepared."""
    sc = system.scenario
    sim = sc.simulation
    out = folder.path
    writer = results_writer(results_format or sc.results_format, out, sim, len(system.recorded))
    folder.header["results_format"] = writer.format
    problems: list[str] = []
    cosim = CoSimulation(system, profile=profile)
    try:
        folder.claim(writer.path)
        writer.open(result_columns(system.recorded))
        folder.mark_incomplete("timeseries", writer.partial_path, "being written by the run")
    except OSError as exc:
        writer.abandon()
        problems.append(describe_os_error(exc))
        outcome = RunOutcome.empty(system.recorded, sim.start_s, f"results not written: {problems[-1]}", "writing")
    else:
        try:
            outcome = cosim.run(progress=progress, sink=writer, stop=stop)
        except (FmuStepError, InitializationError) as exc:
            outcome = RunOutcome.empty(system.recorded, sim.start_s, str(exc), _stage_of(exc),
                                       fmu_log={n: list(i.log) for n, i in cosim.instances.items()})
        except RunInterrupted as exc:
            outcome = RunOutcome.empty(system.recorded, sim.start_s, str(exc), exc.stage, interrupted=True,
                                       stop_signal=stop.signal_name or signal_name(exc.signum))
        _finish_timeseries(writer, outcome, folder, problems)
    derived: dict[str, Any] = {}
    skipped: list[dict[str, str]] = []
    comparison = None
    comparison_text = ""
    post = _PostProcessing(stop, folder, compare_reference=compare_reference, plots=plots)
    if outcome.time_s.size and not problems:
        try:
            comparison, comparison_text = _post_process(system, outcome, out, post, derived, skipped,
                                                        compare_reference, plots)
        except OSError as exc:  # a full disk: what was written and computed before is kept and listed
            problems.append(describe_os_error(exc))
            post.fail(problems[-1])
    if post.stopped:
        derived["post_processing"] = {"stopped": post.stopped, "not_done": post.not_done,
                                      **({"error": post.error} if post.error else {})}
    derived["analyses_skipped"] = skipped
    if outcome.start_values:
        derived.update(_settling(system, outcome))
    summary = build_summary(system, outcome, wall_time_s=time.perf_counter() - wall0, derived=derived,
                            comparison=comparison, listing=folder.listing(), header=folder.header,
                            problems=problems)
    files = {role: out / name for role, name in folder.files.items()}
    try:
        files["summary"] = folder.finish(summary)
        if folder.shortened:
            problems.append(folder.shortened)
    except OSError as exc:
        problems.append(f"summary.json not written ({describe_os_error(exc)}): {out} holds no summary of this run")
    signum = stop.signum if stop.signum is not None else (
        signal_number(outcome.stop_signal) if outcome.stop_signal else None)
    if signum is not None:
        status = exit_status(signum)
    elif outcome.complete and not problems:
        status = 0
    else:
        status = 1
    return RunReport(outcome, summary, files, comparison_text, problems, list(folder.replaced), status)


def _settling(system: ResolvedSystem, outcome: RunOutcome) -> dict[str, Any]:
    """``settling`` (the drivetrain's settling time at the run's start) and a ``window_warning`` when the window
    starts before it; ``coupling`` (the longest step that resolves its modes split across FMUs, the longest output
    interval that samples them) and a ``step_warning`` or ``output_warning`` where they are longer, a
    ``window_length_warning`` where the window is shorter than one period of that mode ({} without a dtcosim
    drivetrain)."""
    from ..cosim.operating_point import start_analyses, window_note

    sim = system.scenario.simulation
    out: dict[str, Any] = {}
    settling, limit = start_analyses(system, outcome.start_values)
    if settling is not None:
        out["settling"] = settling.as_dict()
        note = window_note(settling, sim.window_s[0], sim.start_s, f"the analysis window [{sim.window_s[0]:g}, "
                                                                    f"{sim.window_s[1]:g}] s")
        if note is not None:
            out["window_warning"] = note
    if limit is not None:
        out["coupling"] = limit.as_dict()
        out.update(limit.warnings(sim.step_s, sim.step_s * sim.output_stride, sim.window_s))  # the samples' interval
    return out


def _finish_timeseries(writer: ResultWriter, outcome: RunOutcome, folder: RunFolder, problems: list[str]) -> None:
    """Rename the streamed file when whole; otherwise say in the summary what it holds."""
    if outcome.stage == "writing":
        writer.abandon()
        folder.mark_incomplete("timeseries", writer.partial_path, outcome.error or "write error",
                               rows=writer.rows_written)
        problems.append(outcome.error or "results not written")
        return
    if writer.rows_written == 0:  # stopped before the first sample: no results file at all
        writer.abandon()
        with contextlib.suppress(OSError):
            writer.partial_path.unlink()
        folder.incomplete.pop("timeseries", None)
        return
    try:
        folder.commit("timeseries", writer.close())
    except OSError as exc:
        writer.abandon()
        problems.append(describe_os_error(exc))
        folder.mark_incomplete("timeseries", writer.partial_path, problems[-1], rows=writer.rows_written)


class _PostProcessing:
    """Stages after the co-simulation; a stop request skips the ones not started, a write error the rest."""

    def __init__(self, stop: StopRequests, folder: RunFolder, *, compare_reference: bool, plots: bool) -> None:
        self.stop = stop
        self.folder = folder
        self.stopped = ""
        self.not_done: list[str] = []
        #: the stages in the order :func:`_post_process` runs them
        self.stages = ["generator_vs_ideal", "recorded_comparison", "analyses", *["comparison"] * compare_reference,
                       *["plots"] * plots]
        self.current: str | None = None
        #: the write error that stopped the stages (None: none did)
        self.error: str | None = None

    def go(self, stage: str) -> bool:
        """True if ``stage`` may start."""
        if self.stop.requested and not self.stopped:
            self.stopped = f"{self.stop.reason}; the co-simulation's results are whole"
        if self.stopped:
            self.not_done.append(stage)
            return False
        self.current = stage
        return True

    def fail(self, problem: str) -> None:
        """A file of the current stage could not be written: the rest of it and every later stage are not done."""
        self.stopped, self.error = f"stopped: {problem}", problem
        self.not_done = []
        if self.current is not None:
            self.not_done = [f"the rest of {self.current}", *self.stages[self.stages.index(self.current) + 1:]]

    def commit(self, files: dict[str, Path]) -> None:
        for role, path in files.items():
            self.folder.commit(role, path)


def _post_process(system, outcome, out, post: _PostProcessing, derived, skipped, compare_reference, plots):
    """Derived quantities, analyses, the monolithic comparison and the plots, stage by stage."""
    comparison = None
    comparison_text = ""
    if post.go("generator_vs_ideal"):
        try:
            derived["generator_vs_ideal"] = generator_vs_ideal(system, outcome)
        except Skipped as exc:
            skipped.append({"analysis": "generator_vs_ideal", "reason": str(exc)})
    if system.events:
        derived["events"] = [a.as_dict() for a in system.events]
    derived["analysis_settings"] = system.scenario.analysis.as_dict()
    if post.go("recorded_comparison"):
        recorded = compare_recorded(system, outcome)
        if recorded:  # simulated against recorded channels (a TimeSeriesSource playing a record)
            derived["recorded_comparison"] = recorded
    if post.go("analyses"):
        analyses = RunAnalyses()
        try:
            analyse_run(system, outcome, out, plots=plots, into=analyses)
        finally:  # also when a file could not be written: what was computed and written before is kept
            derived.update(analyses.summary)
            if analyses.notes:
                derived["analysis_notes"] = analyses.notes
            skipped += analyses.skipped
            post.commit(analyses.files)
        release_between_phases(outcome.values.nbytes)  # the analyses' figures and temporaries, before the plots
    if compare_reference and post.go("comparison"):
        if not outcome.complete:
            comparison = {"skipped": "the co-simulation did not complete"}
        else:
            try:
                view = physics_view(system)
                reference = run_reference(system, view)
                comparison = compare(outcome, reference, system, view)
                comparison_text = format_comparison(comparison)
            except PhysicsUnavailable as exc:
                comparison = {"skipped": f"no monolithic reference: {exc}"}
                comparison_text = f"no monolithic comparison: {exc}"
                skipped.append({"analysis": "comparison", "reason": str(exc)})
    if plots and post.go("plots"):
        drawn: list[Path] = []
        try:
            plot_run(system, outcome, out, skipped, drawn)
        finally:  # the plots written before one that could not be
            post.commit({f"plot:{p.stem}": p for p in drawn})
        recorded_plot = plot_recorded(system, outcome, out)
        if recorded_plot is not None:
            post.commit({f"plot:{recorded_plot.stem}": recorded_plot})
        counts_plot = plot_contact_loss_counts(derived.get("contact_loss"), out, system.scenario.name)
        if counts_plot is not None:
            post.commit({f"plot:{counts_plot.stem}": counts_plot})
    return comparison, comparison_text
