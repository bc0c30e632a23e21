"""`dtcosim run` options: --compare-reference, overrides, SSP input, quiet output."""

from __future__ import annotations

import json

import pytest

from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow


def test_compare_reference_reports_every_statistic(fmu_dir, tmp_path):
    out = tmp_path / "cmp"
    proc = dtcosim("run", "--stop", "2", "--fmu-dir", str(fmu_dir), "--out", str(out), "--compare-reference",
                   "--no-plots", "--set", "wind.seed=3", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["window_s"] == [0.0, 2.0]  # [5, 60] clipped to the shortened run
    assert summary["fmus"]["wind"]["parameters"] == {"seed": 3}
    comparison = summary["comparison"]
    assert comparison["reference_complete"] is True
    assert comparison["built_from"] == {"wind_source": "preset table6", "gearbox": "preset table6", "generator": "preset table6"}
    variables = comparison["variables"]
    assert "gearbox.stage1.F_sp[1]" in variables and "generator.omega" in variables
    for name, entry in variables.items():
        assert set(entry["cosim"]) == set(entry["monolithic"]) == set(entry["relative_difference"]) == {"mean", "std", "min", "max"}
        assert entry["reference"]
    assert abs(variables["gearbox.stage1.F_sp[1]"]["relative_difference"]["mean"]) < 0.005
    assert "co-simulation vs monolithic reference" in proc.stdout and "gearbox.stage3.F_mesh" in proc.stdout


def test_run_accepts_an_ssp_and_quiet_prints_nothing(fmu_dir, tmp_path):
    ssp = tmp_path / "p.ssp"
    proc = dtcosim("export-ssp", "--out", str(ssp), "--fmu-dir", str(fmu_dir), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = dtcosim("run", str(ssp), "--stop", "0.5", "--step", "0.002", "--algorithm", "jacobi", "-q",
                   "--out", str(tmp_path / "r"), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["steps"] == 250 and summary["algorithm"] == "jacobi" and summary["step_s"] == 0.002
    assert summary["complete"] is True


def test_bad_override_is_a_scenario_error(fmu_dir, tmp_path):
    proc = dtcosim("run", "--stop", "1", "--fmu-dir", str(fmu_dir), "--set", "gearbox.no_such=1", "-q",
                   "--out", str(tmp_path / "x"), cwd=tmp_path)
    assert proc.returncode == 1
    assert "components.gearbox.parameters.no_such" in proc.stderr


def _run_on_terminal(args, cwd):
    """Run dtcosim with stderr on a pseudo-terminal (size unknown, as some CI terminals); return its output."""
    import os
    import pty
    import subprocess
    import sys
    from pathlib import Path

    master, slave = pty.openpty()
    proc = subprocess.Popen([str(Path(sys.executable).parent / "dtcosim"), *args], cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    out = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:
            break
        if not chunk:
            break
        out += chunk
    assert proc.wait(timeout=120) == 0
    os.close(master)
    return out.decode("utf-8", "replace")


def test_progress_bar_on_a_terminal_and_quiet(toy_scenario, tmp_path):
    from tests.helpers.scenarios import TOY_SCENARIO

    path = toy_scenario(TOY_SCENARIO.replace("stop = 0.1", "stop = 5.0"))
    shown = _run_on_terminal(["run", str(path), "--out", str(tmp_path / "a"), "--no-plots"], tmp_path)
    assert "co-simulation: 100%" in shown and "5.00/5.00 s simulated" in shown
    quiet = _run_on_terminal(["run", str(path), "--out", str(tmp_path / "b"), "--no-plots", "--quiet"], tmp_path)
    assert quiet.strip() == ""


def test_version_names_dtcosim_and_what_results_depend_on(capsys):
    from components import __version__
    from orchestrator.commands import cli

    with pytest.raises(SystemExit) as done:
        cli.main(["--version"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"dtcosim {__version__} (python ")
    assert all(f"{name} " in out for name in ("numpy", "scipy", "fmpy", "pythonfmu"))


def test_a_python_warning_reaches_the_user_as_one_line_of_the_command(tmp_path, monkeypatch, capsys):
    import warnings

    from orchestrator.commands import cache
    from orchestrator.commands.cli import main

    def warns(root=None):
        warnings.warn("Gearbox.fmu keeps pythonfmu's linux64 binary: no C compiler", stacklevel=2)
        return []

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(cache, "cache_entries", warns)
    shown = warnings.showwarning
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert main(["cache"]) == 0
        assert warnings.showwarning is shown  # restored after the command
    err = capsys.readouterr().err
    assert err == "dtcosim cache: warning: Gearbox.fmu keeps pythonfmu's linux64 binary: no C compiler\n"
