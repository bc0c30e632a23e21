"""``dtcosim drivetrain show FILE``: the derived design table of a drivetrain file."""

from __future__ import annotations

import argparse
import json

from .catalogue import help_line



def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``drivetrain`` subcommand (``show``)."""
    p = sub.add_parser("drivetrain", help=help_line("drivetrain"),
                       description="Work with drivetrain description files (TOML; see docs/drivetrains.md).")
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    show = actions.add_parser(
        "show", help="print the derived design table of a drivetrain file",
        description=("Read and check a drivetrain file and print per stage the ratio, pitch and base radii, centre "
                     "distance, masses and inertias (given or derived), mesh frequency at the rotor speed, static force "
                     "per mesh at the input torque (T / (n r_b)), the total ratio and the geometry checks."))
    show.add_argument("file", metavar="FILE", help="drivetrain TOML file or packaged name (e.g. grc-like, paper-table6)")
    show.add_argument("--json", action="store_true", help="print the table as JSON")
    show.add_argument("--rotor-speed-rpm", type=float, default=None,
                      help="rotor speed for the mesh frequencies [rpm] (default: the file's operating point)")
    show.add_argument("--torque-nm", type=float, default=None,
                      help="rotor (input) torque for the static forces [N m] (default: counter torque x total ratio)")
    show.set_defaults(func=run_show)
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])


def run_show(args: argparse.Namespace) -> int:
    """Print the design table."""
    from components.units import rpm

    from ..inputs.drivetrain_file import find_drivetrain, load_drivetrain_file
    from ..reports.drivetrain_table import format_design_table

    spec = load_drivetrain_file(find_drivetrain(args.file))
    speed = rpm(args.rotor_speed_rpm) if args.rotor_speed_rpm is not None else None
    table = spec.design_table(speed, args.torque_nm)
    if args.json:
        print(json.dumps({"source": spec.origin, **table.as_dict()}, indent=1))
    else:
        print(format_design_table(table, spec.origin))
    return 0
