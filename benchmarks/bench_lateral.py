"""What the lateral-torsional gearbox costs: paper-60s-lateral against paper-60s, co-simulated, in one process.

Both scenarios are the paper's 60 s run (H = 20 ms, the same FMU tolerances); paper-60s-lateral's Gearbox is
the lateral-torsional Table 6 gearbox (drivetrain file paper-table6-lateral: 36 degrees of freedom against
12). Each is warmed up once (FMU extraction, kernel load) and measured ``--repeat`` times, the two taking
turns; medians of the process CPU time of the whole run and of its stepping loop are printed, with their
ratio (issue 33: at most 3), the Gearbox's internal steps per communication step, and the accuracy of the
lateral co-simulation against its own monolithic reference (Table 7 statistics).

Run: ``python benchmarks/bench_lateral.py [--fmu-dir DIR] [--repeat N] [--stop T]``.
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import statistics
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, default=None, help="FMU directory (default: dtcosim run's)")
    parser.add_argument("--repeat", type=int, default=5, help="measured runs of each (default 5)")
    parser.add_argument("--stop", type=float, default=60.0, help="stop time [s] (default 60)")
    args = parser.parse_args()

    from components.model.kernel import choose_kernel
    from current_fmus import current_fmu_paths
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.physics_view import physics_view
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.run.comparison import compare, run_reference

    systems = {}
    for name in ("paper-60s", "paper-60s-lateral"):
        scenario = load_scenario(find_scenario(name))
        if args.stop != scenario.simulation.stop_s:
            scenario = scenario.with_simulation(stop_s=args.stop, window_s=(min(5.0, args.stop / 2), args.stop))
        systems[name] = resolve_system(scenario, fmu_paths=current_fmu_paths(scenario, args.fmu_dir))
    sim = systems["paper-60s"].scenario.simulation
    print(f"paper-60s and paper-60s-lateral: 0-{sim.stop_s:g} s, H = {sim.step_s * 1e3:g} ms ({sim.n_steps} steps); "
          f"Gearbox kernel: {choose_kernel()[0]}; median of {args.repeat} runs each after one warm-up, interleaved")
    runs: dict[str, list] = {name: [] for name in systems}
    for system in systems.values():
        CoSimulation(system).run(handle_sigint=False)  # warm-up
    for _ in range(args.repeat):
        for name, system in systems.items():
            runs[name].append(CoSimulation(system).run(handle_sigint=False))
    cpu, loop = {}, {}
    for name, outcomes in runs.items():
        assert all(r.complete for r in outcomes), outcomes[0].error
        cpu[name] = statistics.median(r.cpu_time_s for r in outcomes)
        loop[name] = statistics.median(r.loop_cpu_time_s for r in outcomes)
        print(f"  {name:<18} {cpu[name]:7.3f} s CPU   (stepping loop {loop[name]:.3f} s CPU, "
              f"{1e6 * loop[name] / sim.n_steps:.1f} us per communication step)")
    pairs = statistics.median(b.cpu_time_s / a.cpu_time_s for a, b in zip(runs["paper-60s"], runs["paper-60s-lateral"]))
    ratio = cpu["paper-60s-lateral"] / cpu["paper-60s"]
    print(f"ratio lateral / torsional: whole run {ratio:.2f} (median of the interleaved pairs' ratios {pairs:.2f}; "
          f"target <= 3: {'met' if ratio <= 3.0 else 'NOT met'}), stepping loop "
          f"{loop['paper-60s-lateral'] / loop['paper-60s']:.2f}")

    system = systems["paper-60s-lateral"]
    setup = physics_view(system)
    reference = run_reference(system, setup)
    variables = compare(runs["paper-60s-lateral"][0], reference, system, setup)["variables"]
    # the contact forces (Table 7) and the loaded bearings (the sun and carrier bearings carry nothing but
    # round-off without gravity or errors: no relative difference to speak of)
    forces = {k: v for k, v in variables.items() if any(f in k for f in (".F_sp[", ".F_rp[", ".F_mesh"))
              or (k.endswith(".F") and "planet_bearing" in k) or k.endswith(("drive_bearing.F", "driven_bearing.F"))}
    worst = lambda stat: max((abs(v["relative_difference"][stat]), k) for k, v in forces.items())  # noqa: E731
    print(f"paper-60s-lateral against its monolithic reference ({len(forces)} contact and loaded bearing forces): "
          "mean within {:.1e} ({}), std within {:.1e} ({})".format(*worst("mean"), *worst("std")))


if __name__ == "__main__":
    main()
