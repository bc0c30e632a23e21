"""Coupling study: co-simulation of the paper scenario against the monolithic reference.

For master variants (algorithm, stepping order, input extrapolation) and both
shaft-torque couplings of the Gearbox FMU (``shaft_torque_mode`` 0 = averaged over
the step, 1 = end-of-step value) and communication steps H, print the difference
to the monolithic solution of the same scenario (same seed) over the analysis
window:

* RMS of the pointwise difference of the generator speed [rad/s] and of the
  stage-1 sun-planet force F_sp[1] [N] on the common 10 ms grid;
* relative difference of mean and std of F_sp[1].

Run: ``python benchmarks/coupling_study.py [--stop 20] [--steps 10,5,2,1]`` (H in ms).
Prints Markdown tables (used in docs/orchestrator.md).
"""

from __future__ import annotations

import argparse
import time

VARIANTS = [
    # label, simulation overrides, gearbox parameters
    ("Gauss-Seidel (default order), hold, averaged torque [default]", {}, {"shaft_torque_mode": 0}),
    ("Gauss-Seidel (default order), hold, end-of-step torque", {}, {"shaft_torque_mode": 1}),
    ("Gauss-Seidel (default order), linear, averaged torque", {"extrapolation": "linear"}, {"shaft_torque_mode": 0}),
    ("Gauss-Seidel (default order), linear, end-of-step torque", {"extrapolation": "linear"}, {"shaft_torque_mode": 1}),
    ("Gauss-Seidel, wind stepped first, hold, averaged torque", {"order": ("wind", "gearbox", "generator")}, {"shaft_torque_mode": 0}),
    ("Jacobi, hold, averaged torque", {"algorithm": "jacobi"}, {"shaft_torque_mode": 0}),
    ("Jacobi, hold, end-of-step torque", {"algorithm": "jacobi"}, {"shaft_torque_mode": 1}),
    ("Jacobi, linear, averaged torque", {"algorithm": "jacobi", "extrapolation": "linear"}, {"shaft_torque_mode": 0}),
    ("Jacobi, linear, end-of-step torque", {"algorithm": "jacobi", "extrapolation": "linear"}, {"shaft_torque_mode": 1}),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=20.0, help="stop time [s] (window [5, stop])")
    parser.add_argument("--steps", default="10,5,2,1", help="communication steps in ms, comma separated")
    parser.add_argument("--fmu-dir", default=None, help="FMU directory (default: the project's fmus/)")
    args = parser.parse_args()

    from orchestrator.cosim.fmu_store import ensure_fmus
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.physics_view import physics_view
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario import find_scenario, load_scenario
    from orchestrator.run.comparison import compare, run_reference

    steps = [float(h) * 1e-3 for h in args.steps.split(",")]
    window = (min(5.0, args.stop / 2), args.stop)
    base = load_scenario(find_scenario("paper-60s")).with_simulation(stop_s=args.stop, window_s=window,
                                                                       output_interval_s=0.01)
    paths = ensure_fmus(base, args.fmu_dir)
    system = resolve_system(base, fmu_paths=paths)
    setup = physics_view(system)
    reference = run_reference(system, setup)
    print(f"paper scenario, 0-{args.stop:g} s, window [{window[0]:g}, {window[1]:g}] s; monolithic reference "
          f"({reference.wall_time_s:.2f} s LSODA)\n")
    header = "| variant | " + " | ".join(f"H = {h * 1e3:g} ms" for h in steps) + " |"
    rule = "|---|" + "---|" * len(steps)
    tables = {key: [header, rule] for key in ("omega", "force", "mean", "std")}
    t0 = time.perf_counter()
    for label, sim_changes, gearbox in VARIANTS:
        cells = {key: [] for key in tables}
        for h in steps:
            sc = base.with_simulation(step_s=h, **sim_changes).with_parameters("gearbox", **gearbox)
            s = resolve_system(sc, fmu_paths=paths)
            out = CoSimulation(s).run(handle_sigint=False)
            v = compare(out, reference, s, setup)["variables"]
            cells["omega"].append(f"{v['generator.omega']['rms_difference']:.2e}")
            cells["force"].append(f"{v['gearbox.stage1.F_sp[1]']['rms_difference']:.2e}")
            cells["mean"].append(f"{v['gearbox.stage1.F_sp[1]']['relative_difference']['mean']:+.1e}")
            cells["std"].append(f"{v['gearbox.stage1.F_sp[1]']['relative_difference']['std']:+.1e}")
        for key in tables:
            tables[key].append(f"| {label} | " + " | ".join(cells[key]) + " |")
    titles = {
        "omega": "RMS difference of the generator speed to the monolithic solution [rad/s]",
        "force": "RMS difference of stage-1 F_sp[1] to the monolithic solution [N]",
        "mean": "Relative difference of the mean of stage-1 F_sp[1] (co-simulation / monolithic - 1)",
        "std": "Relative difference of the std of stage-1 F_sp[1] (co-simulation / monolithic - 1)",
    }
    for key, lines in tables.items():
        print(f"{titles[key]}\n")
        print("\n".join(lines))
        print()
    print(f"({time.perf_counter() - t0:.0f} s for {len(VARIANTS) * len(steps)} co-simulations)")


if __name__ == "__main__":
    main()
