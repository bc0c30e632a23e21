"""``dtcosim sweep``: run a parameter study on Dask workers.

Exit status: 0 every point has a result (``ok`` or ``failed``: failed points
are results, listed in the table); 1 invalid study, or points that hit an
infrastructure error (re-tried by the next run); 130 interrupted by Ctrl-C (143 SIGTERM, 129 SIGHUP)
(finished points are kept; run the same command again to continue).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

from .catalogue import help_line
from .cluster_options import add_cluster_arguments, check_cluster_arguments, check_workers, ran
from .cluster_options import where as cluster_where
from .fmu_options import add_fmu_arguments, said_once
from .scenario_options import add_allow_argument, allow_implausible


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``sweep`` subcommand."""
    p = sub.add_parser(
        "sweep",
        help=help_line("sweep"),
        description=(
            "Run every point of a study on Dask workers (a LocalCluster by default, or an existing cluster) "
            "with the co-simulation or the monolithic engine, and write journal.jsonl (one line per finished "
            "point), results.csv, study.json and PNG plots. STUDY is a study TOML file or the name of a packaged "
            "study (paper-sensitivity). Points already in the output directory's journal are not run again."
        ),
    )
    p.add_argument("study", metavar="STUDY", help="study TOML file or packaged study name (e.g. paper-sensitivity)")
    add_cluster_arguments(p)
    p.add_argument("--out", type=Path, default=None, help="output directory (default: results/<study name>)")
    add_fmu_arguments(p, "the base scenario's")
    p.add_argument("--retry-failed", action="store_true",
                   help="run points whose journal record says 'failed' again (default: failures are final)")
    p.add_argument("--check", action="store_true", help="only validate the study against its base and print the plan")
    p.add_argument("--report", action="store_true",
                   help="only regenerate results.csv, study.json and the plots from the journal (nothing runs)")
    p.add_argument("--no-plots", action="store_true", help="do not write the PNG plots")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary")
    p.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                   help="wall-clock time one point may take; past it the point fails (overrides the study's "
                        "timeout; not part of the point keys: with --retry-failed, a larger value re-runs "
                        "the points that ran out of time)")
    add_allow_argument(p, "the study")
    p.set_defaults(func=run)


def _progress_bar(total: int, initial_desc: str):
    """A tqdm bar on stderr counting finished points, and the per-record callback for it."""
    from tqdm import tqdm

    try:
        size = os.get_terminal_size(sys.stderr.fileno())
    except OSError:
        size = os.terminal_size((0, 0))
    bar = tqdm(total=total, unit="pt", desc=initial_desc, file=sys.stderr, ncols=size.columns or 80,
               nrows=size.lines or 24, dynamic_ncols=False)
    counts = {"failed": 0, "error": 0}

    def progress(record: dict) -> None:
        if record["status"] in counts:
            counts[record["status"]] += 1
            bar.set_postfix(failed=counts["failed"], error=counts["error"], refresh=False)
        bar.update(1)

    return bar, progress


def run(args: argparse.Namespace) -> int:
    """Validate the study, run its pending points, write the results."""
    started = time.perf_counter()
    from ..inputs.study import StudyError
    from ..inputs.study_file import find_study, load_study
    from ..output_folders import check_for_study
    from ..study.journal import JOURNAL_FILE, read_journal
    from ..study.prepare import prepare_study
    from ..study.report import point_records, status_counts, write_outputs
    from ..study.sweep import pending_points, run_sweep

    quiet = args.quiet
    check_workers(args, StudyError)
    study = load_study(find_study(args.study))
    if args.timeout is not None:
        try:
            study = replace(study, timeout_s=args.timeout)
        except StudyError as exc:
            raise StudyError("--timeout", exc.value, exc.expected) from None
    study = allow_implausible(study, args.allow_implausible)
    out_dir = args.out if args.out is not None else Path("results") / study.name
    check_for_study(out_dir, study.name)  # a run's folder or another study's: refused before anything is prepared
    say = (lambda msg: None) if quiet else (lambda msg: print(msg, file=sys.stderr))
    prepared = prepare_study(study, fmu_dir=args.fmu_dir, build=not args.no_build, report=said_once(say))
    for note in prepared.notes:
        print(f"dtcosim sweep: warning: {note}", file=sys.stderr)
    if args.check:
        todo = pending_points(prepared, read_journal(out_dir / JOURNAL_FILE), args.retry_failed)
        print(f"{study.name}: valid; engine {study.engine}, base {study.base.kind} {study.base.name}; "
              f"{len(prepared.points)} points ({' x '.join(str(n) for n in study.shape)}), {len(todo)} to run "
              f"into {out_dir}; measures {', '.join(m.name for m in study.measures)}")
        return 0
    if args.report:
        files = write_outputs(prepared, out_dir, plots=not args.no_plots)
        counts = status_counts(point_records(prepared, out_dir=out_dir))
        if not quiet:
            print(f"{study.name}: {counts}; written " + ", ".join(p.name for p in files.values()))
        return 0

    check_cluster_arguments(args, "sweep")
    where = cluster_where(args)
    bar = None
    progress = None

    def on_start(pending: int, skipped: int) -> None:
        nonlocal bar, progress
        say(f"{study.name}: {len(prepared.points)} points, {skipped} already in {out_dir / JOURNAL_FILE}, "
            f"{pending} to run with the {study.engine} engine on {where}")
        if pending and not quiet and sys.stderr.isatty():
            bar, progress_cb = _progress_bar(pending, study.name)
            progress = progress_cb

    def forward(record: dict) -> None:
        if progress is not None:
            progress(record)

    try:
        report = run_sweep(prepared, out_dir, workers=args.workers, scheduler=args.scheduler,
                           retry_failed=args.retry_failed, progress=forward, on_start=on_start,
                           plots=not args.no_plots, dashboard=args.dashboard, executor=args.executor)
    finally:
        if bar is not None:
            bar.close()
    counts = status_counts(point_records(prepared, out_dir=out_dir))
    if not quiet:
        finished = report.ok + report.failed + report.errors
        if report.submitted:
            print(f"{study.name}: {finished} of {report.submitted} submitted points finished ({report.ok} ok, "
                  f"{report.failed} failed, {report.errors} errors) {ran(report)} in "
                  f"{report.compute_time_s:.2f} s (whole command {time.perf_counter() - started:.2f} s, its FMUs "
                  "and files included); "
                  f"{report.skipped} skipped (already in the journal)")
        else:
            print(f"{study.name}: nothing to run, all {report.skipped} points are in the journal "
                  f"(--retry-failed runs failed points again)")
        print(f"table: {counts['ok']} ok, {counts['failed']} failed, {counts['error']} error, "
              f"{counts['pending']} pending")
        print(f"results in {out_dir}/: " + ", ".join(p.name for p in report.files.values()))
    if counts["failed"]:
        print(f"dtcosim sweep: warning: {counts['failed']} points failed (see the error column of "
              f"{out_dir / 'results.csv'})", file=sys.stderr)
    for problem in report.problems:
        print(f"dtcosim sweep: error: {problem}", file=sys.stderr)
    if report.interrupted:
        print(f"dtcosim sweep: interrupted; {report.ok + report.failed + report.errors} finished points kept in "
              f"{out_dir / JOURNAL_FILE}; run the same command again to continue", file=sys.stderr)
        return 128 + (report.signal or 2)
    return 1 if counts["error"] or counts["pending"] or report.problems else 0
