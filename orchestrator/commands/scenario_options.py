"""Command-line options that change a scenario, shared by ``run`` and ``export-ssp``.

The rules are those of :mod:`orchestrator.inputs.overrides` (the same a study's
``[simulation]`` table follows): a changed analysis window is printed as a warning.
"""

from __future__ import annotations

import argparse
import sys

from ..inputs.master_options import ALGORITHMS, EXTRAPOLATIONS


def add_arguments(p: argparse.ArgumentParser) -> None:
    """``--step``, ``--stop``, ``--output-interval``, ``--algorithm``, ``--extrapolation``, ``--set``."""
    p.add_argument("--step", type=float, default=None, metavar="H", help="override the communication step [s]")
    p.add_argument("--stop", type=float, default=None, metavar="T",
                   help="override the stop time [s] (a window beyond it is clipped, with a warning)")
    p.add_argument("--output-interval", type=float, default=None, metavar="DT", help="override the sampling interval [s]")
    p.add_argument("--algorithm", choices=ALGORITHMS, default=None, help="override the master algorithm")
    p.add_argument("--extrapolation", choices=EXTRAPOLATIONS, default=None, help="override the input extrapolation")
    p.add_argument("--set", action="append", default=[], metavar="COMPONENT.PARAMETER=VALUE",
                   help="override a parameter value, e.g. --set wind.seed=7 (repeatable)")


def load(spec, args: argparse.Namespace, command: str):
    """The scenario ``spec`` names (TOML, SSP or packaged name), read with ``--step``/``--stop`` for an SSP that lacks them."""
    from ..inputs.scenario import find_scenario
    from ..run.runner import load_any

    def note(message: str) -> None:
        print(f"dtcosim {command}: note: {message}", file=sys.stderr)

    return load_any(find_scenario(spec), step_s=args.step, stop_s=args.stop, report=note)


def apply(scenario, args: argparse.Namespace, command: str):
    """The scenario with the options applied; notes of what else changed go to stderr as warnings."""
    from ..inputs.overrides import (
        SimulationOverrides,
        apply_parameters,
        parse_assignment,
    )

    overrides = SimulationOverrides(stop_s=args.stop, step_s=args.step, output_interval_s=args.output_interval,
                                    algorithm=args.algorithm, extrapolation=args.extrapolation)
    scenario, notes = overrides.apply(scenario)
    for note in notes:
        print(f"dtcosim {command}: warning: {note}", file=sys.stderr)
    return apply_parameters(scenario, dict(parse_assignment(item) for item in args.set))
