"""Command-line interface ``dtcosim``.

Each subcommand lives in its own module exposing ``register(subparsers)``,
which adds an argparse sub-parser whose ``func`` attribute runs the command
and returns the process exit code.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from components.errors import DtcosimError

#: modules providing subcommands, in help order
COMMAND_MODULES = (
    "orchestrator.commands.run",
    "orchestrator.commands.export_ssp",
    "orchestrator.commands.reference",
    "orchestrator.commands.build",
    "orchestrator.commands.validate",
    "orchestrator.commands.modes",
    "orchestrator.commands.sweep",
    "orchestrator.commands.loads",
)


def _version_text() -> str:
    """``dtcosim X (python ..., numpy ..., fmpy ..., pythonfmu ...)``: what a result depends on."""
    from components import __version__

    from ..result_files import versions

    deps = ", ".join(f"{k} {v}" for k, v in versions().items() if k != "dtcosim")
    return f"dtcosim {__version__} ({deps})"


class _VersionAction(argparse.Action):
    """``--version``: looks the package versions up only when asked."""

    def __call__(self, parser, namespace, values, option_string=None):
        print(_version_text())
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """The ``dtcosim`` argument parser with every registered subcommand."""
    parser = argparse.ArgumentParser(
        prog="dtcosim",
        description="Wind-turbine drivetrain torsional vibration as an FMI 2.0 co-simulation.",
    )
    parser.add_argument("--version", action=_VersionAction, nargs=0,
                        help="print the versions of dtcosim and of what its results depend on, and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``dtcosim`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except DtcosimError as exc:
        print(f"dtcosim {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"dtcosim {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
