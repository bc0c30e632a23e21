"""``dtcosim modes [SCENARIO]``: modal analysis and Campbell diagram of a scenario's drivetrain or a preset.

With a scenario (packaged name, TOML or SSP file) the drivetrain is the one behind
its FMUs - the Gearbox FMU's effective parameters and the generator's inertia and
counter torque, rebuilt as for the monolithic reference
(:func:`orchestrator.cosim.physics_view.physics_view`: the FMUs' records with the scenario's values) - and the operating point is the
scenario's: the WindSource's mean rotor speed ``omega0`` and the generator's
base counter torque (load events and the wind's fluctuation are not part of a
linearisation). A scenario whose Gearbox a torque-driven Rotor FMU drives is analysed
with that rotor (and main shaft) free: the drivetrain's free-free torsion
(:mod:`components.analysis.rotor_coupling`), at the Rotor's initial speed.
``--rotor-speed-rpm`` and ``--torque-nm`` override speed and torque.
Without a scenario: ``--drivetrain FILE`` at the file's operating point and load, or
``--preset`` (default table6) at 16 rpm and the preset's load.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from components.analysis.equilibrium import OperatingPoint
from components.analysis.load_law import LOAD_LAWS, LoadLaw
from components.analysis.settling import settling_time
from components.errors import ParameterError
from components.model.presets import PRESETS, preset
from components.units import rpm

from .catalogue import help_line
from .fmu_options import add_fmu_arguments


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``modes`` subcommand."""
    p = sub.add_parser(
        "modes",
        help=help_line("modes"),
        description=(
            "Linearise the drivetrain about its static equilibrium at a rotor speed and generator "
            "torque (same matrices as the simulation), print the modal table and write modes.csv, "
            "modes.json, modes.png, campbell.csv, campbell_crossings.csv and campbell.png."
        ),
    )
    p.add_argument("scenario", nargs="?", default=None, metavar="SCENARIO",
                   help="take drivetrain and operating point from this scenario (TOML/SSP file or packaged name, "
                        "e.g. paper-60s); default: --preset")
    p.add_argument("--preset", choices=PRESETS, default=None, help="drivetrain preset without a scenario (default: table6)")
    p.add_argument("--drivetrain", default=None, metavar="FILE",
                   help="drivetrain file (TOML path or packaged name, e.g. grc-like) without a scenario, at its "
                        "operating point (rotor speed) and its counter torque")
    p.add_argument("--rotor-speed-rpm", type=float, default=None,
                   help="rotor speed of the operating point [rpm] (default: the scenario's omega0, the drivetrain file's, else 16)")
    p.add_argument("--torque-nm", type=float, default=None,
                   help="output (generator) counter torque [N m] (default: the scenario's or the preset's, 25400 for table6)")
    add_fmu_arguments(p, "a scenario's", build=False)
    p.add_argument("--out", default=None,
                   help="output directory (default: results/<scenario>/modes with a scenario, else results/modes)")
    p.add_argument("--load-law", choices=LOAD_LAWS, default="quadratic",
                   help="Campbell load law: torque ~ speed^2 up to the operating point, constant above (quadratic), "
                        "or the operating torque at every speed (constant)")
    p.add_argument("--speed-range", type=float, nargs=2, default=(4.0, 20.0), metavar=("LOW", "HIGH"),
                   help="Campbell rotor-speed range [rpm] (default 4 20)")
    p.add_argument("--speed-points", type=int, default=33, help="Campbell speed points (default 33)")
    p.add_argument("--shapes", type=int, default=8, help="modes drawn in modes.png (default 8)")
    p.add_argument("--free-input", action="store_true",
                   help="with --drivetrain or --preset: the stage-1 input member free and no rotor on it (a gearbox "
                        "on its own, as in Lin and Parker's free vibration; its rigid-body rotation removed); "
                        "default: held at the rotor speed")
    p.add_argument("--verify", action="store_true",
                   help="also simulate the free response after an impulse and compare every underdamped mode")
    p.set_defaults(func=run)


def scenario_drivetrain(spec: str, fmu_dir: Path | None = None):
    """Drivetrain, rotor, operating point and where it came from, and the scenario name of a scenario.

    Its FMUs are built if missing. The rotor is held where the Gearbox's rotor speed is
    prescribed (a WindSource: at the wind's mean speed; a recorded speed: at the speed its
    initialisation gives the Gearbox) and free where a torque-driven Rotor FMU drives it (at
    the speed the initialisation gives). The output torque is the Gearbox's initial
    ``counter_torque`` where a generator or controller sets it, else the generator's counter torque.

    Returns
    -------
    drivetrain : components.model.drivetrain.Drivetrain
        With the generator's inertia and base counter torque (no load events).
    rotor : components.model.rotor.RotorParameters or None
        The torque-driven rotor; None: held.
    operating_point : components.analysis.equilibrium.OperatingPoint
    source : str
        Where speed and torque came from.
    name : str
    """
    from ..cosim.operating_point import drivetrain_at_start
    from ..cosim.physics_view import PhysicsUnavailable
    from ..cosim.system import resolve_system
    from ..errors import ScenarioError
    from ..inputs.scenario_file import find_scenario
    from ..provision.project_fmus import ensure_fmus
    from ..run.runner import load_any

    scenario = load_any(find_scenario(spec))
    system = resolve_system(scenario, fmu_paths=ensure_fmus(scenario, fmu_dir, build=True))
    try:
        start = drivetrain_at_start(system)
    except PhysicsUnavailable as exc:
        raise ScenarioError("(scenario)", scenario.name, f"a scenario with a dtcosim drivetrain ({exc})") from None
    return start.drivetrain, start.rotor, start.operating_point, start.source, scenario.name


def run(args: argparse.Namespace) -> int:
    """Run the modal analysis and write the files."""
    if sum(x is not None for x in (args.scenario, args.preset, args.drivetrain)) > 1:
        raise ParameterError("--preset/--drivetrain", args.preset or args.drivetrain,
                             "one of SCENARIO, --preset and --drivetrain")
    rotor = None
    if args.drivetrain is not None:
        from ..inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

        spec = load_drivetrain_file(find_drivetrain(args.drivetrain))
        drivetrain, origin = spec.drivetrain, spec.origin
        op = OperatingPoint.of_drivetrain(drivetrain, spec.rotor_speed_rad_s)
        source = "the file's operating point and counter torque"
        out_dir = args.out if args.out is not None else Path("results") / spec.name / "modes"
    elif args.scenario is not None:
        drivetrain, rotor, op, source, name = scenario_drivetrain(args.scenario, args.fmu_dir)
        origin = f"scenario {name}"
        out_dir = args.out if args.out is not None else Path("results") / name / "modes"
    else:
        name = args.preset or "table6"
        drivetrain, origin = preset(name), f"preset {name}"
        op = OperatingPoint.of_drivetrain(drivetrain, rpm(16.0))
        source = "the paper's rated speed and the preset's load"
        out_dir = args.out if args.out is not None else Path("results") / "modes"
    if args.rotor_speed_rpm is not None or args.torque_nm is not None:
        op = OperatingPoint(rpm(args.rotor_speed_rpm) if args.rotor_speed_rpm is not None else op.rotor_speed_rad_s,
                            args.torque_nm if args.torque_nm is not None else op.output_torque_nm)
        source += " (overridden on the command line)"
    speed = op.rotor_speed_rad_s
    lo, hi = args.speed_range
    if not 0.0 < lo < hi:
        raise ParameterError("speed_range", (lo, hi), "0 < LOW < HIGH [rpm]")
    if args.speed_points < 2:
        raise ParameterError("speed_points", args.speed_points, ">= 2")
    law = LoadLaw(args.load_law, abs(speed) if speed != 0.0 else rpm(16.0), op.output_torque_nm)
    from ..reports.modal import (  # matplotlib: only to run
        format_mode_table,
        format_verification,
        modal_report,
    )

    if args.verify and (rotor is not None or args.free_input):
        raise ParameterError("--verify", True, "a held rotor (a prescribed speed): the free-response "
                             "check simulates the drivetrain at a prescribed rotor speed")
    if args.free_input and args.scenario is not None:
        raise ParameterError("--free-input", True, "--drivetrain or --preset (a scenario's rotor is held by its "
                             "source or driven by its Rotor)")
    report = modal_report(
        drivetrain, op, out_dir, law, rpm(np.linspace(lo, hi, args.speed_points)), args.shapes, args.verify, rotor,
        args.free_input,
    )
    an = report["analysis"]
    eq = an.model.equilibrium
    print(f"dtcosim modes: {origin} at {op.rotor_speed_rpm:.6g} rpm, output torque {op.output_torque_nm:.6g} N m "
          f"({source})")
    if args.free_input:
        print("input member free, no rotor (rigid-body rotation removed): the modes of the gearbox on its own")
    elif rotor is None:
        print("rotor held at the operating speed (a prescribed speed): the modes of the drivetrain between a held "
              "rotor and the generator")
    else:
        shaft = (f", main shaft {rotor.shaft_stiffness_nm_rad:.6g} N m/rad" if rotor.has_shaft else
                 ", rigid main shaft")
        print(f"torque-driven rotor {rotor.inertia_kgm2:.6g} kg m^2{shaft}: the drivetrain is free at both ends "
              "(rigid-body rotation removed; generator torque held constant)")
    print(f"static equilibrium: residual {eq.residual_nm:.2g} N m after {eq.iterations} Newton iteration(s) "
          f"from the secant-stiffness start; rotor torque {eq.rotor_torque_nm:.6g} N m")
    print(format_mode_table(an))
    n_under = len(an.underdamped)
    print(f"{n_under} underdamped mode(s), {len(an.modes) - n_under} overdamped; "
          f"real eigenvalues (overdamped roots): {len(an.overdamped_roots_per_s)}")
    try:
        print(f"settling time (where an analysis window should start after the run's start): "
              f"{settling_time(an).describe()}")
    except ValueError as exc:
        print(f"settling time: none ({exc})")
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
