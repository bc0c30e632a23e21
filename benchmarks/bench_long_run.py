"""What a long run costs: the paper scenario over 600 s (the IEC load-case length), H as the scenario's default.

Two parts:

1. **Whole runs** (default): ``run_scenario`` (what ``dtcosim run`` does: stream the samples
   into the results file, analyses, plots, summary) in a fresh process per results format
   (``csv``, ``parquet``) and per Gearbox kernel (``compiled``: compiled ahead of time where
   built, :mod:`components.compile.aot`; ``jit``: numba just in time, ``DTCOSIM_AOT=0``;
   ``numpy``), printing wall and CPU time of the run, the peak resident memory of the
   process (``ru_maxrss``: everything, imports and the FMUs included), for Parquet the peak of
   the child process that converts the stream (:mod:`orchestrator.parquet_conversion`) and that
   peak plus the run's resident memory while the child ran, and the size of the results file,
   against the targets of issue 14: <= 10 s wall including writing results
   and plots, <= 150 MB peak memory, results file <= 60 MB.
2. **Imports** (``--imports``): the peak resident memory of a fresh process that imports
   one package (or loads the compiled gearbox kernel from its disk cache), the footprint
   each brings into a run's process.
3. **Phases** (``--phases``): the phases of a run one by one in this process, per phase wall
   and CPU time, the peak resident memory during the phase (Linux: ``VmHWM``, reset before
   each phase through ``/proc/self/clear_refs``) and the resident memory after it; the
   results written in chunks of 250 rows as a run streams them, in both formats.

Run: ``python benchmarks/bench_long_run.py [--stop 600] [--step H] [--formats csv,parquet]
[--kernels compiled,jit,numpy] [--phases] [--imports]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_STATUS = Path("/proc/self/status")


def _read_kb(path: Path) -> int:
    """The number in ``path`` (written by the converter child); its folder is removed."""
    try:
        return int(path.read_text())
    finally:
        shutil.rmtree(path.parent, ignore_errors=True)


def _cpu_s() -> float:
    """CPU time of this process and of its finished children (the Parquet conversion) [s]."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


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
        wall, cpu = time.perf_counter(), _cpu_s()
        result = fn(*args, **kwargs)
        self.rows.append((name, time.perf_counter() - wall, _cpu_s() - cpu, _memory_mb("VmHWM"),
                          _memory_mb("VmRSS")))
        return result

    def print(self) -> None:
        print("| phase | wall [s] | CPU (with children) [s] | peak RSS during [MB] | RSS after [MB] |")
        print("|---|---|---|---|---|")
        for name, wall, cpu, peak, rss in self.rows:
            print(f"| {name} | {wall:.2f} | {cpu:.2f} | {peak:.0f} | {rss:.0f} |")
        total = sum(r[1] for r in self.rows)
        print(f"| total | {total:.2f} | {sum(r[2] for r in self.rows):.2f} | {max(r[3] for r in self.rows):.0f} | |")


def _long_scenario(args):
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario

    scenario = load_scenario(find_scenario("paper-60s")).with_simulation(stop_s=args.stop, window_s=(5.0, args.stop))
    if args.step is not None:
        scenario = scenario.with_simulation(step_s=args.step, output_interval_s=args.step)
    return scenario


def child_main(args) -> None:
    """One whole run in this (fresh) process; prints one JSON line."""
    wall0 = time.perf_counter()
    from components.model.kernel import choose_kernel
    from current_fmus import current_fmu_paths
    from orchestrator.cosim.system import resolve_system
    from orchestrator.run.runner import run_scenario

    import orchestrator.parquet_conversion as conversion

    # the Parquet conversion's child: this process's RSS when it starts, and the child's own peak (its VmHWM,
    # written by the same child program; ru_maxrss of a child counts the parent's memory it was forked from)
    converting_from_mb = []
    hwm_file = Path(tempfile.mkdtemp(prefix="dtcosim-bench-")) / "converter-vmhwm-kb"
    assert "sys.exit(main(sys.argv[2:]))" in conversion.CHILD_CODE, "the child program changed: adapt the bench"
    conversion.CHILD_CODE = conversion.CHILD_CODE.replace(
        "sys.exit(main(sys.argv[2:]))",
        f"rc = main(sys.argv[2:]); import re; open({str(hwm_file)!r}, 'w').write("
        "re.search(r'VmHWM:\\s+(\\d+)', open('/proc/self/status').read()).group(1)); sys.exit(rc)")
    in_child = conversion._convert_in_child

    def measured_conversion(*a):
        converting_from_mb.append(_memory_mb("VmRSS"))
        return in_child(*a)

    conversion._convert_in_child = measured_conversion
    scenario = _long_scenario(args)
    system = resolve_system(scenario, fmu_paths=current_fmu_paths(scenario))
    prepared_s = time.perf_counter() - wall0
    with tempfile.TemporaryDirectory(prefix="dtcosim-long-") as tmp:
        wall, cpu = time.perf_counter(), _cpu_s()
        report = run_scenario(system, Path(tmp), handle_sigint=False, results_format=args.child)
        wall, cpu = time.perf_counter() - wall, _cpu_s() - cpu
        assert report.outcome.complete and not report.problems, (report.outcome.error, report.problems)
        results = report.files["timeseries"]
        print(json.dumps({
            "format": args.child, "kernel": os.environ.get("BENCH_KERNEL_LABEL", choose_kernel()[0]),
            "numba_imported": "numba" in sys.modules, "wall_s": wall, "cpu_s": cpu,
            "start_up_s": prepared_s, "cosimulation_s": report.outcome.wall_time_s,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
            "pyarrow_imported": "pyarrow" in sys.modules,
            "converter_peak_mb": _read_kb(hwm_file) / 1024.0 if hwm_file.exists() else None,
            "converting_from_mb": converting_from_mb[0] if converting_from_mb else None,
            "results_file": results.name, "results_mb": results.stat().st_size / 1e6,
            "samples": report.summary["samples"], "steps": report.outcome.steps,
            "plots": sum(1 for k in report.files if k.startswith("plot:")),
        }))


def whole_runs_main(args) -> None:
    """Whole runs, one fresh process per kernel and format; a table against the targets."""
    print(f"paper-60s over 0-{args.stop:g} s, H = {'the scenario default' if args.step is None else args.step}; "
          f"each run in a fresh process (peak RSS = the whole process)\n")
    print("| kernel | results | wall [s] | CPU with children [s] | of which co-simulation wall [s] | peak RSS [MB] | "
          "Parquet converter: peak RSS, + the run's RSS then [MB] | results file [MB] | numba, pyarrow in the process |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows = []
    for kernel in args.kernels.split(","):
        for fmt in args.formats.split(","):
            cmd = [sys.executable, __file__, "--child", fmt, "--stop", str(args.stop)]
            if args.step is not None:
                cmd += ["--step", str(args.step)]
            env = {**os.environ, **KERNEL_ENVIRONMENTS[kernel], "BENCH_KERNEL_LABEL": kernel}
            proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
            if proc.returncode != 0:
                print(f"| {kernel} | {fmt} | failed: {proc.stderr.strip().splitlines()[-1:]} |", flush=True)
                continue
            r = json.loads(proc.stdout.strip().splitlines()[-1])
            rows.append(r)
            print(f"| {r['kernel']} | {r['results_file']} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
                  f"{r['cosimulation_s']:.2f} | {r['peak_rss_mb']:.0f} | {_converter(r)} | {r['results_mb']:.1f} | "
                  f"{'yes' if r['numba_imported'] else 'no'}, {'yes' if r['pyarrow_imported'] else 'no'} |",
                  flush=True)
    if rows:
        r = rows[0]
        print(f"\n{r['samples']} samples, {r['steps']} steps, {r['plots']} plots per run; targets: wall <= 10 s, "
              "peak RSS <= 150 MB, results file <= 60 MB")
        csv = {x["kernel"]: x for x in rows if x["format"] == "csv"}
        for x in rows:
            base = csv.get(x["kernel"])
            if x["format"] != "csv" and base:
                print(f"{x['kernel']}: {x['format']} / csv: wall {x['wall_s'] / base['wall_s']:.2f}, "
                      f"CPU {x['cpu_s'] / base['cpu_s']:.2f}, peak RSS {x['peak_rss_mb'] / base['peak_rss_mb']:.2f}, "
                      f"file {x['results_mb'] / base['results_mb']:.2f}")


def _converter(r: dict) -> str:
    """The Parquet conversion's child process: its peak and the sum with the run's RSS while it ran."""
    if r["converter_peak_mb"] is None:
        return "in the run's process" if r["format"] == "parquet" else "-"
    return f"{r['converter_peak_mb']:.0f}, together {r['converter_peak_mb'] + r['converting_from_mb']:.0f}"


#: environment of a whole run per --kernels entry
KERNEL_ENVIRONMENTS = {
    "compiled": {"DTCOSIM_KERNEL": "compiled"},  # ahead of time where built (components.compile.aot), else JIT
    "jit": {"DTCOSIM_KERNEL": "compiled", "DTCOSIM_AOT": "0"},
    "numpy": {"DTCOSIM_KERNEL": "numpy"},
}

#: what --imports loads, each in a fresh process: label -> Python statements
IMPORTS = {
    "python": "pass",
    "numpy": "import numpy",
    "scipy.linalg": "import scipy.linalg",
    "fmpy": "import fmpy.fmi2",
    "pydantic": "import pydantic",
    "orchestrator.run.runner (the host side of a run)": "import orchestrator.run.runner",
    "llvmlite.binding": "import llvmlite.binding",
    "numba": "import numba",
    "numba + the compiled gearbox kernel from its disk cache": (
        "from components.model.kernel import jit_gearbox; jit_gearbox()"),
    "numba + kernel, numba's own cache load (context refresh)": (
        "from numba.core.registry import cpu_target; cpu_target.target_context.refresh(); "
        "from components.model.kernel import jit_gearbox; jit_gearbox()"),
    "the compiled gearbox kernel ahead of time (no numba)": (
        "from components.model.kernel import gearbox; m = gearbox('compiled')[0]; "
        "assert getattr(m, 'AHEAD_OF_TIME', None), 'not built: dtcosim build'"),
    "pyarrow": "import pyarrow",
    "pyarrow.parquet": "import pyarrow.parquet",
    "matplotlib (Figure, Agg canvas)": (
        "import matplotlib.figure, matplotlib.backends.backend_agg"),
    "matplotlib.pyplot": "import matplotlib.pyplot",
    "pandas": "import pandas",
}


def imports_main() -> None:
    """Peak RSS of a fresh process per import: what each package costs a run's process."""
    code = "import resource\n{}\nprint(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)"
    print("| import (fresh process) | peak RSS [MB] | over bare python [MB] |")
    print("|---|---|---|")
    bare_mb = None
    for label, statement in IMPORTS.items():
        proc = subprocess.run([sys.executable, "-c", code.format(statement)], capture_output=True, text=True)
        if proc.returncode != 0:
            print(f"| {label} | failed: {proc.stderr.strip().splitlines()[-1:]} | |")
            continue
        mb = float(proc.stdout.strip().splitlines()[-1])
        bare_mb = mb if bare_mb is None else bare_mb
        over = f"{mb - bare_mb:.0f}" if label != "python" else ""
        print(f"| {label} | {mb:.0f} | {over} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=600.0, help="stop time [s] (default 600)")
    parser.add_argument("--step", type=float, default=None, help="communication step [s] (default: the scenario's)")
    parser.add_argument("--out", type=Path, default=None, help="result directory of --phases (default: temporary)")
    parser.add_argument("--formats", default="csv,parquet", help="results formats of the whole runs")
    parser.add_argument("--kernels", default="compiled,jit,numpy",
                        help="Gearbox kernels of the whole runs: compiled (ahead of time), jit, numpy")
    parser.add_argument("--phases", action="store_true", help="time the phases of one run in this process instead")
    parser.add_argument("--imports", action="store_true", help="peak RSS of a fresh process per import instead")
    parser.add_argument("--child", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child_main(args)
    elif args.imports:
        imports_main()
    elif args.phases:
        phases_main(args)
    else:
        whole_runs_main(args)


def phases_main(args) -> None:
    start_rss = _memory_mb("VmRSS")
    phases = Phases()

    def imports():
        from orchestrator.provision.project_fmus import ensure_fmus  # noqa: F401
        from orchestrator.run import runner  # noqa: F401

    phases.run("imports", imports)
    import numpy as np

    from components.model.kernel import choose_kernel
    from current_fmus import current_fmu_paths
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.run.analyses import analyse_run
    from orchestrator.run.derived import generator_vs_ideal
    from orchestrator.run.memory import release_between_phases
    from orchestrator.run.plots import plot_run
    from orchestrator.cosim.master import BLOCK_STEPS
    from orchestrator.run.results import (
        SUMMARY_FILE,
        TIMESERIES_FILE,
        TIMESERIES_PARQUET,
        build_summary,
        write_timeseries,
    )
    from orchestrator.result_files import write_summary

    def resolve():
        scenario = _long_scenario(args)
        return resolve_system(scenario, fmu_paths=current_fmu_paths(scenario))

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
        chunk = BLOCK_STEPS // sim.output_stride or 1
        csv = phases.run(f"timeseries.csv (chunks of {chunk} rows)", write_timeseries, out / TIMESERIES_FILE,
                         outcome, chunk)
        parquet = phases.run(f"timeseries.parquet (chunks of {chunk} rows)", write_timeseries,
                             out / TIMESERIES_PARQUET, outcome, chunk)
        npy = phases.run("(comparison: np.save of the same samples)", np.save, out / "timeseries.npy", outcome.values)
        fig16 = phases.run("generator vs ideal", generator_vs_ideal, system, outcome)
        analyses = phases.run("analyses + their plots", analyse_run, system, outcome, out, plots=True)
        release_between_phases(outcome.values.nbytes)  # as run_scenario does before the run plots
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
        print(f"files: timeseries.csv {sizes[csv.name] / 1e6:.1f} MB, timeseries.parquet "
              f"{sizes[parquet.name] / 1e6:.1f} MB, np.save of the same samples "
              f"{sizes[Path(str(npy)).name if npy else 'timeseries.npy'] / 1e6:.1f} MB, plots "
              f"{sum(v for k, v in sizes.items() if k.endswith('.png')) / 1e6:.1f} MB "
              f"({len(plots) + sum(1 for k in analyses.files if 'plot' in k)} PNG), everything "
              f"{sum(sizes.values()) / 1e6:.1f} MB; samples in memory {outcome.values.nbytes / 1e6:.1f} MB")
        wall = sum(r[1] for r in phases.rows if not r[0].startswith("(")) - phases.rows[0][1]
        peak = max(r[3] for r in phases.rows)
        print(f"targets: wall without imports {wall:.1f} s (<= 10 s), peak RSS {peak:.0f} MB (<= 150 MB), "
              f"results file {sizes[csv.name] / 1e6:.1f} MB as CSV, {sizes[parquet.name] / 1e6:.1f} MB as Parquet "
              "(<= 60 MB); both formats written here, a run writes one")


if __name__ == "__main__":
    main()
