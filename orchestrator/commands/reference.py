"""``dtcosim reference``: the paper's cases with the monolithic solver."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from components.reference.cases import CASES, TABLE7_PAPER

from .catalogue import help_line


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``reference`` subcommand."""
    p = sub.add_parser(
        "reference",
        help=help_line("reference"),
        description="Run one of the paper's cases with the monolithic (LSODA) reference solver and print its statistics.",
    )
    p.add_argument("--case", choices=sorted(CASES), default=None, help="paper case (default: table7)")
    p.add_argument("--drivetrain", default=None, metavar="FILE",
                   help="a drivetrain file (TOML path or packaged name) instead of a paper case: runs a constant-speed "
                        "constant-load case (10 s) and a wind case (60 s) at its operating point")
    p.add_argument("--file-case", choices=("constant", "wind", "both"), default="both",
                   help="with --drivetrain: which case to run (default both)")
    p.add_argument("--rotor-speed-rpm", type=float, default=None,
                   help="with --drivetrain: rotor speed [rpm] (default: the file's operating point)")
    p.add_argument("--json", action="store_true", help="print a JSON object instead of a table")
    p.add_argument("--t-end", type=float, default=None, help="override the end time [s]")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="also write timeseries.csv, summary.json and reference.png (input speed and every "
                        "contact force, backlash intervals shaded: Fig. 10-11 for --case sine) into DIR")
    p.add_argument("--no-plots", action="store_true", help="with --out: no PNG")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the case(s) and print statistics."""
    if args.drivetrain is None:
        args.case = args.case or "table7"
        return _run_one(args, CASES[args.case], args.out)
    if args.case is not None:
        from components.errors import ParameterError

        raise ParameterError("--case", args.case, "no paper case together with --drivetrain")
    from components.reference.cases import drivetrain_cases
    from components.units import rpm

    from ..inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

    spec = load_drivetrain_file(find_drivetrain(args.drivetrain))
    speed = rpm(args.rotor_speed_rpm) if args.rotor_speed_rpm is not None else spec.rotor_speed_rad_s
    cases = drivetrain_cases(spec.name, spec.drivetrain, speed)
    chosen = list(cases) if args.file_case == "both" else [args.file_case]
    table = spec.design_table(speed)
    if args.json:
        print("[")
    status = 0
    for i, key in enumerate(chosen):
        out = args.out / key if args.out is not None and len(chosen) > 1 else args.out
        status = max(status, _run_one(args, cases[key], out, table, spec.origin))
        if args.json:
            print("," if i + 1 < len(chosen) else "]")
    return status


def _static_forces(table) -> dict[str, float]:
    """Static force per mesh series name of the design table (``stage1.F_sp[2]`` -> T_sun / (n r_b))."""
    out = {}
    for st in table.stages:
        for m in st.meshes:
            if m.kind == "parallel":
                out[f"{st.name}.F_mesh"] = m.static_force_n
            else:
                tag = "F_sp" if m.kind == "sun_planet" else "F_rp"
                out.update({f"{st.name}.{tag}[{i + 1}]": m.static_force_n for i in range(m.count)})
    return out


def _run_one(args: argparse.Namespace, case, out_dir, table=None, origin: str = "") -> int:
    """Run one case and print (or write) its statistics."""
    from components.reference.cases import run_reference_case

    overrides = {} if args.t_end is None else {"t_end_s": args.t_end}
    start = time.perf_counter()
    result, stats = run_reference_case(case, **overrides)
    wall = time.perf_counter() - start
    static = _static_forces(table) if table is not None else {}
    summary = {
        "case": case.name,
        "statistics": {k: {m: v[m] for m in ("mean", "std", "min", "max")} for k, v in stats.items()},
        "wall_time_s": wall,
        "solver_wall_time_s": result.wall_time_s,
        "complete": result.complete,
        "window_s": list(case.window_s),
    }
    if origin:
        summary["drivetrain"] = origin
    if static:
        summary["static_force_n"] = {k: v for k, v in static.items() if k in stats}
    if not result.complete:
        summary["message"] = result.message
    if result.energy is not None:
        summary["energy"] = result.energy.as_dict()
    if out_dir is not None:
        from ..reports.reference_cases import write_reference_outputs

        files = write_reference_outputs(result, case, summary, out_dir, plot=not args.no_plots)
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0 if result.complete else 1
    print(f"{case.name}: {case.description}" + (f" [{origin}]" if origin else ""))
    print(f"window {case.window_s[0]:g}-{case.window_s[1]:g} s, wall time {wall:.3f} s, complete: {result.complete}")
    if static:
        print(f"{'variable':<28}{'mean':>14}{'std':>14}{'min':>14}{'max':>14}{'static':>14}{'mean/static-1':>15}")
        for name, st in stats.items():
            ref = static.get(name)
            extra = f"{ref:14.6g}{st['mean'] / ref - 1.0:15.2e}" if ref else ""
            print(f"{name:<28}{st['mean']:14.6g}{st['std']:14.6g}{st['min']:14.6g}{st['max']:14.6g}{extra}")
    else:
        print(f"{'variable':<24}{'mean':>14}{'std':>14}{'min':>14}{'max':>14}{'paper mean':>14}{'paper std':>14}")
    for name, st in stats.items() if not static else ():
        paper = TABLE7_PAPER.get(name) if case.name == "table7" else None
        pm, ps = (f"{paper[0]:14.5g}", f"{paper[1]:14.5g}") if paper else ("", "")
        if case.name != "table7" and name in case.paper:
            pm = f"{case.paper[name]:14.5g}"
        if case.name == "table4" and name.endswith(("sum_F_sp", "sum_F_rp")):
            pm = f"{case.paper['sum_F_sp']:14.5g}"
        print(f"{name:<24}{st['mean']:14.6g}{st['std']:14.6g}{st['min']:14.6g}{st['max']:14.6g}{pm:>14}{ps:>14}")
    if result.energy is not None:
        e = result.energy
        print(f"energy audit: input {e.input_work_j:.6g} J = output {e.output_work_j:.6g} + dissipated "
              f"{e.dissipated_j:.6g} + stored change {e.stored_change_j:.6g} (residual {e.relative_residual:.2e} of input)")
    if out_dir is not None:
        print(f"results in {out_dir}/: " + ", ".join(f.name for f in files))
    return 0 if result.complete else 1
