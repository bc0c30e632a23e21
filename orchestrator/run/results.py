"""Results of a run on disk: ``timeseries.csv`` and ``summary.json``.

``timeseries.csv`` or ``timeseries.parquet``
    The format is the scenario's ``[record] format`` (or ``--results``): ``csv``,
    ``parquet``, or ``auto``, Parquet for long runs
    (:mod:`orchestrator.inputs.results_format`). The Parquet file has the same
    columns, named ``component.variable`` with the unit and FMI type as metadata
    (:mod:`orchestrator.columnar_files`); :func:`orchestrator.result_files.read_timeseries`
    reads both. The CSV has one row per sample: ``time [s]`` and every recorded variable, header
    ``component.variable [unit]`` with the unit the FMU declares (``[-]`` when it
    declares none), e.g. ``gearbox.stage1.F_sp[1] [N]``. Streamed while the run
    steps (``timeseries.csv.partial``, :mod:`orchestrator.run.writers`) and renamed
    when the co-simulation ends, also for an incomplete run (the samples up to
    where it stopped).

``summary.json``
    ``scenario``, ``complete``, ``statistics`` (``{"component.variable": {"mean",
    "std", "min", "max"}}`` over the analysis window, of the recorded signals: outputs
    and locals that vary by their declared variability, no parameters), ``window_s``,
    ``wall_time_s``, ``steps``, the time grid and master options, the generator
    speed against the ideal gearbox (``generator_vs_ideal``), ``versions``
    (dtcosim, python, numpy, scipy, fmpy, pythonfmu), ``fmus`` (file, SHA-256,
    model name, GUID per component), ``stopped_at`` and ``error`` for an
    incomplete run, ``comparison`` with ``--compare-reference``. Non-finite
    numbers are written as ``null``.

    How the run ended: ``status`` (``complete``, ``stopped`` by a signal,
    ``failed``; ``running`` while it runs, see :mod:`orchestrator.run.run_folder`),
    ``stage`` (``instantiation``, ``initialisation``, ``stepping``, ``writing``),
    ``signal`` when a signal stopped it, ``problems`` (files that could not be
    written), ``post_processing`` when analyses or plots were not done. ``files``
    lists the whole files by role, ``files_incomplete`` those that are there but
    not whole (with the reason and the rows they hold).

    ``import_notes`` (an SSP scenario): what the import passed over, among them
    every parameter value it did not apply and why (SSP 1.0, 5.2.3); ``notes``:
    what the checks of the system accepted with a caveat (a loop through outputs
    without declared dependencies, run with Jacobi).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from components.reference.results import window_statistics

from ..archive_members import shown_path
from ..cosim.outcome import RunOutcome
from ..cosim.resolved import ResolvedSystem
from ..inputs.results_format import RESULTS_FILES, concrete_format
from ..result_files import jsonable, versions
from .writers import Column, CsvWriter, ResultWriter

TIMESERIES_FILE = RESULTS_FILES["csv"]
TIMESERIES_PARQUET = RESULTS_FILES["parquet"]
SUMMARY_FILE = "summary.json"


def results_writer(requested: str, out_dir: str | Path, sim=None, variables: int = 0) -> ResultWriter:
    """The writer of a run's results file in ``out_dir``: ``requested`` is ``csv``, ``parquet`` or ``auto``.

    ``auto`` needs ``sim`` (:class:`~orchestrator.inputs.scenario.SimulationSettings`) and the
    number of recorded ``variables`` to count the values. The writer's ``format``
    attribute says which it is.
    """
    samples = sim.n_steps // sim.output_stride + 1 if sim is not None else 0
    fmt = concrete_format(requested, samples, variables)
    if fmt == "parquet":
        from .parquet_writer import ParquetWriter

        writer: ResultWriter = ParquetWriter(Path(out_dir) / TIMESERIES_PARQUET)
    else:
        writer = CsvWriter(Path(out_dir) / TIMESERIES_FILE)
    return writer


def column_header(component: str, variable: str, unit: str, fmi_type: str = "Real") -> str:
    """CSV header of a column: ``component.variable [unit]`` (``[Boolean 0/1]``, ``[String]`` for those types)."""
    return Column(f"{component}.{variable}", unit, fmi_type).header


def result_columns(columns) -> list[Column]:
    """The results-file columns of recorded variables (:class:`~orchestrator.cosim.system.RecordedVariable`)."""
    return [Column(c.column, c.unit, c.type) for c in columns]


def write_timeseries(path: str | Path, outcome: RunOutcome, chunk_rows: int | None = None) -> Path:
    """Write an outcome's samples with the writer a run streams into: Parquet for a ``.parquet`` path, else CSV.

    ``chunk_rows``: hand the rows over in chunks of that many (as a run does), default all at once.
    """
    path = Path(path)
    if path.suffix == ".parquet":
        from .parquet_writer import ParquetWriter

        writer: ResultWriter = ParquetWriter(path)
    else:
        writer = CsvWriter(path)
    writer.open(result_columns(outcome.columns))
    try:
        text = {j: outcome.text[c.column] for j, c in enumerate(outcome.columns) if c.column in outcome.text}
        n = len(outcome.time_s)
        step = chunk_rows or max(n, 1)
        for i in range(0, n, step):
            part = {j: v[i:i + step] for j, v in text.items()}
            writer.append(outcome.time_s[i:i + step], outcome.values[i:i + step], part or None)
    except BaseException:
        writer.abandon()
        raise
    return writer.close()


def statistics(outcome: RunOutcome, window: tuple[float, float],
               system: ResolvedSystem | None = None) -> dict[str, dict[str, float]]:
    """Mean, std, min, max over ``window`` [s] of every recorded signal (with ``system``: the variables it declares
    signals, :meth:`~orchestrator.cosim.resolved.ResolvedSystem.is_signal`; a recorded parameter is none)."""
    return {c.column: window_statistics(outcome.time_s, outcome.values[:, i], window)
            for i, c in enumerate(outcome.columns)
            if c.type != "String" and (system is None or system.is_signal(c.component, c.variable))}


def run_status(outcome: RunOutcome, problems: list[str] | None = None) -> str:
    """``complete``, ``stopped`` (a signal) or ``failed``."""
    if outcome.interrupted:
        return "stopped"
    return "complete" if outcome.complete and not problems else "failed"


def _record_checks(component) -> dict[str, Any]:
    """``{"records": [...]}``: per record its channels' resolution, step ratio and low-pass cut-off ({} without a record)."""
    series = getattr(component, "series", None)
    if series is None:
        return {}
    return {"records": [{"source": r.record.name, "channels": [dict(c) for c in r.checks]} for r in series.records]}


def build_summary(system: ResolvedSystem, outcome: RunOutcome, *, wall_time_s: float,
                  derived: Mapping[str, Any] | None = None, comparison: Mapping[str, Any] | None = None,
                  files: Mapping[str, str] | None = None, listing: Mapping[str, Any] | None = None,
                  header: Mapping[str, Any] | None = None, problems: list[str] | None = None) -> dict[str, Any]:
    """The ``summary.json`` content of a run (see the module docstring).

    ``files`` (role -> name) or ``listing`` (``{"files": ..., "files_incomplete": ...}``
    of :meth:`~orchestrator.run.run_folder.RunFolder.listing`) say what the folder holds.
    """
    sc = system.scenario
    sim = sc.simulation
    summary: dict[str, Any] = dict(header or {})
    summary.update({
        "scenario": sc.name,
        "description": sc.description,
        "scenario_file": sc.source,
        "status": run_status(outcome, problems),
        "complete": bool(outcome.complete),
        "stage": outcome.stage,
    })
    if outcome.ended_by is not None:
        summary["ended_by"] = outcome.ended_by
        summary["stopped_at"] = outcome.stopped_at_s
    if not outcome.complete:
        summary["stopped_at"] = outcome.stopped_at_s
        summary["error"] = outcome.error
        summary["interrupted"] = outcome.interrupted
        if outcome.stop_signal:
            summary["signal"] = outcome.stop_signal
    if problems:
        summary["problems"] = list(problems)
    if sc.import_notes:
        summary["import_notes"] = list(sc.import_notes)
    if system.notes:
        summary["notes"] = list(system.notes)
    if system.delays:
        summary["coupling_delays"] = [d.as_dict() for d in system.delays]
    summary["samples"] = int(outcome.time_s.size)
    summary.update({
        "window_s": list(sim.window_s),
        "statistics": statistics(outcome, sim.window_s, system),
        "wall_time_s": wall_time_s,
        "cosimulation_wall_time_s": outcome.wall_time_s,
        "loop_time_s": outcome.loop_time_s,
        "steps": outcome.steps,
        "step_s": sim.step_s,
        "start_s": sim.start_s,
        "stop_s": sim.stop_s,
        "output_interval_s": sim.output_interval_s,
        "algorithm": sim.algorithm,
        "extrapolation": sim.extrapolation,
        "order": list(system.order),
        "initial_values": dict(outcome.initial_values),
    })
    if derived:
        summary.update(derived)
    summary["versions"] = versions()
    summary["fmus"] = {
        name: {
            "file": shown_path(system.fmu_paths[name]),  # a member of an .ssp: <archive>!<member>
            "sha256": iface.sha256,
            "model_name": iface.model_name,
            "guid": iface.guid,
            "generation_tool": iface.generation_tool,
            "parameters": dict(sc.component(name).parameters),
            **_record_checks(sc.component(name)),
        }
        for name, iface in system.interfaces.items()
    }
    if outcome.profile is not None:
        summary["profile"] = {"seconds_per_fmi_function": outcome.profile, "loop_time_s": outcome.loop_time_s}
    if files:
        summary["files"] = dict(files)
    if listing:
        summary.update(dict(listing))
    if comparison is not None:
        summary["comparison"] = comparison
    warnings = {name: [m for m in log if m.startswith(("[warning]", "[discard]", "[error]", "[fatal]"))]
                for name, log in outcome.fmu_log.items()}
    warnings = {k: v for k, v in warnings.items() if v}
    if warnings:
        summary["fmu_messages"] = warnings
    return jsonable(summary)


