"""``dtcosim validate``: check built FMUs, and whether this environment (or a fresh one) can run them.

For every FMU: fmpy's validation and dtcosim's conventions (units, descriptions,
state handling, ``documentation/index.html`` and ``resources/requirements.txt``
present), then the FMU's declared requirements against this interpreter
(what is missing stops the FMU from starting and fails the check; a version
outside the tested range is a warning). ``--host`` also runs each FMU once in a
fresh virtual environment holding only its declared requirements and fmpy
(:mod:`fmus.selftest`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from fmus.requirements import check_environment, read_from_fmu
from fmus.validation import check_fmu, fmu_files

from ..cosim.fmu_folder import default_fmu_dir


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``validate`` subcommand."""
    p = sub.add_parser(
        "validate",
        help="validate FMUs (fmpy validation, conventions, declared requirements against this environment)",
        description=("Validate FMU files, or every *.fmu in the given directories, and check this environment "
                     "against each FMU's declared requirements; exit code 1 on any problem."),
    )
    p.add_argument("paths", nargs="*", type=Path, default=[default_fmu_dir()], metavar="PATH",
                   help="FMU files or directories holding them (default: the FMU directory `dtcosim run` uses)")
    p.add_argument("--host", action="store_true",
                   help="also run each FMU once through a bare fmpy loop in a fresh virtual environment that has "
                        "only the declared requirements (and fmpy) installed; needs pip access to the package index")
    p.add_argument("--venv", type=Path, default=None, metavar="DIR",
                   help="with --host: create (or reuse) the environment in DIR and keep it (default: a temporary one)")
    p.set_defaults(func=run)


def _environment_lines(path: Path) -> tuple[list[str], list[str]]:
    """(problems, warnings) of this interpreter against the FMU's declared requirements."""
    req = read_from_fmu(path)
    if req is None:
        return [], []
    check = check_environment(req)
    return [f"this environment cannot run it: {m}" for m in check.missing], list(check.warnings)


def run(args: argparse.Namespace) -> int:
    """Validate and print the problems; 0 if every FMU is valid and can run here, 1 otherwise."""
    files = fmu_files(args.paths)
    if not files:
        print(f"no FMU found in {', '.join(map(str, args.paths))}")
        return 1
    failed = 0
    valid = []
    for path in files:
        if not path.is_file():
            print(f"{path}: no such file")
            failed += 1
            continue
        problems = check_fmu(path)
        warnings: list[str] = []
        if not problems:
            problems, warnings = _environment_lines(path)
        if problems:
            failed += 1
            print(f"{path}: {len(problems)} problem(s)")
            for problem in problems:
                print(f"  - {problem}")
        else:
            req = read_from_fmu(path)
            print(f"{path}: ok (requires {req.summary()}; this environment has it)")
            valid.append(path)
        for warning in warnings:
            print(f"  warning: {warning}")
    if args.host and valid:
        failed += _host_self_test(valid, args.venv)
    return 1 if failed else 0


def _host_self_test(paths: list[Path], env_dir: Path | None) -> int:
    """Run the FMUs in a fresh environment; returns the number that failed."""
    from fmus.selftest import self_test

    where = env_dir if env_dir is not None else "a temporary virtual environment"
    print(f"host self-test: installing the declared requirements and fmpy into {where} ...", flush=True)
    failed = 0
    for result in self_test(paths, env_dir):
        imported = ", ".join(result.imports) or "nothing"
        if result.ok:
            print(f"{result.fmu}: host self-test ok (a bare fmpy loop without dtcosim; imports {imported}, all declared)")
        else:
            failed += 1
            print(f"{result.fmu}: host self-test FAILED: {result.error}")
            for message in result.messages:
                print(f"  log: {message}")
    return failed
