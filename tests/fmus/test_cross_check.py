"""Each FMU carries its own cross-check (FMI Cross-Check layout) and `dtcosim validate --cross-check` compares a run.

The other host is fmpy's command-line program in a subprocess with an empty environment (only PATH of the
system): it reads ``<Model>_in.csv`` and ``<Model>_ref.opt`` as any cross-check host does.
"""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fmus import registry
from fmus.cross_check import MEMBER_DIR, compare
from fmus.cross_check_case import CrossCheckCase, CrossCheckError, Ramp, stated_inputs
from tests.helpers.reference_fmus import reference_fmu
from tests.helpers.scenarios import dtcosim

CHECKED = [k.name for k in registry.KINDS.values() if k.cross_check is not None]
BUILT = [name for name in CHECKED if registry.PRESET in registry.kind(name).built_from]


class _Var:
    def __init__(self, name, start, causality="input", type_="Real"):
        self.name, self.start, self.causality, self.type = name, start, causality, type_


class _Md:
    modelName = "Toy"

    def __init__(self, *variables):
        self.modelVariables = list(variables)


def test_stated_inputs_hold_start_values_follow_ramps_and_integrate_angles_exactly():
    md = _Md(_Var("w", "2.0"), _Var("phi", "0.5"), _Var("T", "0"), _Var("k", "7"), _Var("y", "1", "output"))
    case = CrossCheckCase(1.0, ramps=(Ramp("w", (0.2, 0.3, 0.4), (1.0, 1.5, 1.0)),
                                      Ramp("T", (0.0, 0.5), values=(10.0, 20.0))),
                          integrals=(("phi", "w"),))
    table = stated_inputs(case, md, 0.01)
    assert table.dtype.names == ("time", "w", "phi", "T", "k")
    t = table["time"]
    assert t[0] == 0.0 and t[-1] == pytest.approx(1.0) and t.size == 101
    assert np.all(table["k"] == 7.0)
    assert table["w"][np.isclose(t, 0.3)][0] == pytest.approx(3.0)
    assert table["T"][np.isclose(t, 0.25)][0] == pytest.approx(15.0)
    # by hand: 0.5 + 2 t plus the pulse's triangle 0.5 x 0.2 s x 1 rad/s = 0.1 rad once it is over
    assert table["phi"][np.isclose(t, 0.2)][0] == pytest.approx(0.5 + 0.4, rel=1e-12)
    assert table["phi"][-1] == pytest.approx(0.5 + 2.0 + 0.1, rel=1e-12)


def test_a_ramp_of_an_input_the_fmu_lacks_is_refused():
    with pytest.raises(CrossCheckError, match="'u' is not an input of Toy"):
        stated_inputs(CrossCheckCase(1.0, ramps=(Ramp("u", (0.0, 1.0), (1.0, 2.0)),)), _Md(_Var("w", "1")), 0.1)


def test_every_fmu_declares_a_cross_check():
    assert set(CHECKED) == set(registry.FMU_NAMES)


def test_a_load_record_fmu_checks_its_first_second_of_record_in_simulation_time():
    model = {"series": {"start_s": 30.0, "end_s": 90.0, "time_offset_s": 30.0}}
    case = registry.kind("TimeSeriesSource").cross_check_case(model)
    assert (case.start_time, case.stop_time) == (0.0, 1.0)
    model = {"series": {"start_s": 30.0, "end_s": 30.5, "time_offset_s": 0.0}}
    case = registry.kind("TimeSeriesSource").cross_check_case(model)
    assert (case.start_time, case.stop_time) == (30.0, 30.5)


def _host_run(fmu: Path, tmp: Path) -> Path:
    """fmpy's command-line host, empty environment, on the FMU's own stated inputs and options."""
    from fmpy.util import read_ref_opt_file

    model = fmu.stem
    with zipfile.ZipFile(fmu) as z:
        z.extractall(tmp, [f"{MEMBER_DIR}/{model}_in.csv", f"{MEMBER_DIR}/{model}_ref.opt"])
    folder = tmp / MEMBER_DIR
    opt = read_ref_opt_file(folder / f"{model}_ref.opt")
    out = tmp / f"{model}_out.csv"
    cmd = [sys.executable, "-m", "fmpy.cli", "simulate", str(fmu), "--start-time", str(opt["StartTime"]),
           "--stop-time", str(opt["StopTime"]), "--step-size", str(opt["StepSize"]),
           "--output-interval", str(opt["StepSize"]), "--output-file", str(out)]
    if (folder / f"{model}_in.csv").read_text().count("\n") and model != "WindSource":
        cmd += ["--input-file", str(folder / f"{model}_in.csv")]
    proc = subprocess.run(cmd, capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", BUILT)
def test_the_fmu_carries_its_cross_check_and_another_host_meets_it(name, fmu_path, tmp_path):
    from fmpy import read_model_description
    from fmpy.util import read_csv, read_ref_opt_file

    fmu = fmu_path(name)
    with zipfile.ZipFile(fmu) as z:
        members = set(z.namelist())
        for suffix in ("_in.csv", "_ref.csv", "_ref.opt"):
            assert f"{MEMBER_DIR}/{name}{suffix}" in members
        z.extractall(tmp_path / "ref", [f"{MEMBER_DIR}/{name}_ref.csv", f"{MEMBER_DIR}/{name}_ref.opt"])
    opt = read_ref_opt_file(tmp_path / "ref" / MEMBER_DIR / f"{name}_ref.opt")
    ref = read_csv(tmp_path / "ref" / MEMBER_DIR / f"{name}_ref.csv")
    outputs = [v.name for v in read_model_description(str(fmu)).modelVariables if v.causality == "output"]
    assert list(ref.dtype.names) == ["time", *outputs]
    assert ref["time"][0] == opt["StartTime"] and ref["time"][-1] == pytest.approx(opt["StopTime"])
    assert np.allclose(np.diff(ref["time"]), opt["StepSize"])
    result = _host_run(fmu, tmp_path)
    run = dtcosim("validate", str(fmu), "--cross-check", str(result), cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"{fmu}: cross-check passed" in run.stdout
    report = compare(fmu, result)
    # the same inputs; the kernel may run in another form here (compiled or interpreted): 3e-9 seen
    assert report.passed and report.worst.relative < 1e-6


@pytest.mark.slow
def test_the_gearbox_reference_rings_and_a_deviation_or_a_short_run_fails(fmu_path, tmp_path):
    from fmpy.util import read_csv, write_csv

    fmu = fmu_path("Gearbox")
    good = read_csv(_host_run(fmu, tmp_path))
    torque = good["shaft_torque"]
    assert np.ptp(torque) > 0.01 * torque[0]  # the stated generator-speed pulse moves the shaft torque
    bad = good.copy()
    bad["stage1.F_sp[1]"] *= 1.001  # 0.1 % off: 900 N on 9e5 N
    write_csv(tmp_path / "bad.csv", bad)
    run = dtcosim("validate", str(fmu), "--cross-check", str(tmp_path / "bad.csv"), cwd=tmp_path)
    assert run.returncode == 1
    assert "largest deviation: stage1.F_sp[1]" in run.stdout and "cross-check FAILED" in run.stdout
    write_csv(tmp_path / "short.csv", good[: good.size // 2])
    run = dtcosim("validate", str(fmu), "--cross-check", str(tmp_path / "short.csv"), cwd=tmp_path)
    assert run.returncode == 1 and "before the stop time" in run.stdout
    write_csv(tmp_path / "partial.csv", good, ["shaft_torque"])
    report = compare(fmu, tmp_path / "partial.csv")
    assert not report.passed and "omega_out" in report.missing


def test_a_result_that_is_not_a_cross_check_csv_is_refused_with_a_message(fmu_path, tmp_path):
    (tmp_path / "r.csv").write_text("t;y\n0;1\n")
    run = dtcosim("validate", str(fmu_path("Rotor")), "--cross-check", str(tmp_path / "r.csv"), cwd=tmp_path)
    assert run.returncode != 0 and "Traceback" not in run.stderr
    assert "not a CSV of the FMI Cross-Check layout" in run.stderr + run.stdout


def test_an_fmu_without_a_cross_check_is_named(tmp_path):
    (tmp_path / "r.csv").write_text('"time","y"\n0,1\n1,1\n')
    with pytest.raises(CrossCheckError, match="no cross-check reference"):
        compare(reference_fmu("Feedthrough"), tmp_path / "r.csv")


def test_the_cross_check_run_leaves_no_module_or_path_of_its_deleted_folder(tmp_path):
    """A build's stand-alone run imports the FMU's package from an extraction it deletes: a later instance of the
    FMU (the run that built it) must import its own copy, not reuse modules whose files are gone."""
    import os

    from fmus.build import build_fmu

    before = list(sys.path)
    built = build_fmu("GeneratorRotor", tmp_path)
    left = [name for name in list(sys.modules) if name.startswith(built.package) or name == built.slave_module]
    assert left == []
    assert [entry for entry in sys.path if entry not in before and not os.path.exists(entry)] == []


@pytest.mark.parametrize("dtype", [[("time", "f8"), ("y", "f8")], [("time", "f8"), ("n", "i4"), ("b", "?")],
                                   [("time", "f8"), ("big", "i8"), ("small", "f4")]])
def test_the_csv_cells_are_repr_of_float_of_each_value(dtype):
    from fmus.cross_check import _csv_text

    rng = np.random.default_rng(1)
    table = np.zeros(7, dtype=dtype)
    for name in table.dtype.names:
        table[name] = rng.normal(size=7) * 1e9 if table.dtype[name].kind != "b" else rng.random(7) > 0.5
    table["time"][3] = -0.0
    by_row = [",".join(f'"{n}"' for n in table.dtype.names)] + [",".join(repr(float(x)) for x in row) for row in table]
    assert _csv_text(table) == "\n".join(by_row) + "\n"
    assert _csv_text(table[:0]) == by_row[0] + "\n"


def test_forgetting_a_folder_resolves_links_of_files_and_folders(tmp_path, monkeypatch):
    """Modules whose files lie in the folder through a linked folder or a linked file are forgotten; others stay."""
    import os
    import types

    from fmus.cross_check import forget_python_from

    inside, outside = tmp_path / "fmu" / "resources", tmp_path / "other"
    inside.mkdir(parents=True)
    outside.mkdir()
    (inside / "m.py").write_text("")
    (tmp_path / "via").symlink_to(inside)
    (outside / "linked.py").symlink_to(inside / "m.py")
    (outside / "own.py").write_text("")
    files = {"_t_direct": inside / "m.py", "_t_via_folder": tmp_path / "via" / "m.py",
             "_t_via_file": outside / "linked.py", "_t_outside": outside / "own.py"}
    for name, path in files.items():
        module = types.ModuleType(name)
        module.__file__ = str(path)
        monkeypatch.setitem(sys.modules, name, module)
    monkeypatch.setattr(sys, "path", [*sys.path, str(tmp_path / "via"), str(outside), os.path.relpath(inside)])
    forget_python_from(tmp_path / "fmu")
    assert [name for name in files if name in sys.modules] == ["_t_outside"]
    assert str(outside) in sys.path and str(tmp_path / "via") not in sys.path and os.path.relpath(inside) not in sys.path


def test_ctrl_c_during_the_stand_alone_run_interrupts_after_it_not_as_an_fmu_failure(fmu_path, monkeypatch):
    """The slave runs in this interpreter: a Ctrl-C must not reach its code (there it became an fmi2Error and the
    build's "cross-check run failed"); it is held and raised once the run has ended, as the KeyboardInterrupt it
    is. (Without the hold where it lands is a race: in the slave an FMU failure, in fmpy's loop the interrupt.)"""
    import os
    import signal
    import threading

    import fmpy

    from fmus import cross_check
    from fmus.registry import KINDS

    ended = []
    real_simulate = fmpy.simulate_fmu

    def simulate(*args, **kwargs):  # Ctrl-C 50 ms into the stepping (the Gearbox's 500 steps take longer)
        timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        try:
            return real_simulate(*args, **kwargs)
        finally:
            timer.join()
            ended.append(True)

    monkeypatch.setattr(fmpy, "simulate_fmu", simulate)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            cross_check.reference_members(fmu_path("Gearbox"), KINDS["Gearbox"].cross_check)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the handler in place again
    finally:
        signal.signal(signal.SIGINT, previous)
    assert ended == [True]  # the run went on to its end, then the interrupt
