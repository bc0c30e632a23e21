"""Benchmark: a reduced load-case set (4 bins x 2 seeds x 600 s) on 1 and on 2 Dask workers.

Runs the same set twice in this process, into fresh output directories (nothing
is skipped), the way ``dtcosim loads`` does (:func:`orchestrator.study.load_cases.prepare_load_cases`,
:func:`orchestrator.study.sweep.run_sweep` with the run-file hook, then the
lifetime outputs), on a LocalCluster of 1 worker and of 2 workers, and prints
for each: the wall time of the sweep (cluster start-up, runs, journal, cluster
shutdown) and of the lifetime post-processing, cases per minute, and the cost
of a case: the worker's CPU time of the co-simulation per simulated second
(median over the cases; ``cpu_time`` of the engine, ``time.process_time``) and
its wall time per simulated second. Then the 2-worker speed-up (target >= 1.8
with both cores free). Before and after, it measures how many cores are free
(:func:`bench_sweep.free_cores`: 2.0 = two idle cores); a speed-up can only be
as large as that.

Run: ``python benchmarks/bench_loads.py [--length 600] [--transient 10] [--step H] [--keep DIR]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_sweep import free_cores  # noqa: E402

from orchestrator.inputs.load_case_file import load_cases_from_dict  # noqa: E402
from orchestrator.study.lifetime_outputs import write_lifetime_outputs  # noqa: E402
from orchestrator.study.lifetime_results import store_run_data  # noqa: E402
from orchestrator.study.load_cases import prepare_load_cases  # noqa: E402
from orchestrator.study.sweep import run_sweep  # noqa: E402


def reduced_set(length_s: float, transient_s: float, step_s: float | None) -> dict:
    """The paper-turbine set with 4 bins (5-21 m/s, 4 m/s wide) and 2 seeds."""
    from orchestrator.inputs.files import read_toml
    from orchestrator.inputs.load_case_file import find_load_cases
    from orchestrator.inputs.load_cases import LoadCaseError

    doc = read_toml(find_load_cases("paper-turbine"), LoadCaseError)
    doc["name"] = "bench-loads"
    doc["bins"] = {"cut_in": 5.0, "cut_out": 21.0, "width": 4.0}
    doc["runs"] = {"length": length_s, "transient": transient_s, "seeds": 2}
    if step_s is not None:
        doc["simulation"] = {"step": step_s}
    return doc


def run_once(plc, workers: int, out: Path) -> dict:
    t0 = time.perf_counter()
    report = run_sweep(plc.prepared, out, workers=workers, executor="dask", plots=False,
                       on_result=store_run_data(plc, out))
    sweep_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    write_lifetime_outputs(plc, out)
    post_s = time.perf_counter() - t1
    records = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    ok = [r for r in records if r["status"] == "ok"]
    simulated = plc.load_cases.transient_s + plc.load_cases.length_s
    return {"workers": report.workers, "ok": len(ok), "sweep_s": sweep_s, "compute_s": report.compute_time_s,
            "post_s": post_s,
            "cpu_per_sim_s": statistics.median(r["measures"]["cpu_time"] for r in ok) / simulated,
            "wall_per_sim_s": statistics.median(r["measures"]["wall_time"] for r in ok) / simulated}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=600.0, help="analysed length per run [s]")
    parser.add_argument("--transient", type=float, default=10.0, help="discarded transient per run [s]")
    parser.add_argument("--step", type=float, default=None, help="communication step [s] (default: the scenario's)")
    parser.add_argument("--keep", type=Path, default=None, help="write the results here (default: a temporary folder)")
    args = parser.parse_args()
    lcs = load_cases_from_dict(reduced_set(args.length, args.transient, args.step), source="bench-loads")
    plc = prepare_load_cases(lcs)
    n = len(plc.cases)
    print(f"set: {len(plc.bins)} bins x {len(lcs.seeds)} seeds = {n} cases of {lcs.transient_s:g} + {lcs.length_s:g} s "
          f"(step {plc.prepared.payload.system.scenario.simulation.step_s:g} s)")
    print(f"free cores before: {free_cores():.2f}")
    results = {}
    with tempfile.TemporaryDirectory(prefix="bench-loads-") as tmp:
        root = args.keep or Path(tmp)
        for workers in (1, 2):
            r = run_once(plc, workers, root / f"w{workers}")
            results[workers] = r
            print(f"{workers} worker(s): sweep {r['sweep_s']:.1f} s (compute {r['compute_s']:.1f} s), "
                  f"{60.0 * n / r['sweep_s']:.2f} cases/min, post-processing {r['post_s']:.2f} s; per case: "
                  f"{r['cpu_per_sim_s'] * 1e3:.1f} ms CPU and {r['wall_per_sim_s'] * 1e3:.1f} ms wall per simulated "
                  f"second ({r['cpu_per_sim_s'] * (lcs.transient_s + lcs.length_s):.1f} s CPU per case)")
    print(f"free cores after: {free_cores():.2f}")
    print(f"2-worker speed-up (sweep wall time): {results[1]['sweep_s'] / results[2]['sweep_s']:.2f} "
          f"(compute only: {results[1]['compute_s'] / results[2]['compute_s']:.2f}); target >= 1.8 with both cores free")


if __name__ == "__main__":
    main()
