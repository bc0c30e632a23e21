"""``dtcosim validate``: check FMUs (any FMU, not only dtcosim's), and whether this environment can run them.

For every FMU: fmpy's validation; what dtcosim's master needs (FMI 2.0,
co-simulation, a binary for this platform); for an FMU dtcosim built also its
conventions (units, descriptions, state handling, ``documentation/index.html``
and ``resources/requirements.txt`` present) and its declared requirements against
this interpreter (what is missing stops the FMU from starting and fails the
check; a version outside the tested range is a warning). A file that is not a
zip or has a broken ``modelDescription.xml`` is reported as such, without a
traceback. An SSP (an ``.ssp`` archive, an ``.ssd`` file or an SSP folder) is checked as
``dtcosim run --check`` checks it (its SSD against its FMUs' model descriptions; nothing is
instantiated), then every FMU it holds is validated as above, named ``<file>.ssp!<member>``.
``--cross-check RESULT.csv`` compares another host's run of an FMU with the
reference it carries (:mod:`fmus.cross_check`). ``--host`` also runs each valid dtcosim FMU once in a fresh virtual
environment holding only its declared requirements and fmpy (:mod:`fmus.selftest`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from fmus.requirements import check_environment, read_from_fmu
from fmus.validation import check_fmu, fmu_files, is_dtcosim_fmu

from ..archive_members import shown_path
from ..provision.folders import default_fmu_dir
from .catalogue import help_line


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``validate`` subcommand."""
    p = sub.add_parser(
        "validate",
        help=help_line("validate"),
        description=("Validate FMU files, or every *.fmu in the given directories, and check this environment "
                     "against each FMU's declared requirements; exit code 1 on any problem."),
    )
    p.add_argument("paths", nargs="*", type=Path, default=[default_fmu_dir()], metavar="PATH",
                   help="FMU files or directories holding them, or SSPs (.ssp, .ssd or an SSP folder: the system as "
                        "`dtcosim run --check` checks it, then every FMU in it) (default: the FMU directory "
                        "`dtcosim run` uses)")
    p.add_argument("--step", type=float, default=None, metavar="H",
                   help="communication step [s] for an SSP that gives none (as for `dtcosim run`)")
    p.add_argument("--stop", type=float, default=None, metavar="T",
                   help="stop time [s] for an SSP that gives none (as for `dtcosim run`)")
    p.add_argument("--host", action="store_true",
                   help="also run each FMU once through a bare fmpy loop in a fresh virtual environment that has "
                        "only the declared requirements (and fmpy) installed; needs pip access to the package index")
    p.add_argument("--venv", type=Path, default=None, metavar="DIR",
                   help="with --host: create (or reuse) the environment in DIR and keep it (default: a temporary one)")
    p.add_argument("--cross-check", type=Path, default=None, metavar="RESULT.csv", dest="cross_check",
                   help="compare another host's run of the FMU (one FMU path) with the reference the FMU carries in "
                        "documentation/cross-check/ (FMI Cross-Check layout: run <Model>_in.csv with the options of "
                        "<Model>_ref.opt, write every output as CSV); exit code 1 if it differs")
    p.add_argument("--rel-tol", type=float, default=None, metavar="R",
                   help="with --cross-check: largest deviation of an output relative to its reference's range "
                        "(default: RelTol of <Model>_ref.opt, 1e-4)")
    p.set_defaults(func=run)


def _cross_check(fmu: Path, result: Path, rel_tol: float | None) -> int:
    """Print the comparison of a host's result with the FMU's reference; 0 if it passed, 1 otherwise."""
    from fmus.cross_check import compare

    report = compare(fmu, result, rel_tol)
    rule = "passed" if report.rule_problem is None else f"FAILED: {report.rule_problem}"
    print(f"{fmu} against {result}: FMI Cross-Check rule (10 % band, at most 10 % of samples outside) {rule}")
    if report.missing:
        print(f"  missing outputs: {', '.join(report.missing)}")
    worst = report.worst
    if worst is not None:
        over = [d for d in report.deviations if d.relative > report.rel_tol]
        print(f"  largest deviation: {worst.name} {worst.max_abs:.3g} = {worst.relative:.3g} of its reference's range "
              f"(bound {report.rel_tol:g}); {len(over)} of {len(report.deviations)} outputs over it"
              + (f": {', '.join(d.name for d in over[:8])}{' ...' if len(over) > 8 else ''}" if over else ""))
    print(f"{fmu}: cross-check {'passed' if report.passed else 'FAILED'}")
    return 0 if report.passed else 1


def _environment_lines(path: Path) -> tuple[list[str], list[str]]:
    """(problems, warnings) of this interpreter against the FMU's declared requirements."""
    req = read_from_fmu(path)
    if req is None:
        return [], []
    check = check_environment(req)
    return [f"this environment cannot run it: {m}" for m in check.missing], list(check.warnings)


def _host_problems(path: Path) -> list[str]:
    """What dtcosim's master needs of any FMU: FMI 2.0 co-simulation with a binary for this platform."""
    from ..cosim.fmu_interface import read_fmu_interface
    from ..errors import ScenarioError

    try:
        read_fmu_interface(path, "fmu")  # refuses an FMU without a binary for this platform
    except ScenarioError as exc:
        return [f"dtcosim cannot run it: expected {exc.expected}"]
    return []


def _describe(path: Path) -> str:
    from ..cosim.fmu_interface import read_fmu_interface

    iface = read_fmu_interface(path, "fmu")
    req = read_from_fmu(path)
    what = f"FMI {iface.fmi_version} co-simulation, {iface.generation_tool or 'unknown tool'}, binaries for " \
           f"{', '.join(iface.platforms)}"
    return what + (f"; requires {req.summary()}; this environment has it" if req is not None else "")


def _check_ssp(path: Path, args: argparse.Namespace) -> list[Path] | None:
    """Check an SSP as ``dtcosim run --check`` does and print the outcome; its FMU files, None if it failed."""
    from components.errors import DtcosimError

    from . import scenario_options
    from .run import check_report, checked_system

    try:
        scenario = scenario_options.load(path, args, "validate")
        system = checked_system(scenario, None, False, "validate", lambda message: None)
    except DtcosimError as exc:
        print(f"{path}: 1 problem(s)\n  - {exc}")
        return None
    print(check_report(system, str(path)))
    return list(dict.fromkeys(system.fmu_paths.values()))  # a file two components share: once


def _validate_fmu(path: Path) -> bool:
    """Validate one FMU file and print the outcome; True if it is valid and can run here."""
    shown = shown_path(path)  # an FMU of an SSP as <file>.ssp!<member>
    if not path.is_file():
        print(f"{shown}: {'not a regular file (a device, pipe or folder)' if path.exists() else 'no such file'}")
        return False
    problems = check_fmu(path)
    warnings: list[str] = []
    if not problems:
        problems = _host_problems(path)
    if not problems:
        problems, warnings = _environment_lines(path)
    if problems:
        print(f"{shown}: {len(problems)} problem(s)")
        for problem in problems:
            print(f"  - {problem}")
    else:
        print(f"{shown}: ok ({_describe(path)})")
    for warning in warnings:
        print(f"  warning: {warning}")
    return not problems


def run(args: argparse.Namespace) -> int:
    """Validate and print the problems; 0 if every FMU and SSP is valid and can run here, 1 otherwise."""
    from ..interop.ssp import is_ssp

    if args.cross_check is not None:
        ssps = [p for p in args.paths if is_ssp(p)]
        files = fmu_files(p for p in args.paths if not is_ssp(p))
        if len(files) != 1 or ssps:
            print(f"--cross-check compares one FMU with one result: give one FMU path (found {len(files)}"
                  + (f" and the SSP {ssps[0]})" if ssps else ")"))
            return 1
        return _cross_check(files[0], args.cross_check, args.rel_tol)
    failed, valid, found = 0, [], False
    for given in args.paths:  # in the order given; an SSP's FMUs after its system's line
        if is_ssp(given):
            held = _check_ssp(given, args)
            failed += held is None
            files, found = held or [], True
        else:
            files = fmu_files([given])
            found = found or bool(files)
        for path in files:
            if not _validate_fmu(path):
                failed += 1
            elif is_dtcosim_fmu(path):
                valid.append(path)
    if not found:
        print(f"no FMU found in {', '.join(map(str, args.paths))}")
        return 1
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
