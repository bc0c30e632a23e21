"""One scenario run from start to files: co-simulation, results, plots, optional reference.

Used by ``dtcosim run`` and by the tests; everything a run writes goes into one
output directory (default ``results/<scenario name>/``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..cosim.master import CoSimulation, RunOutcome
from ..cosim.physics_view import PhysicsUnavailable, physics_view
from ..cosim.system import ResolvedSystem
from ..inputs.scenario import Scenario, load_scenario
from ..result_files import write_summary
from .analyses import analyse_run
from .comparison import compare, format_comparison, run_reference
from .derived import Skipped, generator_vs_ideal
from .plots import plot_run
from .recorded import compare_recorded, plot_contact_loss_counts, plot_recorded
from .results import SUMMARY_FILE, TIMESERIES_FILE, build_summary, write_timeseries


def load_any(path: str | Path, step_s: float | None = None, stop_s: float | None = None,
             report: Callable[[str], None] | None = None) -> Scenario:
    """A scenario from a TOML file or an SSP (``.ssp`` archive, ``.ssd`` file or SSP directory).

    ``step_s``, ``stop_s`` (``--step``, ``--stop``) are what an SSP without them uses;
    ``report`` receives the SSP import's notes (:func:`orchestrator.interop.ssp.import_ssp`).
    """
    p = Path(path)
    if p.suffix in (".ssp", ".ssd") or (p.is_dir() and (p / "SystemStructure.ssd").is_file()):
        from ..interop.ssp import import_ssp

        return import_ssp(p, step_s=step_s, stop_s=stop_s, report=report)
    return load_scenario(p)


@dataclass
class RunReport:
    """What :func:`run_scenario` did.

    Attributes
    ----------
    outcome : RunOutcome
    summary : dict
        The content of ``summary.json``.
    files : dict of str -> pathlib.Path
        Written files by role (``timeseries``, ``summary``, ``plot:<name>``).
    comparison_text : str
        The co-simulation vs monolithic table ("" without ``compare_reference``).
    """

    outcome: RunOutcome
    summary: dict[str, Any]
    files: dict[str, Path] = field(default_factory=dict)
    comparison_text: str = ""


def run_scenario(system: ResolvedSystem, out_dir: str | Path, *, compare_reference: bool = False, plots: bool = True,
                 progress: Callable[[int, int], None] | None = None, handle_sigint: bool = True,
                 profile: bool = False) -> RunReport:
    """Run a checked scenario and write ``timeseries.csv``, ``summary.json``, the analyses and the plots.

    The analyses (:func:`orchestrator.run.analyses.analyse_run`: contact loss, fatigue
    loads, contact-force spectra) add ``contact_loss.csv``, ``fatigue_del.csv``,
    ``fatigue_ldd.csv`` and their plots.

    Parameters
    ----------
    system : ResolvedSystem
    out_dir : path
        Created if missing; existing result files are overwritten.
    compare_reference : bool
        Also run the monolithic reference on the same scenario and report every
        statistic of both (``summary.json`` key ``comparison``).
    plots : bool
        Write the PNG plots.
    progress : callable(done, total), optional
        Progress callback (communication steps).
    handle_sigint : bool
        Stop cleanly on Ctrl-C (partial results, ``complete: false``).
    profile : bool
        Time every FMI call per FMU (``summary.json`` key ``profile``).

    Returns
    -------
    RunReport
        Results are written also when the run stops early; ``outcome.complete`` tells.
    """
    wall0 = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    outcome = CoSimulation(system, profile=profile).run(progress=progress, handle_sigint=handle_sigint)
    files: dict[str, Path] = {"timeseries": write_timeseries(out / TIMESERIES_FILE, outcome)}
    derived: dict[str, Any] = {}
    skipped: list[dict[str, str]] = []
    try:
        derived["generator_vs_ideal"] = generator_vs_ideal(system, outcome)
    except Skipped as exc:
        skipped.append({"analysis": "generator_vs_ideal", "reason": str(exc)})
    if system.events:
        derived["events"] = [a.as_dict() for a in system.events]
    derived["analysis_settings"] = system.scenario.analysis.as_dict()
    recorded = compare_recorded(system, outcome)
    if recorded:  # simulated against recorded channels (a TimeSeriesSource playing a record)
        derived["recorded_comparison"] = recorded
    analyses = analyse_run(system, outcome, out, plots=plots)
    derived.update(analyses.summary)
    if analyses.notes:
        derived["analysis_notes"] = analyses.notes
    skipped += analyses.skipped
    files.update(analyses.files)
    comparison = None
    comparison_text = ""
    if compare_reference:
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
    if plots:
        for p in plot_run(system, outcome, out, skipped):
            files[f"plot:{p.stem}"] = p
        recorded_plot = plot_recorded(system, outcome, out)
        if recorded_plot is not None:
            files[f"plot:{recorded_plot.stem}"] = recorded_plot
        counts_plot = plot_contact_loss_counts(derived.get("contact_loss"), out, system.scenario.name)
        if counts_plot is not None:
            files[f"plot:{counts_plot.stem}"] = counts_plot
    derived["analyses_skipped"] = skipped
    summary = build_summary(
        system, outcome, wall_time_s=time.perf_counter() - wall0, derived=derived, comparison=comparison,
        files={k: p.name for k, p in files.items()} | {"summary": SUMMARY_FILE},
    )
    files["summary"] = write_summary(out / SUMMARY_FILE, summary)
    return RunReport(outcome, summary, files, comparison_text)
