"""Where the time and memory of a long run go: the paper scenario over 600 s (the IEC load-case length).

Runs the phases of ``dtcosim run`` (:func:`orchestrator.run.runner.run_scenario`) one by one in
this process and prints, per phase, wall and CPU time, the peak resident memory during the
phase (Linux: ``VmHWM``, reset before each phase through ``/proc/self/clear_refs``) and the
resident memory after it; then the sizes of the files written, and, for comparison, what
writing the same samples with ``np.save`` costs (the binary results file is issue 13's
streaming writer, not measured here).

Targets (issue 14): <= 10 s wall including results and plots, <= 150 MB peak memory,
results file <= 60 MB.

Run: ``python benchmarks/bench_long_run.py [--stop 600] [--step H] [--out DIR]``.
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
from pathlib import Path

_STATUS = Path("/proc/self/status")


def _memory_mb(key: str) -> float:
    """``VmRSS`` or ``VmHWM`` of this process [MB] (nan where /proc is missing)."""
    try:
        match = re.search(rf"^{key}:\s+(\d+) kB", _STATUS.read_text(), re.M)
    except OSError:
        return float("nan")
    return int(match.group(1)) / 1024.0 if match else float("nan")


def _reset_peak() -> None:
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass


class Phases:
    """Times and memory of consecutive phases."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, float, float, float, float]] = []
        self._wall0 = time.perf_counter()

    def run(self, name: str, fn, *args, **kwargs):
        _reset_peak()
        wall, cpu = time.perf_counter(), time.process_time()
        result = fn(*args, **kwargs)
        self.rows.append((name, time.perf_counter() - wall, time.process_time() - cpu, _memory_mb("VmHWM"),
                          _memory_mb("VmRSS")))
        return result

    def print(self) -> None:
        print("| phase | wall [s] | CPU [s] | peak RSS during [MB] | RSS after [MB] |")
        print("|---|---|---|---|---|")
        for name, wall, cpu, peak, rss in self.rows:
            print(f"| {name} | {wall:.2f} | {cpu:.2f} | {peak:.0f} | {rss:.0f} |")
        total = sum(r[1] for r in self.rows)
        print(f"| total | {total:.2f} | {sum(r[2] for r in self.rows):.2f} | {max(r[3] for r in self.rows):.0f} | |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=600.0, help="stop time [s] (default 600)")
    parser.add_argument("--step", type=float, default=None, help="communication step [s] (default: the scenario's)")
    parser.add_argument("--out", type=Path, default=None, help="result directory (default: a temporary one)")
    args = parser.parse_args()
    start_rss = _memory_mb("VmRSS")
    phases = Phases()

    def imports():
        from orchestrator.cosim.fmu_store import ensure_fmus  # noqa: F401
        from orchestrator.run import runner  # noqa: F401

    phases.run("imports", imports)
    import numpy as np

    from components.model.kernel import choose_kernel
    from orchestrator.cosim.fmu_store import ensure_fmus
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario import find_scenario, load_scenario
    from orchestrator.run.analyses import analyse_run
    from orchestrator.run.derived import generator_vs_ideal
    from orchestrator.run.plots import plot_run
    from orchestrator.run.results import SUMMARY_FILE, TIMESERIES_FILE, build_summary, write_timeseries
    from orchestrator.result_files import write_summary

    def resolve():
        scenario = load_scenario(find_scenario("paper-60s")).with_simulation(stop_s=args.stop,
                                                                           window_s=(5.0, args.stop))
        if args.step is not None:
            scenario = scenario.with_simulation(step_s=args.step, output_interval_s=args.step)
        return resolve_system(scenario, fmu_paths=ensure_fmus(scenario, None))

    system = phases.run("scenario + FMU paths", resolve)
    sim = system.scenario.simulation
    print(f"paper-60s over 0-{sim.stop_s:g} s, H = {sim.step_s * 1e3:g} ms ({sim.n_steps} steps), output every "
          f"{sim.output_interval_s * 1e3:g} ms, {len(system.recorded)} recorded variables; Gearbox kernel: "
          f"{choose_kernel()[0]}; RSS at start {start_rss:.0f} MB\n")
    with tempfile.TemporaryDirectory(prefix="dtcosim-long-") as tmp:
        out = args.out or Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        outcome = phases.run("co-simulation (instantiate, step, free)",
                             lambda: CoSimulation(system).run(handle_sigint=False))
        assert outcome.complete, outcome.error
        csv = phases.run("timeseries.csv", write_timeseries, out / TIMESERIES_FILE, outcome)
        npy = phases.run("(comparison: np.save of the same samples)", np.save, out / "timeseries.npy", outcome.values)
        fig16 = phases.run("generator vs ideal", generator_vs_ideal, system, outcome)
        analyses = phases.run("analyses + their plots", analyse_run, system, outcome, out, plots=True)
        plots = phases.run("run plots", plot_run, system, outcome, out)

        def summary():
            derived = {"generator_vs_ideal": fig16} if fig16 is not None else {}
            derived.update(analyses.summary)
            files = {"timeseries": TIMESERIES_FILE, "summary": SUMMARY_FILE}
            return write_summary(out / SUMMARY_FILE, build_summary(system, outcome, wall_time_s=0.0, derived=derived,
                                                                  comparison=None, files=files))

        phases.run("summary.json", summary)
        phases.print()
        sizes = {p.name: p.stat().st_size for p in out.iterdir() if p.is_file()}
        print()
        print(f"files: timeseries.csv {sizes[csv.name] / 1e6:.1f} MB, np.save of the same samples "
              f"{sizes[Path(str(npy)).name if npy else 'timeseries.npy'] / 1e6:.1f} MB, plots "
              f"{sum(v for k, v in sizes.items() if k.endswith('.png')) / 1e6:.1f} MB "
              f"({len(plots) + sum(1 for k in analyses.files if 'plot' in k)} PNG), everything "
              f"{sum(sizes.values()) / 1e6:.1f} MB; samples in memory {outcome.values.nbytes / 1e6:.1f} MB")
        wall = sum(r[1] for r in phases.rows if not r[0].startswith("(")) - phases.rows[0][1]
        peak = max(r[3] for r in phases.rows)
        print(f"targets: wall without imports {wall:.1f} s (<= 10 s), peak RSS {peak:.0f} MB (<= 150 MB), "
              f"results file {sizes[csv.name] / 1e6:.1f} MB as CSV (<= 60 MB)")


if __name__ == "__main__":
    main()
