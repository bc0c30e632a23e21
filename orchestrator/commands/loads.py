"""``dtcosim loads``: run a load-case set on Dask workers and write lifetime DELs, damage, LDD and LRD.

Exit status: 0 every run finished (``ok`` or ``failed``); 1 invalid set, or runs
that hit an infrastructure error (re-tried by the next call); 128 + the signal when
interrupted: 130 Ctrl-C, 143 SIGTERM, 129 SIGHUP (finished runs are kept; the same command
continues).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from .catalogue import help_line
from .cluster_options import add_cluster_arguments, check_cluster_arguments, check_workers, ran
from .cluster_options import where as cluster_where
from .fmu_options import add_fmu_arguments, said_once
from .scenario_options import add_allow_argument, allow_implausible


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``loads`` subcommand."""
    p = sub.add_parser(
        "loads",
        help=help_line("loads"),
        description=(
            "Run every case of a load-case set (each wind-speed bin at its operating point, with several seeds) "
            "on Dask workers (a LocalCluster by default, or an existing cluster), then weight the runs by the wind "
            "distribution over the design life: per-run and lifetime damage-equivalent loads, Miner damage, load "
            "duration and load revolution distributions (CSV with units, PNG plots) and a report ranking the bins "
            "by their share of lifetime damage. SET is a load-case set TOML file or a packaged set's name "
            "(paper-turbine). Runs already in the output directory's journal are not run again."
        ),
    )
    p.add_argument("set", metavar="SET", help="load-case set TOML file or packaged set name (e.g. paper-turbine)")
    add_cluster_arguments(p)
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: results/loads/<set name>, apart from dtcosim run's folders)")
    add_fmu_arguments(p, "the base scenario's")
    p.add_argument("--length", type=_seconds_or("to_stop"), default=None, metavar="SECONDS",
                   help='override the analysed length of each run, or "to_stop" (runs.length; changes the run keys)')
    p.add_argument("--transient", type=_seconds_or("settled"), default=None, metavar="SECONDS",
                   help='override the discarded transient of each run, or "settled": the drivetrain\'s settling '
                        "time (runs.transient; changes the run keys)")
    p.add_argument("--seeds", type=int, default=None, metavar="N",
                   help="override the seeds with 1..N (runs.seeds)")
    p.add_argument("--retry-failed", action="store_true", help="run cases whose journal record says 'failed' again")
    p.add_argument("--check", action="store_true", help="only validate the set against its base and print the plan")
    p.add_argument("--report", action="store_true",
                   help="only recompute the lifetime results from the finished runs (nothing runs): after changing "
                        "the wind distribution, the life, the S-N curves or the equivalent cycle count")
    p.add_argument("--no-plots", action="store_true", help="do not write the PNG plots")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bars and no report on the terminal")
    p.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                   help="wall-clock time one run may take (overrides the set's timeout)")
    add_allow_argument(p, "the load-case set")
    p.set_defaults(func=run)


class _Progress:
    """A bar for the whole set and one per running case (tqdm on stderr, terminals only)."""

    def __init__(self, total: int, name: str, labels: dict[int, str]) -> None:
        from tqdm import tqdm

        self._tqdm = tqdm
        self.labels = labels
        self.total = tqdm(total=total, unit="run", desc=name, file=sys.stderr, position=0, dynamic_ncols=True)
        self.cases: dict[int, object] = {}
        self.counts = {"failed": 0, "error": 0}

    def case(self, event: dict) -> None:
        """A worker's progress event (communication steps of one running case)."""
        i = int(event["index"])
        bar = self.cases.get(i)
        if bar is None:
            if len(self.cases) > 8:
                return
            bar = self._tqdm(total=int(event["total"]), unit="step", desc=self.labels.get(i, f"run {i}"),
                             file=sys.stderr, position=len(self.cases) + 1, leave=False, dynamic_ncols=True)
            self.cases[i] = bar
        bar.n = int(event["done"])
        bar.refresh()

    def finished(self, record: dict) -> None:
        """A case's journal record."""
        bar = self.cases.pop(int(record["index"]), None)
        if bar is not None:
            bar.close()
        if record["status"] in self.counts:
            self.counts[record["status"]] += 1
            self.total.set_postfix(failed=self.counts["failed"], error=self.counts["error"], refresh=False)
        self.total.update(1)

    def close(self) -> None:
        for bar in self.cases.values():
            bar.close()
        self.total.close()


def default_out_dir(name: str) -> Path:
    """``results/loads/<set name>``: a run of a scenario of the same name writes ``results/<name>/``."""
    from ..output_folders import LOADS_FOLDER

    return Path("results") / LOADS_FOLDER / name


def earlier_default_folder(name: str, out_dir: Path) -> Path | None:
    """``results/<set name>`` when it holds this set's journal and ``out_dir`` none (the default before), else None."""
    from ..output_folders import STUDY_JOURNAL, study_in

    earlier = Path("results") / name
    if (out_dir / STUDY_JOURNAL).exists() or not (earlier / STUDY_JOURNAL).is_file():
        return None
    return earlier if study_in(earlier) in (name, "") else None


def _seconds_or(word: str):
    """An argparse type: a number of seconds, or ``word`` (given back as the string)."""
    def parse(text: str):
        if text == word:
            return word
        try:
            return float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected seconds or {word!r}, got {text!r}") from None
    parse.__name__ = f"seconds or {word!r}"
    return parse


def run(args: argparse.Namespace) -> int:
    """Validate the set, run its pending cases, write the lifetime results."""
    import uuid

    from ..inputs.load_case_file import find_load_cases, load_load_cases
    from ..inputs.load_cases import MAX_SEEDS, LoadCaseError
    from ..output_folders import check_for_study
    from ..study.journal import JOURNAL_FILE, read_journal
    from ..study.lifetime_outputs import write_lifetime_outputs
    from ..study.lifetime_results import check_curves, mark_missing_run_files, store_run_data
    from ..study.load_cases import prepare_load_cases
    from ..study.report import point_records, status_counts
    from ..study.sweep import pending_points, run_sweep

    quiet = args.quiet
    check_workers(args, LoadCaseError)
    lcs = load_load_cases(find_load_cases(args.set))
    changes = {}
    for option, attr in (("length", "length_s"), ("transient", "transient_s"), ("timeout", "timeout_s")):
        value = getattr(args, option)
        if value is not None:
            changes[attr] = None if value in ("to_stop", "settled") else value
    if args.seeds is not None:
        if not 1 <= args.seeds <= MAX_SEEDS:  # before a tuple of that many exists
            raise LoadCaseError("--seeds", args.seeds, f"an integer from 1 to {MAX_SEEDS}")
        changes["seeds"] = tuple(range(1, args.seeds + 1))
    if changes:
        lcs = replace(lcs, **changes)
    lcs = allow_implausible(lcs, args.allow_implausible)
    out_dir = args.out if args.out is not None else default_out_dir(lcs.name)
    check_for_study(out_dir, lcs.name)  # a run's folder or another study's: refused before anything is prepared
    say = (lambda msg: None) if quiet else (lambda msg: print(msg, file=sys.stderr))
    plc = prepare_load_cases(lcs, fmu_dir=args.fmu_dir, build=not args.no_build, report=said_once(say))
    check_curves(plc)
    for note in plc.notes:
        print(f"dtcosim loads: warning: {note}", file=sys.stderr)
    if args.out is None:
        earlier = earlier_default_folder(lcs.name, out_dir)
        if earlier is not None:
            print(f"dtcosim loads: note: {earlier} holds the runs of an earlier `dtcosim loads {args.set}` (load sets "
                  f"wrote results/<set>/ before; now {out_dir}/, apart from `dtcosim run`'s folders): to continue "
                  f"them, move it first: mv {earlier} {out_dir}", file=sys.stderr)
    prepared = plc.prepared
    if args.check:
        todo = pending_points(prepared, read_journal(out_dir / JOURNAL_FILE), args.retry_failed)
        print(f"{lcs.name}: valid; base scenario {lcs.base_scenario}; {len(plc.bins)} bins x {len(lcs.seeds)} seeds = "
              f"{len(plc.cases)} runs of {plc.load_cases.transient_s:g} + {plc.load_cases.length_s:g} s, {len(todo)} to run into {out_dir}; "
              f"{len(plc.channels)} channels; wind {lcs.wind.describe()}")
        return 0
    if args.report:
        files = write_lifetime_outputs(plc, out_dir, plots=not args.no_plots)
        if not quiet:
            print((out_dir / "lifetime_report.txt").read_text(), end="")
            print(f"results in {out_dir}/: " + ", ".join(p.name for p in files.values()))
        return 0
    check_cluster_arguments(args, "loads")

    if mark_missing_run_files(plc, out_dir):
        say(f"{lcs.name}: some finished runs have lost their run files in {out_dir}/runs: they run again")
    prepared = replace(prepared, payload=replace(prepared.payload, progress_topic=f"dtcosim-loads-{uuid.uuid4().hex[:8]}"))
    plc = replace(plc, prepared=prepared)
    where = cluster_where(args)
    labels = {c.index: f"run {c.index} {plc.bins[c.bin].label} seed {c.seed}" for c in plc.cases}
    bars: dict[str, _Progress] = {}

    def on_start(pending: int, skipped: int) -> None:
        say(f"{lcs.name}: {len(plc.cases)} runs, {skipped} already in {out_dir / JOURNAL_FILE}, {pending} to run on {where}")
        if pending and not quiet and sys.stderr.isatty():
            bars["p"] = _Progress(pending, lcs.name, labels)

    def finished(record: dict) -> None:
        if "p" in bars:
            bars["p"].finished(record)
        elif not quiet:
            say(f"  {labels.get(record['index'], record['index'])}: {record['status']}"
                + (f" ({record['error']})" if record.get("error") else ""))

    def case(event: dict) -> None:
        if "p" in bars:
            bars["p"].case(event)

    try:
        report = run_sweep(prepared, out_dir, workers=args.workers, scheduler=args.scheduler,
                           retry_failed=args.retry_failed, progress=finished, on_start=on_start, plots=False,
                           dashboard=args.dashboard, executor=args.executor, on_result=store_run_data(plc, out_dir),
                           case_progress=case)
    finally:
        if "p" in bars:
            bars["p"].close()
    problems = list(report.problems)
    try:
        files = write_lifetime_outputs(plc, out_dir, plots=not args.no_plots)
    except OSError as exc:  # a full disk: the runs are kept, the lifetime results can be written later
        from ..atomic_files import describe_os_error

        files = {}
        if not problems:  # a full disk the sweep told already (what is kept, what to do) is not told twice
            problems.append(f"{describe_os_error(exc)}; the lifetime results are not all written; every finished "
                            f"run is kept in {out_dir / JOURNAL_FILE} and {out_dir}/runs: free some space and run the "
                            "same command with --report to write them")
    counts = status_counts(point_records(prepared, out_dir=out_dir))
    if not quiet and files:
        print((out_dir / "lifetime_report.txt").read_text(), end="")
        if report.submitted:
            finished_n = report.ok + report.failed + report.errors
            print(f"{lcs.name}: {finished_n} of {report.submitted} submitted runs finished ({report.ok} ok, "
                  f"{report.failed} failed, {report.errors} errors) {ran(report)} in "
                  f"{report.compute_time_s:.2f} s; {report.skipped} skipped (already in the journal)")
        else:
            print(f"{lcs.name}: nothing to run, all {report.skipped} runs are in the journal")
        print(f"results in {out_dir}/: " + ", ".join(p.name for p in files.values()))
    if counts["failed"]:
        print(f"dtcosim loads: warning: {counts['failed']} runs failed (see {out_dir / 'results.csv'}); the lifetime "
              "figures leave them out", file=sys.stderr)
    for problem in problems:
        print(f"dtcosim loads: error: {problem}", file=sys.stderr)
    if report.interrupted:
        print(f"dtcosim loads: interrupted; finished runs kept in {out_dir / JOURNAL_FILE}; run the same command "
              "again to continue", file=sys.stderr)
        return 128 + (report.signal or 2)
    return 1 if counts["error"] or counts["pending"] or problems else 0
