"""``dtcosim reference``: the paper's cases with the monolithic solver."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from components.reference.cases import CASES, TABLE7_PAPER, run_case


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``reference`` subcommand."""
    p = sub.add_parser(
        "reference",
        help="run a paper case (Table 2, Table 4, Fig. 10-11, Table 7) with the monolithic solver",
        description="Run one of the paper's cases with the monolithic (LSODA) reference solver and print its statistics.",
    )
    p.add_argument("--case", choices=sorted(CASES), default="table7", help="paper case (default: table7)")
    p.add_argument("--json", action="store_true", help="print a JSON object instead of a table")
    p.add_argument("--t-end", type=float, default=None, help="override the end time [s]")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="also write timeseries.csv, summary.json and reference.png (input speed and every "
                        "contact force, backlash intervals shaded: Fig. 10-11 for --case sine) into DIR")
    p.add_argument("--no-plots", action="store_true", help="with --out: no PNG")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the case and print statistics."""
    overrides = {} if args.t_end is None else {"t_end_s": args.t_end}
    start = time.perf_counter()
    result, stats = run_case(args.case, **overrides)
    wall = time.perf_counter() - start
    case = CASES[args.case]
    summary = {
        "case": args.case,
        "statistics": {k: {m: v[m] for m in ("mean", "std", "min", "max")} for k, v in stats.items()},
        "wall_time_s": wall,
        "solver_wall_time_s": result.wall_time_s,
        "complete": result.complete,
        "window_s": list(case.window_s),
    }
    if not result.complete:
        summary["message"] = result.message
    if result.energy is not None:
        summary["energy"] = result.energy.as_dict()
    if args.out is not None:
        from ..reports.reference_cases import write_reference_outputs

        files = write_reference_outputs(result, case, summary, args.out, plot=not args.no_plots)
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0 if result.complete else 1
    print(f"{case.name}: {case.description}")
    print(f"window {case.window_s[0]:g}-{case.window_s[1]:g} s, wall time {wall:.3f} s, complete: {result.complete}")
    print(f"{'variable':<24}{'mean':>14}{'std':>14}{'min':>14}{'max':>14}{'paper mean':>14}{'paper std':>14}")
    for name, st in stats.items():
        paper = TABLE7_PAPER.get(name) if args.case == "table7" else None
        pm, ps = (f"{paper[0]:14.5g}", f"{paper[1]:14.5g}") if paper else ("", "")
        if args.case != "table7" and name in case.paper:
            pm = f"{case.paper[name]:14.5g}"
        if args.case == "table4" and name.endswith(("sum_F_sp", "sum_F_rp")):
            pm = f"{case.paper['sum_F_sp']:14.5g}"
        print(f"{name:<24}{st['mean']:14.6g}{st['std']:14.6g}{st['min']:14.6g}{st['max']:14.6g}{pm:>14}{ps:>14}")
    if result.energy is not None:
        e = result.energy
        print(f"energy audit: input {e.input_work_j:.6g} J = output {e.output_work_j:.6g} + dissipated "
              f"{e.dissipated_j:.6g} + stored change {e.stored_change_j:.6g} (residual {e.relative_residual:.2e} of input)")
    if args.out is not None:
        print(f"results in {args.out}/: " + ", ".join(f.name for f in files))
    return 0 if result.complete else 1
