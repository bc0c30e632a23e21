"""``dtcosim build``: build the project's FMUs (from a preset, a drivetrain file or a scenario)."""

from __future__ import annotations

import argparse

from fmus.build import PRESET_FMU_NAMES, add_arguments, run as run_preset

from ..cosim.fmu_folder import default_fmu_dir


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``build`` subcommand."""
    p = sub.add_parser(
        "build",
        help=f"build the FMUs {', '.join(PRESET_FMU_NAMES)}",
        description=(f"Build the self-contained pythonfmu FMUs {', '.join(n + '.fmu' for n in PRESET_FMU_NAMES)}. "
                     "With --drivetrain FILE: Gearbox.fmu and GeneratorRotor.fmu of that drivetrain file, by default "
                     "into the FMU directory's folder of the file's content (drivetrains/<name>-<sha256>/), where "
                     "scenarios naming the file find them."),
    )
    add_arguments(p, default_out=default_fmu_dir())  # where `dtcosim run` looks for them
    p.add_argument("--drivetrain", default=None, metavar="FILE",
                   help="drivetrain TOML file or packaged name (grc-like, paper-table6, ...) instead of --preset")
    p.add_argument("--scenario", default=None, metavar="SCENARIO",
                   help="build every project FMU a scenario uses (its TimeSeriesSource from the record, drivetrain "
                        "FMUs, ...) into the FMU directory --out, where `dtcosim run` finds them")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Build from the preset or the drivetrain file and print what was written."""
    from ..cosim.compiled_kernels import ensure_compiled_kernels

    ensure_compiled_kernels(report=print, retry=True)
    if args.scenario is not None:
        from ..cosim.fmu_store import ensure_fmus
        from ..inputs.scenario import find_scenario, load_scenario

        scenario = load_scenario(find_scenario(args.scenario))
        for comp, path in ensure_fmus(scenario, args.out, report=print).items():
            print(f"{path}  ({comp})")
        return 0
    if args.drivetrain is None:
        return run_preset(args)
    from components.errors import ParameterError

    from ..cosim.drivetrain_fmus import DRIVETRAIN_FMU_NAMES, build_drivetrain_fmus
    from ..inputs.drivetrain_file import find_drivetrain, load_drivetrain_file
    from ..inputs.scenario import drivetrain_fmu_dir

    if args.preset != "table6":
        raise ParameterError("--preset", args.preset, "no preset together with --drivetrain")
    spec = load_drivetrain_file(find_drivetrain(args.drivetrain))
    names = args.fmu or list(DRIVETRAIN_FMU_NAMES)
    explicit_out = args.out != default_fmu_dir()
    out = args.out if explicit_out else drivetrain_fmu_dir(args.out, spec)
    for built in build_drivetrain_fmus(spec, out, names):
        print(f"{built.path}  ({built.name}, {spec.origin}, build {built.build_id})")
    return 0
