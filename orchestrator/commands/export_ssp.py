"""``dtcosim export-ssp``: write a scenario as an SSP 1.0 archive (for libcosim and other SSP hosts)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import scenario_options
from .fmu_options import add_fmu_arguments


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``export-ssp`` subcommand."""
    p = sub.add_parser(
        "export-ssp",
        help="export a scenario with its FMUs as an SSP 1.0 archive (.ssp)",
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
    add_fmu_arguments(p)
    scenario_options.add_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Export the scenario."""
    from ..cosim.master import CoSimulation
    from ..cosim.system import resolve_system
    from ..interop.ssp import export_ssp
    from ..interop.ssp_export import PARAMETER_SET, stale_warnings, unbaked_components
    from ..provision.project_fmus import ensure_fmus
    from ..provision.staleness import stale_project_fmus

    scenario = scenario_options.apply(scenario_options.load(args.scenario, args, "export-ssp"), args, "export-ssp")
    paths = ensure_fmus(scenario, args.fmu_dir, build=not args.no_build,
                        report=lambda m: print(m, file=sys.stderr))
    for warning in stale_project_fmus(paths):
        print(f"dtcosim export-ssp: warning: {warning}", file=sys.stderr)
    system = resolve_system(scenario, fmu_paths=paths)
    initial = CoSimulation(system).initial_values() if scenario.initial else {}
    out = export_ssp(system, args.out, initial)
    for warning in stale_warnings(system, initial):
        print(f"dtcosim export-ssp: warning: {warning}", file=sys.stderr)
    unbaked = unbaked_components(system, initial)
    if unbaked:
        print(f"dtcosim export-ssp: warning: {', '.join(unbaked)}: not dtcosim FMUs, archived unchanged; their "
              f"parameter values are only in the parameter set '{PARAMETER_SET}', which a host must apply (ecos: "
              f"--parameterSet {PARAMETER_SET})", file=sys.stderr)
    print(f"{out}: {len(scenario.components)} components, {len(scenario.connections)} connections"
          + (f", initial values {', '.join(f'{k} = {v:.10g}' for k, v in initial.items())}" if initial else ""))
    return 0
