"""The paper's 60 s scenario three ways: dtcosim's master, the monolithic reference, libcosim.

One process, one run each (libcosim in a child process with libpython preloaded;
only its ``simulate_until`` is timed):

1. dtcosim co-simulation of ``paper-60s`` at H = 1 ms through WindSource, Gearbox and
   GeneratorRotor FMUs, recording the scenario's 22 variables every step (wall time of
   instantiation, initialisation and stepping; the stepping loop alone also printed);
2. the monolithic reference (LSODA, :func:`components.reference.solver.simulate_monolithic`) of the
   same scenario, same seed, 1 ms output;
3. the same FMUs, exported as SSP, stepped by libcosim (libcosimpy) at the same H, observing
   the same variables.

Targets (issue 4): co-simulation at most 10 x the monolithic reference, under 6 s on the
2-core machine, faster than libcosim.

Run: ``python benchmarks/bench_cosim.py [--fmu-dir DIR] [--stop T]``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, default=None, help="FMU directory (default: the project's fmus/, built if missing)")
    parser.add_argument("--stop", type=float, default=60.0, help="stop time [s] (default 60)")
    parser.add_argument("--no-libcosim", action="store_true", help="skip the libcosim run")
    args = parser.parse_args()

    from orchestrator.cosim.fmu_store import ensure_fmus
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.physics_view import physics_view
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario import find_scenario, load_scenario
    from orchestrator.interop.libcosim import run_ssp_in_libcosim
    from orchestrator.interop.ssp import export_ssp
    from orchestrator.run.comparison import run_reference

    scenario = load_scenario(find_scenario("paper-60s"))
    if args.stop != scenario.simulation.stop_s:
        scenario = scenario.with_simulation(stop_s=args.stop, window_s=(min(5.0, args.stop / 2), args.stop))
    system = resolve_system(scenario, fmu_paths=ensure_fmus(scenario, args.fmu_dir))
    sim = scenario.simulation
    print(f"paper-60s: 0-{sim.stop_s:g} s, H = {sim.step_s:g} s ({sim.n_steps} steps), {len(system.recorded)} recorded "
          f"variables, {sim.algorithm}/{sim.extrapolation}, order {', '.join(system.order)}")

    outcome = CoSimulation(system).run(handle_sigint=False)
    assert outcome.complete, outcome.error
    t_cosim = outcome.wall_time_s
    print(f"  dtcosim co-simulation      {t_cosim:7.2f} s   (stepping loop {outcome.loop_time_s:.2f} s, "
          f"{1e6 * outcome.loop_time_s / outcome.steps:.1f} us per communication step)")

    setup = physics_view(system)
    t0 = time.perf_counter()
    reference = run_reference(system, setup)
    t_mono = time.perf_counter() - t0
    assert reference.complete, reference.message
    print(f"  monolithic reference       {t_mono:7.2f} s   (LSODA {reference.wall_time_s:.2f} s + output evaluation)")

    t_lib = None
    if not args.no_libcosim:
        with tempfile.TemporaryDirectory(prefix="dtcosim-bench-") as tmp:
            ssp = export_ssp(system, Path(tmp) / "paper.ssp", CoSimulation(system).initial_values())
            lib = run_ssp_in_libcosim(ssp, sim.stop_s, [rv.column for rv in system.recorded])
        t_lib = lib.simulation_wall_time_s
        print(f"  libcosim (libcosimpy)      {t_lib:7.2f} s   (simulate_until only; child process total "
              f"{lib.total_wall_time_s:.2f} s)")

    print("ratios")
    print(f"  co-simulation / monolithic {t_cosim / t_mono:7.2f}   (target <= 10)")
    if t_lib is not None:
        print(f"  co-simulation / libcosim   {t_cosim / t_lib:7.2f}   (target < 1)")
    print(f"  co-simulation wall time    {t_cosim:7.2f} s (target < 6 s)")


if __name__ == "__main__":
    main()
