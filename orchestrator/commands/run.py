"""``dtcosim run``: run a co-simulation scenario and write its results.

Exit status: 0 complete, 1 error (bad scenario, FMU failure, initialisation
failure, a results file that could not be written: ``summary.json`` says what
is there), ``128 + signal`` when stopped by a signal: 130 Ctrl-C (SIGINT), 143
SIGTERM, 129 SIGHUP (partial results written).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..inputs.results_format import RESULTS_FORMATS
from . import scenario_options
from .catalogue import help_line
from .fmu_options import add_fmu_arguments


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``run`` subcommand."""
    p = sub.add_parser(
        "run",
        help=help_line("run"),
        description=(
            "Run a co-simulation scenario through its FMUs with the fixed-step master and write "
            "timeseries.csv (or timeseries.parquet for long runs, see --results), summary.json and PNG plots. SCENARIO is a TOML file, an .ssp/.ssd file, or the "
            "name of a packaged scenario (default: paper-60s). Missing project FMUs are built first."
        ),
    )
    p.add_argument("scenario", nargs="?", default=None, metavar="SCENARIO",
                   help="scenario TOML/SSP file or packaged scenario name (default: paper-60s)")
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: results/<scenario name>, or results/<scenario name>-<id> "
                        "with --stop/--step/--output-interval/--algorithm/--extrapolation/--set; the files of a "
                        "previous run in it are replaced)")
    add_fmu_arguments(p)
    p.add_argument("--compare-reference", action="store_true",
                   help="also run the monolithic reference solver on the same scenario and report every statistic of both")
    scenario_options.add_arguments(p)
    p.add_argument("--check", action="store_true",
                   help="only check the scenario against the FMUs' model descriptions (nothing is instantiated) and exit")
    p.add_argument("--no-plots", action="store_true", help="do not write the PNG plots")
    p.add_argument("--results", choices=RESULTS_FORMATS, default=None,
                   help="results file: csv (timeseries.csv), parquet (timeseries.parquet: binary, units as metadata; "
                        "pandas.read_parquet, MATLAB parquetread) or auto, Parquet above 2 million values "
                        "(samples x recorded variables) (default: the scenario's [record] format, else auto)")
    p.add_argument("--profile", action="store_true",
                   help="time every FMI call per FMU and report where the stepping time goes (adds ~1 us per call)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no statistics table")
    p.set_defaults(func=run)


def _progress_bar(sim):
    """A tqdm bar on stderr counting simulated seconds, and the master's progress callback for it."""
    from tqdm import tqdm

    try:
        size = os.get_terminal_size(sys.stderr.fileno())
    except OSError:
        size = os.terminal_size((0, 0))
    # a terminal of unknown size reports 0 x 0, which would make tqdm hide the bar
    bar = tqdm(total=round(sim.stop_s - sim.start_s, 9), unit="s", unit_scale=False, desc="co-simulation",
               file=sys.stderr, ncols=size.columns or 80, nrows=size.lines or 24,
               bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}<{remaining}]")
    done_steps = [0]

    def progress(done: int, total: int) -> None:
        bar.update((done - done_steps[0]) * sim.step_s)
        done_steps[0] = done

    return bar, progress


def checked_system(scenario, fmu_dir, build: bool, command: str, say):
    """The scenario checked against its FMUs' model descriptions (``run --check``; nothing is instantiated).

    Finds the FMUs (building missing project FMUs if ``build``), warns of stale ones and prints
    the system's notes, as ``dtcosim <command>``; returns the
    :class:`~orchestrator.cosim.resolved.ResolvedSystem`. ``validate`` checks an SSP with it.
    """
    from ..cosim.system import resolve_system
    from ..provision.project_fmus import ensure_fmus
    from ..provision.staleness import stale_project_fmus

    paths = ensure_fmus(scenario, fmu_dir, build=build, report=say, kernels_in_background=True)
    for warning in stale_project_fmus(paths):
        print(f"dtcosim {command}: warning: {warning}", file=sys.stderr)
    system = resolve_system(scenario, fmu_paths=paths)
    for note in system.notes:
        print(f"dtcosim {command}: note: {note}", file=sys.stderr)
    return system


def check_report(system, name: str) -> str:
    """What ``run --check`` prints of a valid system called ``name``: its size, orders and the loops' explicit coupling."""
    scenario = system.scenario
    lines = [f"{name}: valid ({len(scenario.components)} FMUs, {len(scenario.connections)} connections, "
             f"{len(system.recorded)} recorded variables, {len(system.events)} load event(s); stepping order "
             f"{', '.join(system.order)}; initialisation order {', '.join(system.init_order)})"]
    lines += [f"  coupling: {delay.note}" for delay in system.delays
              if delay.note not in system.notes]  # the loops' explicit coupling (the notes are printed before)
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Run the scenario; write results; print a summary."""
    from ..run.analyses import format_analyses
    from ..run.run_folder import RunFolder
    from ..run.runner import run_scenario

    quiet = args.quiet
    say = (lambda msg: None) if quiet else (lambda msg: print(msg, file=sys.stderr))
    scenario = scenario_options.apply(scenario_options.load(args.scenario, args, "run"), args, "run")
    out_dir, out_note = (args.out, "") if args.out is not None else scenario_options.default_out_dir(scenario, args)
    system = checked_system(scenario, args.fmu_dir, not args.no_build, "run", say)
    if args.check:
        print(check_report(system, scenario.name))
        return 0
    RunFolder.check(out_dir)  # a file or an unwritable folder: refused before anything is instantiated
    if out_note:
        print(f"dtcosim run: note: {out_note}", file=sys.stderr)
    previous = scenario_options.previous_run(out_dir)
    if previous:
        print(f"dtcosim run: note: replacing the previous run in {out_dir}/ ({previous})", file=sys.stderr)
    sim = scenario.simulation
    say(f"{scenario.name}: {len(scenario.components)} FMUs, {sim.algorithm}/{sim.extrapolation}, "
        f"H = {sim.step_s:g} s, {sim.start_s:g}-{sim.stop_s:g} s ({sim.n_steps} steps), order {', '.join(system.order)}")

    bar, progress = _progress_bar(sim) if not quiet and sys.stderr.isatty() else (None, None)
    try:
        report = run_scenario(system, out_dir, compare_reference=args.compare_reference, plots=not args.no_plots,
                              progress=progress, profile=args.profile, results_format=args.results)
    finally:
        if bar is not None:
            bar.close()
    outcome = report.outcome
    s = report.summary
    for component, messages in s.get("fmu_messages", {}).items():  # what the FMUs warned about, once each
        for message in dict.fromkeys(m for m in messages if m.startswith("[warning]")):
            text = message.removeprefix("[warning]").strip().removeprefix("logStatusWarning:").strip()
            print(f"dtcosim run: warning: FMU {component}: {text}", file=sys.stderr)
    for warning in ("step_warning", "output_warning", "window_warning", "window_length_warning"):
        if warning in s:
            print(f"dtcosim run: warning: {s[warning]}", file=sys.stderr)
    if not outcome.time_s.size:  # stopped before the first sample: nothing to show
        told = f"{out_dir / 'summary.json'} says so" if "summary" in report.files else "no summary was written"
        for problem in report.problems[1:] if outcome.stage == "writing" else report.problems:
            print(f"dtcosim run: error: {problem}", file=sys.stderr)  # the first write error is the outcome's
        print(f"dtcosim run: {outcome.error}; nothing was simulated ({told})", file=sys.stderr)
        return report.exit_status
    if not quiet:
        import textwrap

        print(textwrap.fill(f"{scenario.name}: {'complete' if outcome.complete else 'INCOMPLETE'}, {outcome.steps} "
                            f"steps in {s['wall_time_s']:.2f} s (stepping {outcome.loop_time_s:.2f} s, "
                            f"{1e6 * outcome.loop_time_s / max(outcome.steps, 1):.1f} us/step)", width=80,
                            subsequent_indent="  "))
        from ..run.text_tables import fit_table, number

        w0, w1 = sim.window_s
        print(f"statistics over [{w0:g}, {w1:g}] s:")
        rows = [[name, *(number(st[k]) for k in ("mean", "std", "min", "max"))] for name, st in s["statistics"].items()]
        print("\n".join(fit_table(["variable", "mean", "std", "min", "max"], rows)))
        fig16 = s.get("generator_vs_ideal")
        if fig16:
            dev = fig16["relative_deviation"]
            if dev.get("max_abs") is not None:
                print(f"generator vs {fig16['ratio']:.6g} x rotor speed (relative): mean {dev['mean']:+.2e}, "
                      f"max |dev| {dev['max_abs']:.2e}")
        for row in s.get("recorded_comparison", []):
            print(textwrap.fill(
                f"simulated {row['simulated']} vs recorded {row['recorded']} over [{w0:g}, {w1:g}] s: "
                f"RMS difference {row['rms_difference']:.4g} ({100 * row['rms_difference_relative']:.3g} % of the "
                f"record's RMS), max {row['max_difference']:.4g} ({100 * row['max_difference_relative']:.3g} %), "
                f"mean {row['mean_difference']:+.4g}", width=80, subsequent_indent="  "))
        analyses = format_analyses(s)
        if analyses:
            print(analyses)
        if outcome.profile:
            steps = max(outcome.steps, 1)
            print("time per communication step in FMI calls [us]:")
            functions = ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal")
            fmi_total = sum(sum(times.values()) for times in outcome.profile.values())
            rows = [[comp, *(f"{1e6 * times[f] / steps:.1f}" for f in functions)] for comp, times in outcome.profile.items()]
            print("\n".join(fit_table(["component", *functions], rows)))
            print(f"  master (loop minus FMI calls): {1e6 * (outcome.loop_time_s - fmi_total) / steps:.1f} us/step")
        if report.comparison_text:
            print(report.comparison_text)
        print(textwrap.fill(f"results in {Path(out_dir)}/: " + ", ".join(p.name for p in report.files.values()),
                            width=80, subsequent_indent="  ", break_on_hyphens=False, break_long_words=False))
    post = s.get("post_processing")
    for problem in report.problems:
        if not post or problem != post.get("error"):  # the write error that stopped them: told below, once
            print(f"dtcosim run: error: {problem}", file=sys.stderr)
    if post and post.get("error"):
        print(f"dtcosim run: error: {post['error']}; not done: {', '.join(post['not_done'])}", file=sys.stderr)
    elif post and not outcome.interrupted:  # a signal during stepping is told once, below
        print(f"dtcosim run: {post['stopped']}; not done: {', '.join(post['not_done'])}", file=sys.stderr)
    if not outcome.complete:
        print(f"dtcosim run: {outcome.error}; partial results written to {out_dir}", file=sys.stderr)
    elif report.exit_status > 128 and not post and not report.problems:  # a signal after every result was written
        print(f"dtcosim run: interrupted ({signal_name(report.exit_status - 128)}) after every result was written: "
              f"{out_dir} holds the whole run", file=sys.stderr)
    elif report.exit_status > 128 and not post:  # a signal, and a result that could not be written (said above)
        told = f"{out_dir / 'summary.json'} lists what it holds" if "summary" in report.files else "it holds no summary"
        print(f"dtcosim run: interrupted ({signal_name(report.exit_status - 128)}); the co-simulation completed but "
              f"not every result was written: {out_dir} holds part of the run ({told})", file=sys.stderr)
    return report.exit_status


def signal_name(signum: int) -> str:
    """``SIGINT`` for 2 (the number itself when unknown)."""
    import signal

    try:
        return signal.Signals(signum).name
    except ValueError:
        return str(signum)
