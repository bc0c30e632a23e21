"""`dtcosim run` options: --compare-reference, overrides, SSP input, quiet output."""

from __future__ import annotations

import json

import pytest

from conftest import dtcosim

pytestmark = pytest.mark.slow


def test_compare_reference_reports_every_statistic(paper_fmu_dir, tmp_path):
    out = tmp_path / "cmp"
    proc = dtcosim("run", "--stop", "2", "--fmu-dir", str(paper_fmu_dir), "--out", str(out), "--compare-reference",
                   "--no-plots", "--set", "wind.seed=3", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["window_s"] == [0.0, 2.0]  # [5, 60] clipped to the shortened run
    assert summary["fmus"]["wind"]["parameters"] == {"seed": 3}
    comparison = summary["comparison"]
    assert comparison["reference_complete"] is True and comparison["preset"] == "table6"
    variables = comparison["variables"]
    assert "gearbox.stage1.F_sp[1]" in variables and "generator.omega" in variables
    for name, entry in variables.items():
        assert set(entry["cosim"]) == set(entry["monolithic"]) == set(entry["relative_difference"]) == {"mean", "std", "min", "max"}
        assert entry["reference"]
    assert abs(variables["gearbox.stage1.F_sp[1]"]["relative_difference"]["mean"]) < 0.005
    assert "co-simulation vs monolithic reference" in proc.stdout and "gearbox.stage3.F_mesh" in proc.stdout


def test_run_accepts_an_ssp_and_quiet_prints_nothing(paper_fmu_dir, tmp_path):
    ssp = tmp_path / "p.ssp"
    proc = dtcosim("export-ssp", "--out", str(ssp), "--fmu-dir", str(paper_fmu_dir), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = dtcosim("run", str(ssp), "--stop", "0.5", "--step", "0.002", "--algorithm", "jacobi", "-q",
                   "--out", str(tmp_path / "r"), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["steps"] == 250 and summary["algorithm"] == "jacobi" and summary["step_s"] == 0.002
    assert summary["complete"] is True


def test_bad_override_is_a_scenario_error(paper_fmu_dir, tmp_path):
    proc = dtcosim("run", "--stop", "1", "--fmu-dir", str(paper_fmu_dir), "--set", "gearbox.no_such=1", "-q",
                   "--out", str(tmp_path / "x"), cwd=tmp_path)
    assert proc.returncode == 1
    assert "components.gearbox.parameters.no_such" in proc.stderr
