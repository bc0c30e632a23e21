"""What the four figures of a default ``dtcosim run`` cost, against the co-simulation that made their data.

Each measurement is a fresh Python process, as a run is: it co-simulates the paper's 60 s scenario
(its CPU time is the baseline, measured in the same process), computes the load duration
distributions, then imports what the first figure imports (the run figures' renderer,
:mod:`orchestrator.raster`, and Pillow; timed apart: a start-up cost that ``bench_commands.py``
counts with the command) and draws and writes each figure a default run writes, in a run's order:
``load_duration.png`` (:mod:`orchestrator.run.analysis_plots`), ``rotor_speed.png``,
``generator_speed.png``, ``contact_forces.png`` (:mod:`orchestrator.run.plots`), each the first of
its kind in the process. ``--repeat`` processes; printed: the median CPU time of each figure, of
the PNG encoding inside it, of the four together and of the import, and the ratio of the four to
the co-simulation.

Target (issue 34): the four figures and their import at most about 0.3 s CPU.

Run: ``python benchmarks/bench_plots.py [--repeat N] [--keep DIR]``.
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FIGURES = ("load_duration", "rotor_speed", "generator_speed", "contact_forces")
#: what the first figure of a run imports (Pillow's modules are imported where they are used)
FIRST_IMPORTS = ("orchestrator.run.plots", "orchestrator.run.analysis_plots", "PIL.Image", "PIL.ImageDraw",
                 "PIL.ImageFont")


def child(out: Path) -> dict[str, float]:
    """One fresh process's measurement (see the module docstring)."""
    from components.analysis.fatigue import fatigue_report
    from current_fmus import current_fmu_paths
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.run.analyses import _recorded_signals as recorded_signals
    from orchestrator.run.derived import generator_vs_ideal, single_role

    scenario = load_scenario(find_scenario("paper-60s"))
    system = resolve_system(scenario, fmu_paths=current_fmu_paths(scenario))
    CoSimulation(system).run(handle_sigint=False)  # FMU extraction and kernel loading are not the baseline
    cpu0 = time.process_time()
    outcome = CoSimulation(system).run(handle_sigint=False)
    times = {"co-simulation": time.process_time() - cpu0}
    assert outcome.complete, outcome.error
    series = {c.column: outcome.values[:, i] for i, c in enumerate(outcome.columns)}
    signals = recorded_signals(system, series)
    units = {c.column: c.unit for c in outcome.columns}
    ldds = list(fatigue_report(series, scenario.analysis.fatigue_settings(), scenario.simulation.window_s,
                               signals.forces + signals.torques, time_s=outcome.time_s, torques=signals.torques,
                               units=units).ldd.values())
    window = scenario.simulation.window_s
    rotor = single_role(system, WIND_SOURCE).column("rotor_speed")
    generator = single_role(system, GENERATOR).column("generator_speed")
    ratio = generator_vs_ideal(system, outcome)["ratio"]

    import importlib

    cpu0 = time.process_time()
    for module in FIRST_IMPORTS:  # what the first figure imports
        importlib.import_module(module)
    times["import"] = time.process_time() - cpu0
    assert "matplotlib" not in sys.modules, "the run figures imported matplotlib"
    from orchestrator.raster import figure
    from orchestrator.run import plots
    from orchestrator.run.analysis_plots import plot_load_duration

    encoding = []
    encode = figure.write_png

    def timed_encode(image, path):
        start = time.process_time()
        try:
            return encode(image, path)
        finally:
            encoding.append(time.process_time() - start)

    figure.write_png = timed_encode
    draw = {
        "load_duration": lambda: plot_load_duration(ldds, out / "load_duration.png"),
        "rotor_speed": lambda: plots.plot_rotor_speed(outcome, rotor, window, out / "rotor_speed.png"),
        "generator_speed": lambda: plots.plot_generator_speed(outcome, rotor, generator, ratio, window,
                                                              out / "generator_speed.png"),
        "contact_forces": lambda: plots.plot_contact_forces(outcome, single_role(system, GEARBOX), window,
                                                            out / "contact_forces.png"),
    }
    for name in FIGURES:
        cpu0 = time.process_time()
        draw[name]()
        times[name] = time.process_time() - cpu0
        times[f"{name} encoding"] = encoding[-1]
    assert "matplotlib" not in sys.modules, "the run figures imported matplotlib"
    times["size"] = sum((out / f"{name}.png").stat().st_size for name in FIGURES)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="fresh processes measured (default 5)")
    parser.add_argument("--keep", type=Path, default=None, help="write the figures into this folder and keep them")
    parser.add_argument("--child", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        print(json.dumps(child(args.child)))
        return
    runs = []
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-plots-") as tmp:
        out = args.keep or Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell
        for _ in range(args.repeat + 1):  # the first writes the bytecode of a fresh checkout
            proc = subprocess.run([sys.executable, __file__, "--child", str(out)], capture_output=True, text=True,
                                  env=env, check=True)
            runs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    runs = runs[1:]

    def median(key: str) -> float:
        return statistics.median(r[key] for r in runs)

    print(f"paper-60s over 0-60 s: the four figures of a default run, each the first of its kind in a fresh process "
          f"(CPU time, median of {len(runs)} processes)")
    for name in FIGURES:
        print(f"  {name + '.png':22s} {median(name):6.3f} s CPU   (of which PNG encoding {median(name + ' encoding'):.3f} s)")
    total = statistics.median(sum(r[name] for name in FIGURES) for r in runs)
    print(f"  {'the four figures':22s} {total:6.3f} s CPU   ({median('size') / 1024:.0f} KiB)")
    print(f"  {'their import':22s} {median('import'):6.3f} s CPU   (the renderer and Pillow)")
    with_import = statistics.median(sum(r[name] for name in FIGURES) + r["import"] for r in runs)
    print(f"  {'figures and import':22s} {with_import:6.3f} s CPU   (target <= about 0.3 s)")
    print(f"  {'co-simulation':22s} {median('co-simulation'):6.3f} s CPU")
    ratio = statistics.median(sum(r[name] for name in FIGURES) / r["co-simulation"] for r in runs)
    print(f"ratio: the four figures / the co-simulation that made their data  {ratio:.2f}")


if __name__ == "__main__":
    main()
