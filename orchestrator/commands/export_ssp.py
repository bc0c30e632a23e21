"""``dtcosim export-ssp``: write a scenario as an SSP 1.0 archive (for libcosim and other SSP hosts)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import scenario_options
from .catalogue import help_line
from .fmu_options import add_fmu_arguments


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``export-ssp`` subcommand."""
    p = sub.add_parser(
        "export-ssp",
        help=help_line("export-ssp"),
        description=(
            "Write SCENARIO (TOML, SSP or packaged name; default paper-60s) as an SSP 1.0 archive: "
            "SystemStructure.ssd with components, connectors, parameter values, connections, the fixed-step "
            "algorithm for libcosim (osp:FixedStepAlgorithm) and dtcosim's own settings as an annotation, plus the "
            "FMUs under resources/. The FMUs are initialised once to compute the values of [[initial]] bindings, "
            "which other hosts receive as parameter values. dtcosim FMUs are archived as copies whose start values "
            "are the exported values, so hosts that apply no parameter set (ecos without --parameterSet) run the "
            "same system; other tools' FMUs are archived unchanged (their values are in the parameter set only)."
        ),
    )
    p.add_argument("scenario", nargs="?", default=None, metavar="SCENARIO",
                   help="scenario TOML/SSP file or packaged scenario name (default: paper-60s)")
    p.add_argument("--out", type=Path, required=True, metavar="FILE.ssp", help="output archive")
    p.add_argument("--target", choices=("dtcosim", "libcosim", "ecos"), default="dtcosim",
                   help="the host the archive is for: libcosim and ecos step with Jacobi, so the export sets that "
                        "algorithm with the scenario's coupling and step for it ([jacobi] table, as paper-60s "
                        "declares) and says (SSD and output) what its step was chosen for; a scenario without one is "
                        "warned about: give the step the coupling study finds for Jacobi with --step, or its --json "
                        "file with --tuning")
    p.add_argument("--tuning", type=Path, default=None, metavar="FILE.json",
                   help="the largest steps per algorithm that the coupling study measured (python "
                        "benchmarks/coupling_study.py --json FILE.json): the export uses the one of the target's "
                        "algorithm")
    add_fmu_arguments(p)
    scenario_options.add_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Export the scenario."""
    from ..cosim.master import CoSimulation
    from ..cosim.system import resolve_system
    from ..interop.ssp import export_ssp
    from ..interop.ssp_export import PARAMETER_SET, host_notes, stale_warnings, unbaked_components
    from ..provision.project_fmus import ensure_fmus
    from ..provision.staleness import stale_project_fmus

    scenario, tuning, tuning_text = _tuned_for(scenario_options.load(args.scenario, args, "export-ssp"), args)
    paths = ensure_fmus(scenario, args.fmu_dir, build=not args.no_build,
                        report=lambda m: print(m, file=sys.stderr))
    for warning in stale_project_fmus(paths):
        print(f"dtcosim export-ssp: warning: {warning}", file=sys.stderr)
    system = resolve_system(scenario, fmu_paths=paths)
    initial = CoSimulation(system).initial_values() if scenario.initial or scenario.bindings else {}
    out = export_ssp(system, args.out, initial, tuning)
    for warning in stale_warnings(system, initial):
        print(f"dtcosim export-ssp: warning: {warning}", file=sys.stderr)
    unbaked = unbaked_components(system, initial)
    if unbaked:
        print(f"dtcosim export-ssp: warning: {', '.join(unbaked)}: not dtcosim FMUs, archived unchanged; their "
              f"parameter values are only in the parameter set '{PARAMETER_SET}', which a host must apply (ecos: "
              f"--parameterSet {PARAMETER_SET})", file=sys.stderr)
    print(f"{out}: {len(scenario.components)} components, {len(scenario.connections)} connections"
          + (f", initial values {', '.join(f'{k} = {v:.10g}' for k, v in initial.items())}" if initial else "")
          + f"; {tuning_text}")
    sim = scenario.simulation
    for note in host_notes(args.target, sim.step_s, sim.stop_s):
        print(f"dtcosim export-ssp: note: {note}", file=sys.stderr)
    return 0


def _tuned_for(scenario, args: argparse.Namespace):
    """(the scenario with the target host's algorithm, coupling and step and the command line's changes,
    ExportTuning, what it was tuned for as text).

    A target that steps with Jacobi gets the scenario's coupling for Jacobi (its ``[jacobi]`` table:
    :meth:`~orchestrator.inputs.scenario.Scenario.for_algorithm`), then the command line's changes
    (``--set``, ``--step``, ...). The step is, in this order, the one
    ``--tuning`` measured for the target's algorithm, the one ``--step`` gives, the one the ``[jacobi]``
    table declares (with what it was chosen by), or the scenario's (chosen for the scenario's own algorithm;
    a target that steps with another algorithm is warned about on stderr).
    """
    from ..errors import ScenarioError
    from ..interop.ssp_export import HOST_ALGORITHMS, ExportTuning

    own = scenario.simulation.algorithm
    algorithm = HOST_ALGORITHMS[args.target] or own
    if args.algorithm is not None and args.algorithm != algorithm:
        raise ScenarioError("--algorithm", args.algorithm, f"{algorithm}: --target {args.target} steps with "
                            f"{algorithm}; leave --algorithm out or choose another --target", scenario.source)
    coupling = scenario.jacobi if algorithm == "jacobi" else None
    coupled = "" if coupling is None else coupling.describe()
    scenario = scenario_options.apply(scenario.for_algorithm(algorithm), args, "export-ssp")
    criteria = ""
    if args.tuning is not None:
        if args.step is not None:
            raise ScenarioError("--step", args.step, "no --step together with --tuning (which gives the step)",
                                scenario.source)
        step, criteria = _measured_step(args.tuning, scenario.name, algorithm)
        scenario = scenario.with_simulation(step_s=step)
    step_ms = f"{scenario.simulation.step_s * 1e3:g} ms"
    with_coupling = f" with the scenario's coupling for {algorithm} ({coupled})" if coupled else ""
    if args.tuning is not None:
        tuned_for = algorithm
        text = (f"target {args.target}: {algorithm} at H = {step_ms}{with_coupling}, the largest step within the "
                f"coupling study's criteria for {algorithm} ({criteria}; {args.tuning})")
    elif args.step is not None:
        tuned_for = algorithm
        text = f"target {args.target}: {algorithm} at H = {step_ms}{with_coupling} (given with --step)"
    elif coupling is not None and coupling.step_s is not None:
        tuned_for, criteria = algorithm, coupling.step_criteria
        text = (f"target {args.target}: {algorithm} at H = {step_ms}{with_coupling}, the step the scenario declares "
                f"for {algorithm}" + (f": {criteria}" if criteria else ""))
    else:
        tuned_for = own if args.algorithm is None else args.algorithm
        text = f"target {args.target}: {algorithm} at H = {step_ms}{with_coupling}, the scenario's step, chosen for {tuned_for}"
        if algorithm != tuned_for:
            print(f"dtcosim export-ssp: warning: {args.target} steps with {algorithm}, but H = {step_ms} is the "
                  f"scenario's step, chosen for {tuned_for}: its accuracy against the monolithic reference holds "
                  f"for {tuned_for} only; measure the largest step within the coupling study's criteria for "
                  f"{algorithm} (python benchmarks/coupling_study.py --algorithms {algorithm} --json FILE) and give "
                  "it with --tuning FILE or --step, or declare the scenario's coupling and step for it "
                  f"([{algorithm}] table)", file=sys.stderr)
    return scenario, ExportTuning(args.target, tuned_for, criteria, coupled), text


def _measured_step(path: Path, scenario_name: str, algorithm: str) -> tuple[float, str]:
    """(largest step for ``algorithm``, the criteria) from a coupling-study JSON file (``--json``) of this scenario."""
    import json
    import math

    from ..errors import ScenarioError
    from ..inputs.files import read_regular_bytes

    try:
        data = json.loads(read_regular_bytes(path).decode("utf-8"))
    except (OSError, ValueError) as exc:
        raise ScenarioError("--tuning", str(path), f"a JSON file of benchmarks/coupling_study.py --json ({exc})") \
            from None
    if not isinstance(data, dict) or not isinstance(data.get("largest_step_s"), dict):
        raise ScenarioError("largest_step_s", None, "a table of the largest step per algorithm (benchmarks/"
                            "coupling_study.py --json)", str(path))
    if data.get("scenario") != scenario_name:
        raise ScenarioError("scenario", data.get("scenario"), f"the exported scenario {scenario_name!r}: the steps "
                            "were measured on another scenario", str(path))
    step = data["largest_step_s"].get(algorithm)
    if not isinstance(step, (int, float)) or isinstance(step, bool) or not math.isfinite(step) or step <= 0:
        raise ScenarioError(f"largest_step_s.{algorithm}", step, f"a step [s] > 0: the study found none within its "
                            f"criteria for {algorithm} (measure smaller steps: --steps)", str(path))
    window = data.get("window_s")
    span = (f", measured with the window [{window[0]:g}, {window[1]:g}] s" if isinstance(window, list) and len(window) == 2
            and all(isinstance(w, (int, float)) for w in window) else "")
    return float(step), str(data.get("criteria", "")) + span
