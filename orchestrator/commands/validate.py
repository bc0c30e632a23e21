"""``dtcosim validate``: check built FMUs with fmpy's validation and dtcosim's conventions."""

from __future__ import annotations

import argparse
from pathlib import Path

from fmus.validation import check_fmu, fmu_files

from ..cosim.system import default_fmu_dir


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``validate`` subcommand."""
    p = sub.add_parser(
        "validate",
        help="validate FMUs (fmpy validation plus units, descriptions and state support)",
        description="Validate FMU files, or every *.fmu in the given directories; exit code 1 on any problem.",
    )
    p.add_argument("paths", nargs="*", type=Path, default=[default_fmu_dir()], metavar="PATH",
                   help="FMU files or directories holding them (default: the FMU directory `dtcosim run` uses)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Validate and print the problems; 0 if every FMU is valid, 1 otherwise."""
    files = fmu_files(args.paths)
    if not files:
        print(f"no FMU found in {', '.join(map(str, args.paths))}")
        return 1
    failed = 0
    for path in files:
        if not path.is_file():
            print(f"{path}: no such file")
            failed += 1
            continue
        problems = check_fmu(path)
        if problems:
            failed += 1
            print(f"{path}: {len(problems)} problem(s)")
            for problem in problems:
                print(f"  - {problem}")
        else:
            print(f"{path}: ok")
    return 1 if failed else 0
