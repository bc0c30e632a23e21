"""What the user waits for: whole ``dtcosim`` commands, each in a fresh process, against the monolithic reference.

1. **Warm runs** (default): ``dtcosim run`` (the paper's 60 s scenario, plots included: what a
   user types first) and ``dtcosim reference --case table7 --json`` (the monolithic solver on the
   same case) taking turns, ``--repeat`` times each after one warm-up of each, into a temporary
   folder; printed: the median CPU time (user + system, of the command's process and its
   children) and wall time of each, and the ratio run / reference (target, issue 34: <= 1).
   ``--no-plots`` adds ``dtcosim run --no-plots``.
2. **The first run after install** (``--first-run``): ``dtcosim run`` with an empty per-user cache
   (``DTCOSIM_CACHE_DIR`` and ``MPLCONFIGDIR`` in a new temporary folder: no FMUs, no compiled
   kernels, no matplotlib font list) from a copy of this tree without bytecode, imported through
   ``PYTHONPATH`` (after ``pip install -e .`` no module of dtcosim is compiled yet: Python compiles
   each one the first run imports; ``--keep-bytecode``: this tree, its bytecode as its runs left
   it). One such run whose background kernel compile is awaited makes
   the warm runs' cache; then ``--repeat`` first runs, each in an empty cache of its own (the compile
   it starts in the background is ended after it), take turns with warm runs in that cache; printed:
   the medians of both and the ratio of the first run's wall time to the warm run's (target, issue 34:
   <= 3), and how long the background compile took. With ``--baseline REV`` a first run of the sources of
   git revision ``REV`` (``git archive`` into a temporary folder, a new copy of it for each run, imported
   through ``PYTHONPATH``; the repository is not touched) takes its turn after each first run of this tree, and the medians of the
   turns' ratios this tree / ``REV`` are printed.

The commands run with ``PYTHONDONTWRITEBYTECODE`` removed from their environment, as in a user's
shell: with it set every command compiles dtcosim's modules again. The machine's other work
changes the absolute times; the ratios are measured in the same run.

Run: ``python benchmarks/bench_commands.py [--repeat N] [--no-plots] [--first-run [--baseline REV]]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from baseline_tree import archive_tree, working_tree_copy

DTCOSIM = [sys.executable, "-m", "orchestrator.commands.cli"]


def environment(**changes: str) -> dict[str, str]:
    """This process's environment without ``PYTHONDONTWRITEBYTECODE``, with ``changes``."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    return {**env, **changes}


def timed(argv: list[str], env: dict[str, str], cwd: Path | None = None) -> tuple[float, float]:
    """(wall, CPU) seconds of one command; CPU is user + system of the process and the children it waited for."""
    wall0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, cwd=cwd)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - wall0
    err = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({proc.returncode}):\n{err}")
    return wall, usage.ru_utime + usage.ru_stime


def warm(repeat: int, no_plots: bool, env: dict[str, str]) -> dict[str, list[tuple[float, float]]]:
    """Each command once to warm up, then ``repeat`` times taking turns."""
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-commands-") as tmp:
        commands = {"dtcosim run": DTCOSIM + ["run", "--out", str(Path(tmp) / "run")],
                    "dtcosim reference --case table7 --json": DTCOSIM + ["reference", "--case", "table7", "--json"]}
        if no_plots:
            commands["dtcosim run --no-plots"] = DTCOSIM + ["run", "--no-plots", "--out", str(Path(tmp) / "bare")]
        for argv in commands.values():
            timed(argv, env, Path(tmp))
        times: dict[str, list[tuple[float, float]]] = {name: [] for name in commands}
        for _ in range(repeat):
            for name, argv in commands.items():
                times[name].append(timed(argv, env, Path(tmp)))
    return times


def report(times: dict[str, list[tuple[float, float]]]) -> dict[str, tuple[float, float]]:
    medians = {}
    for name, values in times.items():
        wall = statistics.median(w for w, _ in values)
        cpu = statistics.median(c for _, c in values)
        medians[name] = (wall, cpu)
        print(f"  {name:42s} {cpu:6.2f} s CPU  {wall:6.2f} s wall")
    return medians


def _stop_background_compile(cache: Path) -> None:
    """End the background kernel compile a first run started in ``cache`` (its own session: its whole group)."""
    import signal

    from components.compile.aot import background_builder

    os.environ["DTCOSIM_CACHE_DIR"] = str(cache)  # where background_builder looks
    pid = background_builder()
    if pid is not None:
        try:
            os.killpg(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass


def first_run(repeat: int, baseline: str | None = None, keep_bytecode: bool = False) -> None:
    """One first run whose background compile is awaited (the warm runs' cache), then ``repeat`` first runs, each
    with an empty cache of its own (its background compile ended after it) and, unless ``keep_bytecode``, from a
    copy of this tree without bytecode of its own, taking turns with warm runs (and with first runs of revision
    ``baseline``, each from a new copy of it unless ``keep_bytecode``)."""
    from components.compile.aot import build_lock_file

    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-first-") as tmp:
        tree = archive_tree(baseline, Path(tmp)) if baseline else None

        def first(tag: str, sources: Path | None = None) -> tuple[tuple[float, float], Path]:
            cache = Path(tmp) / f"cache-{tag}"
            env = environment(DTCOSIM_CACHE_DIR=str(cache), MPLCONFIGDIR=str(Path(tmp) / f"matplotlib-{tag}"))
            env.pop("DTCOSIM_FMU_DIR", None)
            if sources is not None:
                env["PYTHONPATH"] = str(sources)
            return timed(DTCOSIM + ["run", "--out", str(Path(tmp) / f"first-{tag}")], env, Path(tmp)), cache

        _, cache = first("warm")
        waited = time.perf_counter()
        os.environ["DTCOSIM_CACHE_DIR"] = str(cache)  # where build_lock_file looks
        while build_lock_file().exists():  # the kernels compiling in the background, for later runs
            time.sleep(0.5)
        print(f"  (the background compile ended {time.perf_counter() - waited:.1f} s after the first run)")
        warm_env = environment(DTCOSIM_CACHE_DIR=str(cache), MPLCONFIGDIR=str(Path(tmp) / "matplotlib-warm"))
        warm_env.pop("DTCOSIM_FMU_DIR", None)
        warm_argv = DTCOSIM + ["run", "--out", str(Path(tmp) / "warm")]
        timed(warm_argv, warm_env, Path(tmp))  # the warm-up
        times: dict[str, list[tuple[float, float]]] = {"first dtcosim run, empty caches": [], "dtcosim run": []}
        other = f"first run of {baseline}, empty caches"
        if baseline:
            times[other] = []

        def fresh_sources(i: int, of_baseline: bool) -> Path | None:
            """The sources of one first run: a new copy without bytecode (None: this tree as it is)."""
            if keep_bytecode:
                return tree if of_baseline else None
            folder = Path(tmp) / f"sources-{'baseline-' if of_baseline else ''}{i}"
            return shutil.copytree(tree, folder) if of_baseline else working_tree_copy(folder)

        for i in range(repeat):
            for name, tag, of_baseline in [("first dtcosim run, empty caches", str(i), False)] + (
                    [(other, f"baseline-{i}", True)] if baseline else []):
                sources = fresh_sources(i, of_baseline)
                measured, fresh = first(tag, sources)
                _stop_background_compile(fresh)
                shutil.rmtree(fresh, ignore_errors=True)
                if sources not in (None, tree):
                    shutil.rmtree(sources, ignore_errors=True)
                times[name].append(measured)
            times["dtcosim run"].append(timed(warm_argv, warm_env, Path(tmp)))
        medians = report(times)
        ratio = medians["first dtcosim run, empty caches"][0] / medians["dtcosim run"][0]
        print(f"ratio: first run wall / warm run wall  {ratio:.2f}   (target <= 3)")
        if baseline:
            pairs = list(zip(times["first dtcosim run, empty caches"], times[other]))
            print(f"first run, this tree / {baseline}: CPU {statistics.median(a[1] / b[1] for a, b in pairs):.2f}, "
                  f"wall {statistics.median(a[0] / b[0] for a, b in pairs):.2f} (medians of the turns' ratios)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="measured runs of each command (default 5)")
    parser.add_argument("--no-plots", action="store_true", help="also time `dtcosim run --no-plots`")
    parser.add_argument("--first-run", action="store_true", help="time the first run with empty caches instead")
    parser.add_argument("--baseline", metavar="REV", help="with --first-run: also first runs of git revision REV")
    parser.add_argument("--keep-bytecode", action="store_true",
                        help="with --first-run: first runs of this tree as it is (its modules' bytecode already "
                             "compiled), not of a copy without it")
    args = parser.parse_args()
    if args.first_run:
        print(f"the first `dtcosim run` with empty caches against warm runs (median of {args.repeat})")
        first_run(args.repeat, args.baseline, args.keep_bytecode)
        return
    print(f"whole commands in fresh processes, median of {args.repeat} (taking turns, after one warm-up each)")
    medians = report(warm(args.repeat, args.no_plots, environment()))
    run_cpu = medians["dtcosim run"][1]
    ref_cpu = medians["dtcosim reference --case table7 --json"][1]
    print(f"ratio: dtcosim run CPU / dtcosim reference --case table7 --json CPU  {run_cpu / ref_cpu:.2f}   "
          "(target <= 1)")
    if "dtcosim run --no-plots" in medians:
        print(f"       the four figures and their renderer: {run_cpu - medians['dtcosim run --no-plots'][1]:.2f} s CPU "
              "(run - run --no-plots)")


if __name__ == "__main__":
    main()
