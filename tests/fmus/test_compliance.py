"""Issue 32.3: every FMU dtcosim builds passes independent FMI 2.0 checks with 0 warnings and 0 errors.

What runs here (the FMI Compliance Checker's sources are not on this machine; see docs/hosts.md):

* ``fmutool -input X.fmu -check`` of the PyPI package ``fmu-manipulation-toolbox`` (not dtcosim's, not fmpy's):
  ``modelDescription.xml`` against the FMI 2.0 XSD schemas it bundles, then its semantic rules of FMI 2.0.5
  (sections 2.2.7-2.2.8: unique names, causality/variability/initial combinations, start values, every output
  in ``<Outputs>``, dependencies that refer to variables); every WARNING or ERROR line counts;
* fmpy's ``validate_fmu`` (its own schema and rules);
* a run in fmpy as the host with logging on (``loggingOn``, every category), over the FMU's own cross-check
  inputs: every message the FMU logs with status warning or worse, and every FMI call that returns other than
  fmi2OK, counts;
* the FMI Compliance Checker itself (``fmuCheck.linux64``) where it is built: on PATH or named by
  ``$DTCOSIM_FMUCHECK``; skipped otherwise.

"Every FMU": the five built from the paper's preset, a TimeSeriesSource built from a record, an FMU copy
with the start values ``dtcosim export-ssp`` writes into an archive, and the Gearbox of the lateral-torsional
``paper-table6-lateral`` (its displacement and bearing outputs).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from fmus.build import PRESET_FMU_NAMES, build_fmu
from fmus.cross_check import MEMBER_DIR
from fmus.registry import FMU_NAMES
from fmus.start_values import write_with_start_values

pytestmark = pytest.mark.slow

#: the FMUs checked: every model of the registry, an exported copy with other start values, a lateral Gearbox
CHECKED = (*FMU_NAMES, "Gearbox-exported", "Gearbox-lateral")
FMUCHECK_VARIABLE = "DTCOSIM_FMUCHECK"

SERIES_SCENARIO = """
name = "record"
[simulation]
start = 0.0
stop = 1.0
step = 0.01
[components.loads]
fmu = "TimeSeriesSource.fmu"
[components.loads.series]
record = "record.csv"
[[components.loads.series.channels]]
channel = "GenTq"
output = "torque"
interpolation = "linear"
"""


@pytest.fixture(scope="module")
def every_fmu(fmu_path, tmp_path_factory) -> dict[str, Path]:
    """Name -> FMU: the session's three, the other preset FMUs, a TimeSeriesSource and an exported copy."""
    from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file
    from orchestrator.inputs.scenario_file import load_scenario
    from orchestrator.provision.series_fmus import ensure_series_fmu

    out = tmp_path_factory.mktemp("compliance")
    fmus = {name: fmu_path(name) for name in ("WindSource", "Gearbox", "GeneratorRotor")}
    for name in PRESET_FMU_NAMES:
        if name not in fmus:
            fmus[name] = build_fmu(name, out / "built").path
    (out / "record.csv").write_text("Time [s], GenTq [kN-m]\n0, 40\n0.5, 41\n1.0, 42\n2.0, 40\n")
    (out / "record.toml").write_text(SERIES_SCENARIO)
    spec = load_scenario(out / "record.toml").component("loads").series
    fmus["TimeSeriesSource"] = ensure_series_fmu(spec, out / "series")
    fmus["Gearbox-exported"] = write_with_start_values(
        fmus["Gearbox"], out / "exported" / "Gearbox.fmu", {"generator_interface": 1, "stage1.k0": 2.0e9})
    lateral = load_drivetrain_file(find_drivetrain("paper-table6-lateral")).drivetrain
    fmus["Gearbox-lateral"] = build_fmu("Gearbox", out / "lateral", drivetrain=lateral,
                                        origin="drivetrain paper-table6-lateral").path
    assert set(fmus) == set(CHECKED)
    return fmus


def fmutool_check(fmu: Path) -> tuple[int, list[str]]:
    """(exit status, the WARNING and ERROR lines) of ``fmutool -input FMU -check``."""
    fmutool = Path(sys.executable).parent / "fmutool"
    proc = subprocess.run([str(fmutool), "-input", str(fmu), "-check"], capture_output=True, text=True,
                          timeout=120)
    lines = (proc.stdout + proc.stderr).splitlines()
    return proc.returncode, [line for line in lines if re.match(r"\s*(WARNING|ERROR|CRITICAL)\b", line)]


@pytest.mark.parametrize("name", CHECKED)
def test_schema_and_semantic_rules_of_fmi_2_pass_with_no_warning(every_fmu, name):
    status, findings = fmutool_check(every_fmu[name])
    assert findings == [] and status == 0
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(every_fmu[name])) == []


@pytest.mark.parametrize("damage, expected", [
    # an output left out of <ModelStructure><Outputs> (FMI 2.0, 2.2.8)
    (lambda md: re.sub(r"<Outputs>\s*<Unknown [^>]*/>", "<Outputs>", md, count=1), "is not listed in <Outputs>"),
    # a parameter that is calculated (FMI 2.0, 2.2.7: a parameter is exact)
    (lambda md: re.sub(r'(causality="parameter"[^>]*)initial="exact"', r'\1initial="calculated"', md, count=1),
     "initial='calculated' is not allowed"),
    # an element the schema does not know
    (lambda md: md.replace("<ModelVariables>", "<ModelVariables><Bogus/>", 1), "Bogus"),
])
def test_the_checker_counts_what_breaks_the_standard(every_fmu, tmp_path, damage, expected):
    """The check can fail: a copy of the WindSource with one rule broken is reported."""
    source = every_fmu["WindSource"]
    broken = tmp_path / "WindSource.fmu"
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(broken, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                changed = damage(data.decode("utf-8"))
                assert changed != data.decode("utf-8")
                data = changed.encode("utf-8")
            zout.writestr(item, data)
    status, findings = fmutool_check(broken)
    assert status != 0 and any(expected in line for line in findings), findings


def logged_run(fmu: Path, folder: Path, start_values: dict | None = None):
    """fmpy as the host, loggingOn and every category, over the FMU's own cross-check inputs and options.

    Returns ``(messages logged with status warning or worse, FMI calls that returned other than OK, doSteps,
    the exception that ended the run or None)``.
    """
    from fmpy import read_model_description, simulate_fmu
    from fmpy.util import read_csv, read_ref_opt_file

    model = read_model_description(str(fmu)).coSimulation.modelIdentifier
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder, [f"{MEMBER_DIR}/{model}_in.csv", f"{MEMBER_DIR}/{model}_ref.opt"])
    opt = read_ref_opt_file(str(folder / MEMBER_DIR / f"{model}_ref.opt"))
    inputs = read_csv(str(folder / MEMBER_DIR / f"{model}_in.csv"))
    messages, calls = [], []

    def logger(env, instance, status, category, message):
        messages.append((int(status), category.decode() if category else "", message.decode() if message else ""))

    failure = None
    try:
        simulate_fmu(str(fmu), start_time=opt["StartTime"], stop_time=opt["StopTime"], step_size=opt["StepSize"],
                     output_interval=opt["StepSize"], input=inputs if len(inputs.dtype.names) > 1 else None,
                     start_values=start_values or {}, debug_logging=True, logger=logger,
                     fmi_call_logger=calls.append, validate=True)
    except Exception as exc:  # fmpy raises on a call that fails: the run's verdict, counted by the caller
        failure = exc
    returned = [(c.partition("(")[0], c.rpartition("->")[2].strip()) for c in calls if "->" in c]
    # fmi2Instantiate returns the instance (a non-NULL address), every other call a status
    not_ok = [(f, r) for f, r in returned if (r in ("0x0", "None", "NULL") if f == "fmi2Instantiate" else r != "OK")]
    warned = [m for m in messages if m[0] >= 1]  # fmi2Warning = 1, fmi2Discard, fmi2Error, fmi2Fatal
    return warned, not_ok, sum(f == "fmi2DoStep" for f, _ in returned), failure


@pytest.mark.parametrize("name", CHECKED)
def test_a_run_with_logging_on_reports_no_warning_and_every_call_returns_ok(every_fmu, tmp_path, name):
    warned, not_ok, steps, failure = logged_run(every_fmu[name], tmp_path)
    assert (warned, not_ok, failure) == ([], [], None)
    assert steps > 10


def test_the_logged_run_counts_what_an_fmu_reports(every_fmu, tmp_path):
    """The run can fail: a refused parameter is an error message and a call that does not return OK."""
    warned, not_ok, _, failure = logged_run(every_fmu["GeneratorRotor"], tmp_path, {"inertia": -1.0})
    assert failure is not None and not_ok
    assert any(status >= 3 and "inertia" in message for status, _, message in warned), warned


def fmu_check_program() -> str | None:
    """The FMI Compliance Checker: ``$DTCOSIM_FMUCHECK`` or ``fmuCheck.linux64`` on PATH (None: not built here)."""
    named = os.environ.get(FMUCHECK_VARIABLE)
    return named if named else shutil.which("fmuCheck.linux64")


SUMMARY = re.compile(r"FMU reported:\s*(\d+) warning\(s\) and error\(s\)\s*Checker reported:\s*(\d+) Warning\(s\)"
                     r"\s*(\d+) Error\(s\)")


@pytest.mark.parametrize("name", CHECKED)
def test_the_fmi_compliance_checker_reports_0_warnings_and_0_errors(every_fmu, tmp_path, name):
    """The documented command of docs/hosts.md ("The FMI Compliance Checker"), where the checker is built."""
    program = fmu_check_program()
    if program is None:
        pytest.skip(f"the FMI Compliance Checker is not built on this machine (fmuCheck.linux64 not on PATH, "
                    f"${FMUCHECK_VARIABLE} unset): build it from its public sources (docs/hosts.md)")
    from fmpy.util import read_ref_opt_file

    fmu = every_fmu[name]
    model = fmu.stem
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(tmp_path, [f"{MEMBER_DIR}/{model}_in.csv", f"{MEMBER_DIR}/{model}_ref.opt"])
    opt = read_ref_opt_file(str(tmp_path / MEMBER_DIR / f"{model}_ref.opt"))
    log = tmp_path / "fmucheck.log"
    args = [program, "-l", "3", "-h", repr(opt["StepSize"]), "-s", repr(opt["StopTime"]),
            "-o", str(tmp_path / "out.csv"), "-e", str(log)]
    inputs = tmp_path / MEMBER_DIR / f"{model}_in.csv"
    if inputs.read_text().splitlines()[0].count(",") > 0:
        args += ["-i", str(inputs)]
    proc = subprocess.run([*args, str(fmu)], capture_output=True, text=True, timeout=600, env={"PATH": "/usr/bin:/bin"})
    report = proc.stdout + proc.stderr + (log.read_text() if log.exists() else "")
    found = SUMMARY.search(report)
    assert found is not None, report[-3000:]
    assert found.groups() == ("0", "0", "0"), report[-3000:]
