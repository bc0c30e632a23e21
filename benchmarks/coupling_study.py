"""Coupling study: the paper scenario co-simulated at several communication steps H against the monolithic reference.

Default mode (the study behind the packaged scenarios' ``step``): the default master
(Gauss-Seidel, hold, averaged shaft torque) at H = 1, 2, 5, 10, 20 ms over the whole
paper scenario (60 s, Table 7 window [5, 60] s). For each H it prints, against the
monolithic solution of the same scenario (same seed):

* the largest relative difference of the mean and of the std over every contact
  force (the Table 7 statistics), relative to the monolithic mean / std;
* the RMS of the pointwise difference of the generator speed [rad/s] within the
  window (outputs every H; the reference is sampled on the same grid);
* the cost: process CPU time of the stepping loop per simulated second, and of the
  whole run (instantiation and initialisation included);

then the largest H that keeps every Table 7 statistic within ``--tolerance``
(default 1e-4) and the generator-speed RMS below ``--omega-tolerance`` (default
1e-4 rad/s), each with ``--margin`` (0.8): the ``step`` the packaged scenarios use.
``--algorithms`` (default ``gauss-seidel,jacobi``) gives one table and one largest H
per master algorithm: the Jacobi column is the step for hosts that step with Jacobi
(libcosim, ecos), with the scenario's coupling for Jacobi (its ``[jacobi]`` table:
``Scenario.for_algorithm``), which ``dtcosim export-ssp --target libcosim|ecos`` and
``dtcosim run --algorithm jacobi`` apply; its largest H is the ``step`` of that table.
``--json FILE`` writes the largest step per algorithm, which
``dtcosim export-ssp --target libcosim --tuning FILE`` uses.

Then, at that H, the Gearbox FMU's internal error control (``solver.rtol``,
``solver.atol_q``, ``solver.atol_v``) at ``--tolerance-scales`` times the FMU's
defaults (1e-4, 1e-8 rad, 1e-5 rad/s), with the same columns, and the loosest
scale that keeps the same criteria: the Gearbox tolerances ``paper-60s`` sets.
Looser tolerances only save time until the Gearbox takes one internal step per
communication step; beyond that scale the results do not change.

``--variants`` prints the older comparison of master variants (algorithm, order,
extrapolation, shaft-torque coupling) instead.

Run: ``python benchmarks/coupling_study.py [--stop 60] [--steps 1,2,5,10,20] [--tolerance-scales 1,3,10]``
(H in ms).
Prints Markdown tables (used in docs/orchestrator.md).
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import time

VARIANTS = [
    # label, simulation overrides, gearbox parameters
    ("Gauss-Seidel (default order), hold, averaged torque [default]", {}, {"shaft_torque_mode": 0}),
    ("Gauss-Seidel (default order), hold, end-of-step torque", {}, {"shaft_torque_mode": 1}),
    ("Gauss-Seidel (default order), linear, averaged torque", {"extrapolation": "linear"}, {"shaft_torque_mode": 0}),
    ("Gauss-Seidel, wind stepped first, hold, averaged torque", {"order": ("wind", "gearbox", "generator")}, {"shaft_torque_mode": 0}),
    ("Jacobi, hold, averaged torque", {"algorithm": "jacobi"}, {"shaft_torque_mode": 0}),
    ("Jacobi, hold, end-of-step torque", {"algorithm": "jacobi"}, {"shaft_torque_mode": 1}),
]


def _setup(stop: float, fmu_dir, output_interval: float | None):
    from current_fmus import current_fmu_paths
    from orchestrator.cosim.physics_view import physics_view
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.run.comparison import run_reference

    base = load_scenario(find_scenario("paper-60s"))
    window = base.simulation.window_s if stop == base.simulation.stop_s else (min(5.0, stop / 2), stop)
    changes = {"stop_s": stop, "window_s": window}
    if output_interval is not None:  # the step too: the scenario's own step may not divide the interval
        changes.update(step_s=output_interval, output_interval_s=output_interval)
    base = base.with_simulation(**changes)
    paths = current_fmu_paths(base, fmu_dir)
    system = resolve_system(base, fmu_paths=paths)
    setup = physics_view(system)
    cpu0 = time.process_time()
    reference = run_reference(system, setup)
    reference_cpu = time.process_time() - cpu0
    return base, paths, setup, reference, reference_cpu


def accuracy_and_cost(outcome, reference, system, setup) -> dict[str, float]:
    """Largest relative Table 7 differences, generator-speed RMS error and cost of one co-simulation."""
    from orchestrator.run.comparison import compare

    variables = compare(outcome, reference, system, setup)["variables"]
    forces = {k: v for k, v in variables.items() if ".F_" in k}
    stop = system.scenario.simulation.stop_s - system.scenario.simulation.start_s
    return {
        "mean": max(abs(v["relative_difference"]["mean"]) for v in forces.values()),
        "std": max(abs(v["relative_difference"]["std"]) for v in forces.values()),
        "omega_rms": variables["generator.omega"]["rms_difference"],
        "force_rms": max(v["rms_relative_to_std"] for v in forces.values()),
        "loop_cpu_per_s": outcome.loop_cpu_time_s / stop,
        "cpu_per_s": outcome.cpu_time_s / stop,
    }


def step_study(args) -> None:
    from components.model.kernel import choose_kernel
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system

    from orchestrator.run.comparison import run_reference

    steps = [float(h) * 1e-3 for h in args.steps.split(",")]
    base, paths, setup, reference, reference_cpu = _setup(args.stop, args.fmu_dir, min(steps))
    window = base.simulation.window_s
    kernel = choose_kernel()[0]
    print(f"paper scenario, 0-{args.stop:g} s, window [{window[0]:g}, {window[1]:g}] s, outputs every H (the "
          f"reference on the same grid); Gearbox kernel: {kernel}; monolithic reference at "
          f"{min(steps) * 1e3:g} ms output: integration {reference.info['cpu_time_s']:.2f} s CPU, total "
          f"{reference_cpu:.2f} s CPU\n")
    algorithms = [a.strip() for a in args.algorithms.split(",") if a.strip()]
    rows = []
    references = {min(steps): reference}
    for algorithm in algorithms:
        for h in steps:
            sc = base.for_algorithm(algorithm, step_s=h, output_interval_s=h)
            system = resolve_system(sc, fmu_paths=paths)
            CoSimulation(system).run(handle_sigint=False)  # warm-up: the first run also loads the compiled kernels
            outcome = CoSimulation(system).run(handle_sigint=False)
            if not outcome.complete:
                raise SystemExit(f"{algorithm}, H = {h * 1e3:g} ms: {outcome.error}")
            if h not in references:  # the reference on each output grid, once for all algorithms
                references[h] = run_reference(system, setup)
            rows.append((algorithm, h, accuracy_and_cost(outcome, references[h], system, setup)))
    print(f"Gearbox tolerances of the scenario: {_tolerance_text(base)}\n")
    print("| algorithm | H [ms] | max rel. diff. mean (contact forces) | max rel. diff. std (contact forces) | "
          "generator-speed RMS error [rad/s] | max RMS difference / std (contact forces) | "
          "stepping CPU per simulated s [s] | run CPU per simulated s [s] | within |")
    print("|---|---|---|---|---|---|---|---|---|")
    largest: dict[str, float | None] = {a: None for a in algorithms}
    for algorithm, h, r in rows:
        ok = _within(r, args)
        if ok and (largest[algorithm] is None or h > largest[algorithm]):
            largest[algorithm] = h
        print(f"| {algorithm} | {h * 1e3:g} | {r['mean']:.2e} | {r['std']:.2e} | {r['omega_rms']:.2e} | "
              f"{r['force_rms']:.2e} | {r['loop_cpu_per_s']:.4f} | {r['cpu_per_s']:.4f} | {'yes' if ok else 'no'} |")
    chosen = largest.get(algorithms[0])
    all_rows = rows
    rows = [(h, r) for a, h, r in rows if a == algorithms[0]]
    costs = [r["loop_cpu_per_s"] for h, r in rows if h >= 5e-3]
    print()
    if len(costs) > 1:
        print(f"cost per simulated second non-increasing from 5 ms up: "
              f"{'yes' if all(b <= a for a, b in zip(costs, costs[1:])) else 'NO'} "
              f"({', '.join(f'{c:.4f}' for c in costs)} s)")
    limits = (f"every Table 7 statistic within {args.margin:g} x {args.tolerance:g} and generator-speed RMS < "
              f"{args.margin:g} x {args.omega_tolerance:g} rad/s")
    for algorithm, h in largest.items():
        print(f"{algorithm}: " + (f"no H meets {limits}" if h is None else f"largest H with {limits}: {h * 1e3:g} ms"))
    if args.json:
        _write_steps(args, base, largest, all_rows, limits)
    if chosen is not None:
        if args.tolerance_scales:
            tolerance_study(args, base, paths, setup, chosen, reference if chosen == min(steps) else None)
    if args.interfaces:
        interface_study(args, base, paths, setup, steps)


def _write_steps(args, base, largest: dict, rows: list, limits: str) -> None:
    """The largest step per algorithm as JSON, for ``dtcosim export-ssp --target HOST --tuning FILE``."""
    import json
    from pathlib import Path

    data = {
        "scenario": base.name,
        "start_s": base.simulation.start_s,
        "stop_s": base.simulation.stop_s,
        "window_s": list(base.simulation.window_s),
        "criteria": limits,
        "largest_step_s": largest,
        "couplings": {a: (base.jacobi.describe() if a == "jacobi" and base.jacobi is not None else "")
                      for a in largest},
        "rows": [{"algorithm": a, "step_s": h, **r} for a, h, r in rows],
    }
    Path(args.json).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    print(f"written {args.json}")


#: the Gearbox's interface to the generator and the rotor: the scenario's, and the alternatives it replaced
INTERFACES = (
    ("motion interface, rotor slope from the last two speeds", {"generator_interface": 0, "rotor_derivatives": False}),
    ("motion interface, rotor derivative inputs", {"generator_interface": 0, "rotor_derivatives": True}),
    ("inertia interface, rotor slope from the last two speeds", {"generator_interface": 1, "rotor_derivatives": False}),
    ("inertia interface, rotor derivative inputs", {"generator_interface": 1, "rotor_derivatives": True}),
)


def interface_study(args, base, paths, setup, steps: list[float]) -> None:
    """Largest relative std difference of the contact forces per Gearbox interface and H (the scenario's tolerances)."""
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.run.comparison import run_reference

    print("\nmax rel. diff. std (contact forces) / generator-speed RMS error [rad/s] by the Gearbox's interface "
          "(parameters generator_interface, rotor_derivatives)\n")
    print("| interface | " + " | ".join(f"H = {h * 1e3:g} ms" for h in steps) + " |")
    print("|---|" + "---|" * len(steps))
    references = {}
    for label, values in INTERFACES:
        cells = []
        for h in steps:
            sc = base.with_simulation(step_s=h, output_interval_s=h).with_parameters("gearbox", **values)
            system = resolve_system(sc, fmu_paths=paths)
            outcome = CoSimulation(system).run(handle_sigint=False)
            if h not in references:
                references[h] = run_reference(system, setup)
            if not outcome.complete:
                cells.append("failed")
                continue
            r = accuracy_and_cost(outcome, references[h], system, setup)
            cells.append(f"{r['std']:.1e} / {r['omega_rms']:.1e}")
        print(f"| {label} | " + " | ".join(cells) + " |")


#: the Gearbox FMU's error-control parameters the tolerance table scales
SOLVER_TOLERANCES = ("solver.rtol", "solver.atol_q", "solver.atol_v")


def _solver_defaults() -> dict[str, float]:
    """The Gearbox FMU's default error control, by parameter name (``solver.rtol``: ...)."""
    from components.model.integrators import StepControl

    defaults = StepControl()
    return {name: getattr(defaults, name.split(".")[1]) for name in SOLVER_TOLERANCES}


def _within(r: dict, args) -> bool:
    """Every criterion met with the margin: a change in the last digits of the arithmetic cannot move the choice."""
    tol, omega_tol = args.margin * args.tolerance, args.margin * args.omega_tolerance
    return r["mean"] <= tol and r["std"] <= tol and r["omega_rms"] < omega_tol


def _tolerance_text(scenario) -> str:
    given = next(c for c in scenario.components if c.name == "gearbox").parameters
    return ", ".join(f"{name} = {given.get(name, value):g}" for name, value in _solver_defaults().items())


def tolerance_study(args, base, paths, setup, step_s: float, reference) -> None:
    """The Gearbox's error control at ``args.tolerance_scales`` x its defaults, at the communication step ``step_s``."""
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.run.comparison import run_reference

    defaults = _solver_defaults()
    scales = [float(x) for x in args.tolerance_scales.split(",")]
    print(f"\nGearbox error control at H = {step_s * 1e3:g} ms, scale x the FMU's defaults (solver.rtol "
          f"{defaults['solver.rtol']:g}, solver.atol_q {defaults['solver.atol_q']:g} rad, solver.atol_v "
          f"{defaults['solver.atol_v']:g} rad/s)\n")
    print("| scale | max rel. diff. mean | max rel. diff. std | generator-speed RMS error [rad/s] | "
          "max RMS difference / std | stepping CPU per simulated s [s] | within |")
    print("|---|---|---|---|---|---|---|")
    chosen = None
    for scale in scales:
        values = {name: scale * value for name, value in defaults.items()}
        sc = base.with_simulation(step_s=step_s, output_interval_s=step_s).with_parameters("gearbox", **values)
        system = resolve_system(sc, fmu_paths=paths)
        CoSimulation(system).run(handle_sigint=False)  # warm-up: the cost column compares like with like
        outcome = CoSimulation(system).run(handle_sigint=False)
        if not outcome.complete:
            raise SystemExit(f"scale {scale:g}: {outcome.error}")
        if reference is None:  # the same grid for every scale: one reference run
            reference = run_reference(system, setup)
        r = accuracy_and_cost(outcome, reference, system, setup)
        ok = _within(r, args)
        if ok and (chosen is None or scale > chosen):
            chosen = scale
        print(f"| {scale:g} | {r['mean']:.2e} | {r['std']:.2e} | {r['omega_rms']:.2e} | {r['force_rms']:.2e} | "
              f"{r['loop_cpu_per_s']:.4f} | {'yes' if ok else 'no'} |")
    print()
    if chosen is None:
        print("no scale meets the criteria")
    else:
        print(f"loosest scale within the criteria: {chosen:g} ("
              + ", ".join(f"{name} = {chosen * value:g}" for name, value in defaults.items())
              + f"); the scenario has {_tolerance_text(base)}")


def variant_study(args) -> None:
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.run.comparison import compare

    steps = [float(h) * 1e-3 for h in args.steps.split(",")]
    base, paths, setup, reference, reference_cpu = _setup(args.stop, args.fmu_dir, 0.01)
    window = base.simulation.window_s
    print(f"paper scenario, 0-{args.stop:g} s, window [{window[0]:g}, {window[1]:g}] s; monolithic reference "
          f"({reference_cpu:.2f} s CPU)\n")
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=60.0, help="stop time [s] (default 60: Table 7's window)")
    parser.add_argument("--steps", default=None, help="communication steps in ms, comma separated "
                        "(default 1,2,5,10,20; with --variants 10,5,2,1)")
    parser.add_argument("--tolerance", type=float, default=1e-4, help="relative tolerance on Table 7's mean and std")
    parser.add_argument("--omega-tolerance", type=float, default=1e-4, help="generator-speed RMS tolerance [rad/s]")
    parser.add_argument("--margin", type=float, default=0.8, help="a criterion is met at <= margin x its tolerance "
                        "(default 0.8)")
    parser.add_argument("--tolerance-scales", default="0.3,1,3,10", help="Gearbox error-control scales (x the FMU's "
                        "defaults) tried at the chosen H, comma separated (default 0.3,1,3,10; empty: skip)")
    parser.add_argument("--interfaces", action="store_true", help="also the table of the Gearbox's interface "
                        "options (generator_interface, rotor_derivatives) at every H")
    parser.add_argument("--algorithms", default="gauss-seidel,jacobi", help="master algorithms of the step table, "
                        "comma separated; the tolerance and interface tables use the first (default "
                        "gauss-seidel,jacobi)")
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the largest step per algorithm "
                        "(and every row) to FILE, for dtcosim export-ssp --tuning FILE")
    parser.add_argument("--variants", action="store_true", help="compare master variants instead")
    parser.add_argument("--fmu-dir", default=None, help="FMU directory (default: the FMU folder `dtcosim run` uses, $DTCOSIM_FMU_DIR or ~/.cache/dtcosim/fmus)")
    args = parser.parse_args()
    if args.steps is None:
        args.steps = "10,5,2,1" if args.variants else "1,2,5,10,20"
    (variant_study if args.variants else step_study)(args)


if __name__ == "__main__":
    main()
