"""Benchmark: the 49-point paper-sensitivity study on 1 and on 2 Dask workers.

Runs the packaged study twice in this process, into fresh output directories
(nothing is skipped), on a LocalCluster of 1 worker and of 2 workers (processes,
one thread each), and prints both wall times and the speed-up. Two times per
run: ``sweep`` is the whole :func:`orchestrator.study.sweep.run_sweep` call (cluster
start-up, scatter, 49 points, journal, table and heat maps, cluster shutdown),
``compute`` the first submission to the last result. Target: at least 1.6 x on
the 2-core machine. With ``--repeat N`` the pair is run N times, alternating, and
the medians are reported (the machine is shared: expect +-10 %). Before and
after, it measures how many cores are actually free: a CPU-bound loop in one
process and in two processes at once (2.0 = two idle cores); a speed-up can only
be as large as that.

Run: ``python benchmarks/bench_sweep.py [--repeat N]``
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from orchestrator.inputs.study_file import find_study, load_study
from orchestrator.study.prepare import prepare_study
from orchestrator.study.sweep import run_sweep


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


def _run(prepared, workers: int, root: Path, tag: str) -> tuple[float, float]:
    out = root / f"{tag}-w{workers}"
    t0 = time.perf_counter()
    report = run_sweep(prepared, out, workers=workers)
    wall = time.perf_counter() - t0
    assert report.submitted == report.ok == len(prepared.points), report
    assert report.workers == workers
    return wall, report.compute_time_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="runs per worker count (alternating); medians reported")
    args = parser.parse_args()
    prepared = prepare_study(load_study(find_study("paper-sensitivity")))
    runs: dict[int, list[tuple[float, float]]] = {1: [], 2: []}
    capacity = [free_cores()]
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-sweep-") as tmp:
        root = Path(tmp)
        for k in range(args.repeat):
            for workers in (1, 2):
                runs[workers].append(_run(prepared, workers, root, f"r{k}"))
    capacity.append(free_cores())
    med = {w: (statistics.median(r[0] for r in rs), statistics.median(r[1] for r in rs)) for w, rs in runs.items()}
    n = len(prepared.points)
    print(f"paper-sensitivity, {n} points, monolithic engine, LocalCluster (processes, 1 thread each); "
          f"median of {args.repeat} run(s)")
    print(f"  {'workers':>7} {'sweep [s]':>10} {'compute [s]':>12}")
    for w in (1, 2):
        print(f"  {w:>7} {med[w][0]:>10.2f} {med[w][1]:>12.2f}")
    print(f"  free cores measured before / after: {capacity[0]:.2f} / {capacity[1]:.2f} (2.00 = both cores idle)")
    print(f"  speed-up 2 vs 1 worker: sweep {med[1][0] / med[2][0]:.2f} x, compute {med[1][1] / med[2][1]:.2f} x "
          f"(target >= 1.6 x)")


if __name__ == "__main__":
    main()
