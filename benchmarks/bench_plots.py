"""What the four figures of a default ``dtcosim run`` cost, against the co-simulation that made their data.

One process: the paper's 60 s scenario is co-simulated once (its CPU time is the baseline), its
analyses computed, then each figure a default run writes (``rotor_speed.png``,
``generator_speed.png``, ``contact_forces.png``: :mod:`orchestrator.run.plots`;
``load_duration.png``: :mod:`orchestrator.run.analysis_plots`) is drawn and written ``--repeat``
times into a temporary folder, the figures taking turns. Printed: the median CPU time of each
figure and of the four together, the share of that spent encoding the PNG, and the ratio of the
four figures to the co-simulation measured in the same process. matplotlib is imported (and its
first figure drawn) before anything is timed: the import is a start-up cost (``bench_commands.py``
measures whole commands).

Target (issue 34): the four figures at most about 0.3 s CPU.

Run: ``python benchmarks/bench_plots.py [--repeat N] [--stop T]``.
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import statistics
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="measured drawings of each figure (default 7)")
    parser.add_argument("--stop", type=float, default=60.0, help="stop time of the run [s] (default 60)")
    parser.add_argument("--keep", type=Path, default=None, help="write the figures into this folder and keep them")
    args = parser.parse_args()

    from current_fmus import current_fmu_paths
    from orchestrator import plotting
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE
    from orchestrator.run import analyses, plots
    from orchestrator.run.analysis_plots import plot_load_duration
    from orchestrator.run.derived import generator_vs_ideal, single_role

    scenario = load_scenario(find_scenario("paper-60s"))
    if args.stop != scenario.simulation.stop_s:
        scenario = scenario.with_simulation(stop_s=args.stop, window_s=(min(5.0, args.stop / 2), args.stop))
    system = resolve_system(scenario, fmu_paths=current_fmu_paths(scenario))
    CoSimulation(system).run(handle_sigint=False)  # warm-up: FMU extraction, kernel load
    cosim = []
    for _ in range(3):
        cpu0 = time.process_time()
        outcome = CoSimulation(system).run(handle_sigint=False)
        cosim.append(time.process_time() - cpu0)
    assert outcome.complete, outcome.error
    cosim_cpu = statistics.median(cosim)

    encode = []
    original_encode = plotting.encode_png

    def timed_encode(canvas, path):  # the PNG encoding alone (the figure is drawn before)
        cpu0 = time.process_time()
        try:
            return original_encode(canvas, path)
        finally:
            encode.append(time.process_time() - cpu0)

    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-plots-") as tmp:
        out = Path(args.keep or tmp)
        out.mkdir(parents=True, exist_ok=True)
        report = analyses.analyse_run(system, outcome, out, plots=False)
        assert "fatigue" in report.summary, report.skipped
        from components.analysis.fatigue import fatigue_report

        series = {c.column: outcome.values[:, i] for i, c in enumerate(outcome.columns)}
        sig = analyses._recorded_signals(system, series)
        units = {c.column: c.unit for c in outcome.columns}
        ldds = list(fatigue_report(series, system.scenario.analysis.fatigue_settings(),
                                   system.scenario.simulation.window_s, sig.forces + sig.torques, time_s=outcome.time_s,
                                   torques=sig.torques, units=units).ldd.values())
        window = system.scenario.simulation.window_s
        rotor = single_role(system, WIND_SOURCE).column("rotor_speed")
        generator = single_role(system, GENERATOR).column("generator_speed")
        ratio = generator_vs_ideal(system, outcome)["ratio"]
        figures = {
            "rotor_speed": lambda: plots.plot_rotor_speed(outcome, rotor, window, out / "rotor_speed.png"),
            "generator_speed": lambda: plots.plot_generator_speed(outcome, rotor, generator, ratio, window,
                                                                  out / "generator_speed.png"),
            "contact_forces": lambda: plots.plot_contact_forces(outcome, single_role(system, GEARBOX), window,
                                                                out / "contact_forces.png"),
            "load_duration": lambda: plot_load_duration(ldds, out / "load_duration.png"),
        }
        for draw in figures.values():  # warm-up: matplotlib's imports, font cache, first text layout
            draw()
        cpu = {name: [] for name in figures}
        enc = {name: [] for name in figures}
        plotting.encode_png = timed_encode
        try:
            for _ in range(args.repeat):
                for name, draw in figures.items():
                    encode.clear()
                    cpu0 = time.process_time()
                    written = draw()
                    cpu[name].append(time.process_time() - cpu0)
                    enc[name].append(sum(encode))
                    assert written, name
        finally:
            plotting.encode_png = original_encode
        sizes = {name: (out / f"{name}.png").stat().st_size for name in figures}

    print(f"paper-60s over 0-{scenario.simulation.stop_s:g} s ({outcome.time_s.size} samples): the four figures of a "
          f"default run, median of {args.repeat} drawings each (CPU time, this process)")
    total = 0.0
    for name in figures:
        med = statistics.median(cpu[name])
        total += med
        print(f"  {name + '.png':22s} {med:6.3f} s CPU   (of which PNG encoding {statistics.median(enc[name]):.3f} s; "
              f"{sizes[name] / 1024:.0f} KiB)")
    print(f"  {'the four figures':22s} {total:6.3f} s CPU   (target <= about 0.3 s)")
    print(f"  co-simulation            {cosim_cpu:6.3f} s CPU   (median of 3)")
    print(f"ratio: the four figures / the co-simulation that made their data  {total / cosim_cpu:.2f}")


if __name__ == "__main__":
    main()
