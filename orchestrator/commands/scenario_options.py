"""Command-line options that change a scenario, shared by ``run`` and ``export-ssp``.

The rules are those of :mod:`orchestrator.inputs.overrides` (the same a study's
``[simulation]`` table follows): a changed analysis window is printed as a warning.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

from ..inputs.master_options import ALGEBRAIC_LOOPS, ALGORITHMS, EXTRAPOLATIONS


def add_arguments(p: argparse.ArgumentParser) -> None:
    """``--step``, ``--stop``, ``--window``, ``--output-interval``, ``--algorithm``, ``--extrapolation``, ``--set``,
    ``--allow-implausible``, ``--algebraic-loops``, ``--no-feedthrough``."""
    p.add_argument("--step", type=float, default=None, metavar="H", help="override the communication step [s]")
    p.add_argument("--stop", type=float, default=None, metavar="T",
                   help="override the stop time [s] (a window beyond it is clipped, a window that ended at the "
                        "scenario's stop follows a later one; both with a warning)")
    p.add_argument("--window", type=float, nargs=2, default=None, metavar=("START", "END"),
                   help="override the analysis window [s] (statistics, fatigue, contact loss)")
    p.add_argument("--output-interval", type=float, default=None, metavar="DT", help="override the sampling interval [s]")
    p.add_argument("--algorithm", choices=ALGORITHMS, default=None, help="override the master algorithm")
    p.add_argument("--extrapolation", choices=EXTRAPOLATIONS, default=None, help="override the input extrapolation")
    p.add_argument("--set", action="append", default=[], metavar="COMPONENT.PARAMETER=VALUE",
                   help="override a parameter value, e.g. --set wind.seed=7 (repeatable)")
    add_allow_argument(p, "the scenario")
    p.add_argument("--algebraic-loops", choices=ALGEBRAIC_LOOPS, default=None,
                   help="override what the master does with an algebraic loop: refuse it, or iterate it at every "
                        "communication point ([simulation] algebraic_loops)")
    p.add_argument("--no-feedthrough", action="append", default=[], metavar="COMPONENT[.OUTPUT]",
                   help="an output (or, with COMPONENT alone, every output without declared dependencies) that "
                        "does not depend directly on the FMU's inputs, for FMUs whose model description does not "
                        "say (repeatable; [components.X] no_feedthrough)")


def add_allow_argument(p: argparse.ArgumentParser, where: str) -> None:
    """``--allow-implausible COMPONENT.PARAMETER`` (repeatable): what ``[plausibility] allow`` in ``where`` keeps."""
    p.add_argument("--allow-implausible", action="append", default=[], metavar="COMPONENT.PARAMETER",
                   help="keep a value physics calls implausible (a deliberate study), e.g. --allow-implausible "
                        f"gearbox.stage1.backlash (repeatable; [plausibility] allow in {where})")


def load(spec, args: argparse.Namespace, command: str):
    """The scenario ``spec`` names (TOML, SSP or packaged name), read with ``--step``/``--stop`` for an SSP that lacks them."""
    from ..inputs.scenario_file import find_scenario
    from ..run.runner import load_any

    def note(message: str) -> None:
        print(f"dtcosim {command}: note: {message}", file=sys.stderr)

    scenario = load_any(find_scenario(spec), step_s=args.step, stop_s=args.stop, report=note)
    for comp in scenario.components:
        if comp.series is not None:
            used = {c.source.variable for c in scenario.connections if c.source.component == comp.name}
            for warning in comp.series.warnings(used):
                print(f"dtcosim {command}: warning: {warning}", file=sys.stderr)
    return scenario


def apply(scenario, args: argparse.Namespace, command: str):
    """The scenario with the options applied; notes of what else changed go to stderr as warnings."""
    from ..inputs.overrides import SimulationOverrides, apply_assignments

    overrides = SimulationOverrides(stop_s=args.stop, step_s=args.step, output_interval_s=args.output_interval,
                                    window_s=args.window, algorithm=args.algorithm, extrapolation=args.extrapolation)
    scenario, notes = overrides.apply(scenario)
    for note in notes:
        print(f"dtcosim {command}: warning: {note}", file=sys.stderr)
    if args.algebraic_loops is not None:
        scenario = scenario.with_simulation(algebraic_loops=args.algebraic_loops)
    for item in args.no_feedthrough:
        scenario = scenario.with_no_feedthrough(item.strip())
    scenario = allow_implausible(scenario, args.allow_implausible)
    return apply_assignments(scenario, args.set)


def allow_implausible(target, keys: list[str]):
    """A scenario, study or load-case set that also keeps the ``--allow-implausible`` keys."""
    keys = [k.strip() for k in keys]
    return target.with_allowed(*keys) if keys else target


def given_overrides(args: argparse.Namespace) -> list[str]:
    """The scenario-changing options on the command line, as typed (``["--stop 3", "--set wind.seed=7"]``)."""
    out = []
    for option, value in (("--stop", args.stop), ("--step", args.step), ("--output-interval", args.output_interval),
                          ("--algorithm", args.algorithm), ("--extrapolation", args.extrapolation),
                          ("--algebraic-loops", args.algebraic_loops)):
        if value is not None:
            out.append(f"{option} {value:g}" if isinstance(value, float) else f"{option} {value}")
    if args.window is not None:
        out.append(f"--window {args.window[0]:g} {args.window[1]:g}")
    out += [f"--set {item.strip()}" for item in args.set]
    out += [f"--no-feedthrough {item.strip()}" for item in args.no_feedthrough]
    return out


def default_out_dir(scenario, args: argparse.Namespace) -> tuple[Path, str]:
    """``results/<scenario>``; with overrides ``results/<scenario>-<8 hex digits of the overrides>``, and a note.

    A run with changed settings never replaces the scenario's own results: the
    same overrides always go to the same folder, and the note (printed by the
    command) says where.
    """
    base = Path("results") / scenario.name
    overrides = given_overrides(args)
    if not overrides:
        return base, ""
    digest = hashlib.sha256(json.dumps(sorted(overrides)).encode()).hexdigest()[:8]
    out = Path("results") / f"{scenario.name}-{digest}"
    return out, (f"{', '.join(overrides)} change the scenario: results go to {out}/ ({base}/ is for the scenario "
                 "as written; --out chooses another folder)")


def previous_run(out_dir: Path) -> str:
    """What a previous run left in ``out_dir`` (``"paper-60s, complete, started 2026-..."``), "" if nothing."""
    try:
        summary = json.loads((Path(out_dir) / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return ""
    if not isinstance(summary, dict) or "scenario" not in summary:
        return ""
    state = summary.get("status") or ("complete" if summary.get("complete") else "incomplete")
    started = f", started {summary['started_at']}" if summary.get("started_at") else ""
    return f"scenario {summary.get('scenario')}, {state}{started}"
