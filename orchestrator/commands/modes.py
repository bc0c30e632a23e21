"""``dtcosim modes``: modal analysis and Campbell diagram of a drivetrain preset."""

from __future__ import annotations

import argparse

import numpy as np

from components.campbell import LOAD_LAWS, LoadLaw
from components.errors import ParameterError
from components.modes import OperatingPoint
from components.presets import PRESETS, preset
from components.units import rpm

from ..modal_report import format_mode_table, format_verification, modal_report


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``modes`` subcommand."""
    p = sub.add_parser(
        "modes",
        help="natural frequencies, damping and mode shapes at an operating point; Campbell diagram",
        description=(
            "Linearise the drivetrain about its static equilibrium at a rotor speed and generator "
            "torque (same matrices as the simulation), print the modal table and write modes.csv, "
            "modes.json, modes.png, campbell.csv, campbell_crossings.csv and campbell.png."
        ),
    )
    p.add_argument("--preset", choices=PRESETS, default="table6", help="drivetrain preset (default: table6)")
    p.add_argument("--rotor-speed-rpm", type=float, default=16.0, help="rotor speed of the operating point [rpm] (default 16)")
    p.add_argument("--torque-nm", type=float, default=None,
                   help="output (generator) counter torque [N m] (default: the preset's, 25400 for table6)")
    p.add_argument("--out", default="results/modes", help="output directory (default: results/modes)")
    p.add_argument("--load-law", choices=LOAD_LAWS, default="quadratic",
                   help="Campbell load law: torque ~ speed^2 up to the operating point, constant above (quadratic), "
                        "or the operating torque at every speed (constant)")
    p.add_argument("--speed-range", type=float, nargs=2, default=(4.0, 20.0), metavar=("LOW", "HIGH"),
                   help="Campbell rotor-speed range [rpm] (default 4 20)")
    p.add_argument("--speed-points", type=int, default=33, help="Campbell speed points (default 33)")
    p.add_argument("--shapes", type=int, default=8, help="modes drawn in modes.png (default 8)")
    p.add_argument("--verify", action="store_true",
                   help="also simulate the free response after an impulse and compare every underdamped mode")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the modal analysis and write the files."""
    drivetrain = preset(args.preset)
    speed = rpm(args.rotor_speed_rpm)
    op = OperatingPoint(speed, args.torque_nm) if args.torque_nm is not None else OperatingPoint.of_drivetrain(drivetrain, speed)
    lo, hi = args.speed_range
    if not 0.0 < lo < hi:
        raise ParameterError("speed_range", (lo, hi), "0 < LOW < HIGH [rpm]")
    if args.speed_points < 2:
        raise ParameterError("speed_points", args.speed_points, ">= 2")
    law = LoadLaw(args.load_law, abs(speed) if speed != 0.0 else rpm(16.0), op.output_torque_nm)
    report = modal_report(
        drivetrain, op, args.out, law, rpm(np.linspace(lo, hi, args.speed_points)), args.shapes, args.verify
    )
    an = report["analysis"]
    eq = an.model.equilibrium
    print(f"dtcosim modes: preset {args.preset} at {op.rotor_speed_rpm:g} rpm, output torque {op.output_torque_nm:g} N m")
    print(f"static equilibrium: residual {eq.residual_nm:.2g} N m after {eq.iterations} Newton iteration(s) "
          f"from the secant-stiffness start; rotor torque {eq.rotor_torque_nm:.6g} N m")
    print(format_mode_table(an))
    n_under = len(an.underdamped)
    print(f"{n_under} underdamped mode(s), {len(an.modes) - n_under} overdamped; "
          f"real eigenvalues (overdamped roots): {len(an.overdamped_roots_per_s)}")
    crossings = [c for c in report["campbell"].crossings() if not c["overdamped"]]
    if crossings:
        print("Campbell crossings of underdamped modes (" + report["campbell"].load_law.describe() + "):")
        for c in crossings:
            print(f"  mode {c['mode']} x {c['excitation']} at {c['rotor_speed_rpm']:.4g} rpm, {c['frequency_hz']:.4g} Hz, "
                  f"zeta {c['damping_ratio']:.3g}")
    if report["verification"] is not None:
        print("free response after an impulse (nonlinear monolithic model) vs linearised damped frequency:")
        print(format_verification(report["verification"]))
    for name, path in report["files"].items():
        print(f"wrote {path}")
    return 0
