"""``dtcosim build``: build the FMUs WindSource, Gearbox and GeneratorRotor."""

from __future__ import annotations

import argparse

from fmus.build import add_arguments, run

from ..cosim.fmu_folder import default_fmu_dir


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``build`` subcommand."""
    p = sub.add_parser(
        "build",
        help="build the FMUs WindSource, Gearbox and GeneratorRotor",
        description="Build the self-contained pythonfmu FMUs WindSource.fmu, Gearbox.fmu and GeneratorRotor.fmu.",
    )
    add_arguments(p, default_out=default_fmu_dir())  # where `dtcosim run` looks for them
    p.set_defaults(func=run)
