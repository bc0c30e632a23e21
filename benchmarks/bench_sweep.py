"""Benchmark: where a study's points run, and what 1 and 2 workers cost, on the packaged studies and a small load set.

Three parts, each a whole ``dtcosim sweep`` / ``dtcosim loads`` command in a fresh process into a
fresh output folder (nothing skipped), wall times, medians of ``--repeat`` runs taking turns:

1. **Overhead** (``--overhead``): a study of 4 points of 1 s through the FMUs (``shaft3-seeds``
   shortened) with ``--executor dask --workers 2`` against ``--executor process``: the difference is
   what a LocalCluster of 2 workers costs before its first point (start-up, TLS, the workers'
   imports, the FMUs loaded in each). Twice that is the least work 2 workers finish sooner than one
   process: ``orchestrator.study.sweep.MIN_CLUSTER_WORK_S``, printed beside it.
2. **Packaged studies** (default): ``paper-sensitivity`` (49 monolithic points) and ``shaft3-seeds``
   (18 co-simulations) and the load set ``paper-turbine --length 60 --seeds 1`` with the default
   settings (``--executor auto``) on ``--workers 1`` and ``--workers 2``: target (issue 34), 2 workers
   never slower than 1 (ratio 1-worker wall / 2-worker wall >= 1, within the noise of a shared
   machine); and the same on Dask alone (``--executor dask``), what the cluster gives above the size.

Before and after, it measures how many cores are free (:func:`free_cores`: 2.0 = two idle cores); a
speed-up can only be as large as that.

Run: ``python benchmarks/bench_sweep.py [--repeat N] [--overhead]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the overhead study: shaft3-seeds' base and measures, 4 points of 1 s
OVERHEAD_STUDY = """
name = "overhead"
engine = "cosim"
seeds = [1, 2]
measures = ["gearbox.shaft3.torque:std", "cpu_time"]

[base]
scenario = "paper-60s"

[simulation]
stop = 1.0
window = [0.5, 1.0]

[[axes]]
parameter = "gearbox.shaft3.stiffness"
values = [2864.8, 5729.6]
"""

#: (label, command words) of the packaged studies and the load set
PACKAGED = (
    ("paper-sensitivity", ["sweep", "paper-sensitivity", "--no-plots"]),
    ("shaft3-seeds", ["sweep", "shaft3-seeds", "--no-plots"]),
    ("loads paper-turbine --length 60 --seeds 1", ["loads", "paper-turbine", "--length", "60", "--seeds", "1",
                                                   "--no-plots"]),
)


def _spin(n: int = 15_000_000) -> None:
    x = 0
    for i in range(n):
        x += i


def free_cores() -> float:
    """Parallel capacity now: 2 x (time of one spin loop) / (time of two running at once)."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")

    def timed(k: int) -> float:
        procs = [ctx.Process(target=_spin) for _ in range(k)]
        t0 = time.perf_counter()
        for p in procs:
            p.start()
        for p in procs:
            p.join()
        return time.perf_counter() - t0

    one = timed(1)
    two = timed(2)
    return 2.0 * one / two


def command_wall(words: list[str], out: Path) -> float:
    """Wall time of one ``dtcosim`` command into the fresh folder ``out`` (it must succeed)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "orchestrator.commands.cli", *words, "--out", str(out), "-q"],
                          capture_output=True, text=True, env=env, cwd=out.parent)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"dtcosim {' '.join(words)} failed ({proc.returncode}):\n{proc.stderr}")
    return wall


def compare(cases: dict[str, list[str]], repeat: int, root: Path) -> dict[str, float]:
    """Median wall of each case, the cases taking turns, each run into a new folder."""
    walls: dict[str, list[float]] = {name: [] for name in cases}
    for _ in range(repeat):
        for name, words in cases.items():
            walls[name].append(command_wall(words, Path(tempfile.mkdtemp(dir=root)) / "out"))
    return {name: statistics.median(w) for name, w in walls.items()}


def overhead(repeat: int, root: Path) -> None:
    from orchestrator.study.sweep import MIN_CLUSTER_WORK_S

    study = root / "overhead.toml"
    study.write_text(OVERHEAD_STUDY)
    words = ["sweep", str(study), "--no-plots"]
    med = compare({"process": words + ["--executor", "process"],
                   "dask, 2 workers": words + ["--executor", "dask", "--workers", "2"]}, repeat, root)
    cost = med["dask, 2 workers"] - med["process"]
    print(f"overhead: a study of 4 co-simulations of 1 s, median of {repeat}")
    for name, wall in med.items():
        print(f"  --executor {name:18s} {wall:6.2f} s wall")
    print(f"  the LocalCluster's cost before its first point: {cost:.2f} s; twice that {2 * cost:.1f} s "
          f"(MIN_CLUSTER_WORK_S = {MIN_CLUSTER_WORK_S:g} s)")


def packaged(repeat: int, root: Path) -> None:
    print(f"packaged studies and a load set, whole commands, median of {repeat} (wall time)")
    print(f"  {'':42s} {'1 worker':>9} {'2 workers':>10} {'1 / 2':>6}")
    for executor in ("auto", "dask"):
        for label, words in PACKAGED:
            med = compare({w: words + ["--executor", executor, "--workers", str(w)] for w in ("1", "2")}, repeat, root)
            print(f"  {label + ' (' + executor + ')':42s} {med['1']:8.2f}s {med['2']:9.2f}s "
                  f"{med['1'] / med['2']:6.2f}")
    print("  target: 1 / 2 >= 1 with --executor auto (2 workers never slower than 1)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each case (taking turns); medians reported")
    parser.add_argument("--overhead", action="store_true", help="measure the LocalCluster's fixed cost instead")
    args = parser.parse_args()
    capacity = [free_cores()]
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-sweep-") as tmp:
        (overhead if args.overhead else packaged)(args.repeat, Path(tmp))
    capacity.append(free_cores())
    print(f"free cores measured before / after: {capacity[0]:.2f} / {capacity[1]:.2f} (2.00 = both cores idle)")


if __name__ == "__main__":
    main()
