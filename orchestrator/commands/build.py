"""``dtcosim build``: build the project's FMUs (from a preset, a drivetrain file, or all a scenario needs).

By default into the FMU folder ``dtcosim run`` searches (:func:`orchestrator.provision.folders.default_fmu_dir`:
``$DTCOSIM_FMU_DIR``, else ``fmus/`` in the per-user cache), or into ``--out``; never into the
installed package or a checkout. ``python build_fmus.py`` is this command for a checkout.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from components.model.presets import PRESETS
from fmus.registry import PRESET, names_built_from

from ..provision.folders import default_fmu_dir, usable_fmu_dir
from .catalogue import help_line

#: the FMUs built from a preset, in the registry's order
PRESET_FMUS = names_built_from(PRESET)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``build`` subcommand."""
    fmus = ", ".join(PRESET_FMUS)
    p = sub.add_parser(
        "build",
        help=help_line("build"),
        description=(f"Build the self-contained pythonfmu FMUs {fmus} into the FMU folder `dtcosim run` searches "
                     f"({default_fmu_dir()}; $DTCOSIM_FMU_DIR sets it) or into --out. With --drivetrain FILE: the "
                     "FMUs of that drivetrain file, by default into the FMU folder's folder of the file's content "
                     "(drivetrains/<name>-<sha256>/), where scenarios naming the file find them."),
    )
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: the FMU folder `dtcosim run` searches, $DTCOSIM_FMU_DIR or "
                        "fmus/ in the per-user cache)")
    p.add_argument("--preset", choices=PRESETS, default="table6",
                   help="drivetrain preset giving the structure and parameter defaults (default: table6)")
    p.add_argument("--fmu", choices=PRESET_FMUS, action="append",
                   help=f"build only this FMU (repeatable; default: all of {fmus})")
    p.add_argument("--drivetrain", default=None, metavar="FILE",
                   help="drivetrain TOML file or packaged name (grc-like, paper-table6, ...) instead of --preset")
    p.add_argument("--scenario", default=None, metavar="SCENARIO",
                   help="build every project FMU a scenario uses (its TimeSeriesSource from the load record, "
                        "drivetrain FMUs, ...) into the FMU folder --out, where `dtcosim run` finds them")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Build from the preset, the drivetrain file or the scenario and print what was written."""
    from fmus.build import build_all

    from ..cosim.compiled_kernels import ensure_compiled_kernels

    scenario = spec = None  # what to build from, read and checked before anything is created or compiled
    if args.scenario is not None:
        from ..inputs.scenario_file import find_scenario, load_scenario

        scenario = load_scenario(find_scenario(args.scenario))
    elif args.drivetrain is not None:
        from components.errors import ParameterError

        from ..inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

        if args.preset != "table6":
            raise ParameterError("--preset", args.preset, "no preset together with --drivetrain")
        spec = load_drivetrain_file(find_drivetrain(args.drivetrain))
        spec.cosim_drivetrain()  # a drivetrain the FMUs can be built from (with its generator)
    fmu_dir = usable_fmu_dir(args.out, "--out")  # or an error naming the setting, before the kernels' compile
    ensure_compiled_kernels(report=print, retry=True)
    if scenario is not None:
        from ..provision.project_fmus import ensure_fmus

        for comp, path in ensure_fmus(scenario, fmu_dir, report=print).items():
            print(f"{path}  ({comp})")
        return 0
    if spec is None:
        for built in build_all(fmu_dir, args.preset, names=args.fmu or PRESET_FMUS, report=print):
            print(f"{built.path}  ({built.name}, preset {args.preset}, build {built.build_id})")
        return 0
    from ..provision.drivetrain_fmus import DRIVETRAIN_FMU_NAMES, build_drivetrain_fmus
    from ..provision.folders import drivetrain_fmu_dir

    names = args.fmu or list(DRIVETRAIN_FMU_NAMES)
    out = args.out if args.out is not None else drivetrain_fmu_dir(fmu_dir, spec)
    for built in build_drivetrain_fmus(spec, out, names):
        print(f"{built.path}  ({built.name}, {spec.origin}, build {built.build_id})")
    return 0
