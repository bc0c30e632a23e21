#!/usr/bin/env python3
"""The interpreted gearbox kernel on the paper's scenario: CPU per communication step, against the compiled kernel
and against a base revision's interpreted kernel, in one process.

What the first ``dtcosim run`` of a machine steps while its kernels compile ahead of time in the
background (issue 34.3), and what runs where neither numba nor a compiled module is there:

1. ``paper-60s`` co-simulated by dtcosim's master, the three FMUs in this process, the Gearbox FMU's
   kernel interpreted (``DTCOSIM_KERNEL=numpy``, read when the FMUs configure their models: the
   WindSource's phasor step runs interpreted too, as on a first run) and compiled (the default):
   process CPU time of the stepping loop (every FMU and the master; instantiation and initialisation
   excluded) per communication step;
2. the baseline (``--baseline REV``, default :data:`BASE_REVISION`, the commit before the interpreted
   kernel was made faster): REV's Gearbox FMU, built from ``git archive REV`` in a temporary folder by a
   child process (its own package name keeps its code apart from today's in this process), run
   interpreted and compiled in the same scenario (the compiled forms must be as fast); ``--baseline
   none`` skips it.

The runs take turns (interpreted, compiled, the baseline's two) ``--repeat`` times, so a change of
the shared machine's load hits them alike; medians are printed, and each ratio also as the median
of the ratios of the runs that took turns. Each run's recorded variables are compared with the
interpreted run's: the baseline's interpreted run agrees to the bit (the same numbers), the compiled
runs to about 1e-8 (the gearbox kernel's forms agree to the bit, the WindSource's phasor step does
not: its numpy form multiplies the phasors with numpy's complex product, which differs from the
compiled loop's in the last bit, and the run amplifies that).

3. ``--compile N``: what the interpreted form's speed must not cost the compiled one, the CPU time of
   the gearbox kernel's ahead-of-time build (:func:`components.compile.aot.build_module`:
   ``numba.pycc``) of today's sources and of the baseline's, each in a fresh child process with empty
   caches (no numba cache to load from), ``N`` times each taking turns; medians.

Run: ``python benchmarks/bench_interpreted.py [--repeat 5] [--stop 60] [--baseline REV|none] [--fmu-dir DIR]
[--compile N]``.
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from baseline_tree import archive_tree

#: the commit before the interpreted kernel was made faster (issue 34.3: its per-step cost)
BASE_REVISION = "b1dfac4"
REPO = Path(__file__).resolve().parents[1]


@contextmanager
def kernel_form(kernel: str | None):
    """``$DTCOSIM_KERNEL`` set to ``kernel`` (None: unset) while FMUs are instantiated."""
    from components.model.kernel import ENVIRONMENT_VARIABLE

    previous = os.environ.pop(ENVIRONMENT_VARIABLE, None)
    if kernel is not None:
        os.environ[ENVIRONMENT_VARIABLE] = kernel
    try:
        yield
    finally:
        os.environ.pop(ENVIRONMENT_VARIABLE, None)
        if previous is not None:
            os.environ[ENVIRONMENT_VARIABLE] = previous


def child(tree: Path, code: str, *args: str, env: dict[str, str] | None = None) -> str:
    """Run ``code`` in a child Python that imports dtcosim from ``tree``; its standard output."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | (env or {})
    return subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); " + code, str(tree),
                           *args], check=True, capture_output=True, text=True, cwd=tree, env=env).stdout


def baseline_gearbox(tree: Path, out_dir: Path) -> Path:
    """The Gearbox FMU (preset table6) of the sources in ``tree``, built by a child process."""
    out = child(tree, "from fmus.build import build_fmu; print(build_fmu('Gearbox', sys.argv[2], 'table6').path)",
                str(out_dir / "baseline"))
    return Path(out.strip().splitlines()[-1])


def compile_cpu(tree: Path, out_dir: Path) -> float:
    """CPU time [s] of the gearbox kernel's ahead-of-time build from the sources in ``tree``, in a child process with
    empty caches."""
    with tempfile.TemporaryDirectory(dir=out_dir) as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        child(tree, "from pathlib import Path; from components.compile.aot import AotKernel, build_module; "
              "from components.model.kernel import GEARBOX; build_module(AotKernel.of(GEARBOX), Path(sys.argv[2]))",
              tmp, env={"DTCOSIM_CACHE_DIR": str(Path(tmp) / "cache"), "NUMBA_CACHE_DIR": str(Path(tmp) / "numba")})
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs of each, taking turns (default 5)")
    parser.add_argument("--stop", type=float, default=60.0, help="stop time [s] (default 60: the paper's scenario)")
    parser.add_argument("--baseline", default=BASE_REVISION, metavar="REV",
                        help=f"git revision whose Gearbox FMU runs too (default {BASE_REVISION}; none: skip it)")
    parser.add_argument("--fmu-dir", type=Path, default=None,
                        help="FMU folder of today's FMUs (default: a temporary one, built now)")
    parser.add_argument("--compile", type=int, default=0, metavar="N",
                        help="also time the gearbox kernel's ahead-of-time build, N times each (default 0: not)")
    args = parser.parse_args()

    from current_fmus import current_fmu_paths
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario

    scenario = load_scenario(find_scenario("paper-60s"))
    if args.stop != scenario.simulation.stop_s:
        scenario = scenario.with_simulation(stop_s=args.stop, window_s=(min(5.0, args.stop / 2), args.stop))
    steps = scenario.simulation.n_steps
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-interpreted-") as tmp:
        tmp = Path(tmp)
        paths = current_fmu_paths(scenario, args.fmu_dir or tmp / "fmus")
        runners = {"interpreted": (resolve_system(scenario, paths), "numpy"),
                   "compiled": (resolve_system(scenario, paths), None)}
        tree = archive_tree(args.baseline, tmp) if args.baseline.lower() != "none" else None
        if tree is not None:
            base = resolve_system(scenario, {**paths, "gearbox": baseline_gearbox(tree, tmp)})
            runners["baseline"] = (base, "numpy")
            runners["baseline compiled"] = (base, None)
        times: dict[str, list[float]] = {name: [] for name in runners}
        recorded: dict[str, np.ndarray] = {}
        for _ in range(args.repeat + 1):  # the first round warms up (extraction, imports), not counted
            for name, (system, kernel) in runners.items():
                with kernel_form(kernel):
                    outcome = CoSimulation(system).run(handle_sigint=False)
                if not outcome.complete:
                    raise SystemExit(f"{name}: {outcome.error}")
                recorded[name] = np.asarray(outcome.values, dtype=float)
                times[name].append(outcome.loop_cpu_time_s)
        builds: dict[str, list[float]] = {}
        for _ in range(args.compile):
            for name, source in (("today", REPO), ("baseline", tree)):
                if source is not None:
                    builds.setdefault(name, []).append(compile_cpu(source, tmp))
    times = {name: values[1:] for name, values in times.items()}
    scale = np.abs(recorded["interpreted"]).max(axis=0) + 1e-300
    differences = {name: float(np.max(np.abs(values - recorded["interpreted"]) / scale))
                   for name, values in recorded.items() if name != "interpreted"}
    med = {name: statistics.median(v) for name, v in times.items()}

    def per_step(name: str) -> str:
        return (f"{med[name]:6.3f} s CPU, {med[name] / steps * 1e6:6.1f} us per communication step "
                f"(runs {', '.join(f'{v:.3f}' for v in times[name])})")

    def ratio(a: str, b: str) -> str:
        pairs = statistics.median(x / y for x, y in zip(times[a], times[b]))
        return f"{med[a] / med[b]:6.2f}  (median of the runs' ratios {pairs:.2f})"

    print(f"paper-60s, 0-{scenario.simulation.stop_s:g} s, H = {scenario.simulation.step_s * 1e3:g} ms ({steps} "
          f"communication steps); stepping loop of the three FMUs and the master, median of {args.repeat} runs "
          "taking turns")
    print(f"  Gearbox interpreted (DTCOSIM_KERNEL=numpy)   {per_step('interpreted')}")
    print(f"  Gearbox compiled                             {per_step('compiled')}")
    if "baseline" in times:
        print(f"  Gearbox of {args.baseline}, interpreted          {per_step('baseline')}")
        print(f"  Gearbox of {args.baseline}, compiled             {per_step('baseline compiled')}")
    print("  recorded variables against the interpreted run's (largest difference relative to each variable's "
          "largest value): " + ", ".join(f"{name} {d:.1e}" for name, d in differences.items()))
    if "baseline compiled" in recorded:
        same = np.array_equal(recorded["compiled"], recorded["baseline compiled"])
        print(f"  the compiled runs of today and of {args.baseline}: {'the same values to the bit' if same else 'differ'}")
    print("ratios (same process)")
    print(f"  interpreted / compiled                  {ratio('interpreted', 'compiled')}")
    if "baseline" in times:
        print(f"  baseline {args.baseline} / interpreted       {ratio('baseline', 'interpreted')}   (the speed-up; "
              "target >= 2, aim 3)")
        print(f"  compiled / baseline {args.baseline} compiled {ratio('compiled', 'baseline compiled')}   (must not "
              "exceed 1 beyond the machine's noise)")
    if builds:
        print(f"the gearbox kernel's ahead-of-time build (numba.pycc), CPU, median of {args.compile} taking turns")
        for name, values in builds.items():
            label = "today's sources" if name == "today" else f"the sources of {args.baseline}"
            listed = ", ".join(f"{v:.1f}" for v in values)
            print(f"  {label:<28} {statistics.median(values):6.1f} s   (builds {listed})")
        if "baseline" in builds:
            pairs = statistics.median(a / b for a, b in zip(builds["today"], builds["baseline"]))
            whole = statistics.median(builds["today"]) / statistics.median(builds["baseline"])
            print(f"  today / baseline             {whole:6.2f}   (median of the pairs' ratios {pairs:.2f}; must not "
                  "exceed 1 beyond the machine's noise)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
