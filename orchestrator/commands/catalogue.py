"""The ``dtcosim`` subcommands: name, module and the line ``dtcosim --help`` shows (a light module: nothing imported).

:mod:`orchestrator.commands.cli` lists every command from here and imports only the
module of the command that runs (importing all ten cost about 0.4 s of every command's
start-up); each module's ``register(sub)`` takes its line from :func:`help_line`.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """A subcommand: its name, the module with its ``register(sub)``, and its one-line help."""

    name: str
    module: str
    help: str


#: the subcommands, in help order
COMMANDS = (
    Command("run", "orchestrator.commands.run",
            "run a co-simulation scenario (default: the paper's 60 s scenario) and write results and plots"),
    Command("export-ssp", "orchestrator.commands.export_ssp",
            "export a scenario with its FMUs as an SSP 1.0 archive (.ssp)"),
    Command("reference", "orchestrator.commands.reference",
            "run a paper case (Table 2, Table 4, Fig. 10-11, Table 7) with the monolithic solver"),
    Command("build", "orchestrator.commands.build",
            "build the project's FMUs (WindSource, Gearbox, GeneratorRotor, ...) from a preset or a drivetrain file"),
    Command("validate", "orchestrator.commands.validate",
            "validate FMUs (fmpy validation, conventions, declared requirements against this environment)"),
    Command("modes", "orchestrator.commands.modes",
            "natural frequencies, damping and mode shapes at an operating point; Campbell diagram"),
    Command("cache", "orchestrator.commands.cache",
            "list the per-user cache (compiled kernels, FMU binary, unpacked FMUs, the FMU folder's drivetrain "
            "and record FMUs); --prune removes stale entries"),
    Command("drivetrain", "orchestrator.commands.drivetrain",
            "drivetrain description files: show the derived design table"),
    Command("sweep", "orchestrator.commands.sweep",
            "run a parameter study (grid, explicit points, seeds) on Dask workers and write a table and plots"),
    Command("loads", "orchestrator.commands.loads",
            "run a load-case set (wind-speed bins x seeds) and write lifetime DELs, Miner damage, LDD and LRD"),
)


def help_line(name: str) -> str:
    """The one-line help of command ``name``."""
    return next(c.help for c in COMMANDS if c.name == name)
