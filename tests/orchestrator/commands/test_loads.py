"""``dtcosim loads``: the packaged paper-turbine set runs and its report ranks the bins; errors are one line."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tests.helpers.scenarios import dtcosim


def test_a_bad_set_is_one_error_line_without_traceback(tmp_path):
    (tmp_path / "bad.toml").write_text('[base]\nscenario = "paper-60s"\n[wind]\ndistribution = "weibull"\nk = 2.0\n'
                                       'A = 9.0\n[bins]\nedges = [4.0, 8.0]\n[runs]\nlenght = 60.0\n')
    proc = dtcosim("loads", "bad.toml", cwd=tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.strip().splitlines() == [
        "dtcosim loads: error: bad.toml: invalid load-case set entry runs.lenght = 60.0: expected a known key here: "
        "length, seed_parameter, seeds, transient (did you mean length?)"]


def test_check_prints_the_plan(tmp_path, fmu_dir):
    proc = dtcosim("loads", "paper-turbine", "--check", "--fmu-dir", str(fmu_dir), cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "11 bins x 3 seeds = 33 runs of 2.9 + 600 s, 33 to run" in proc.stdout  # transient "settled": 2.82 s
    assert "17 channels" in proc.stdout


@pytest.mark.slow
def test_the_packaged_paper_turbine_set_runs_and_ranks_the_bins_by_damage_share(tmp_path, fmu_dir):
    out = tmp_path / "out"
    proc = dtcosim("loads", "paper-turbine", "--length", "2", "--transient", "3", "--seeds", "1", "--workers", "2",
                   "--out", str(out), "--fmu-dir", str(fmu_dir), cwd=tmp_path, timeout=900)
    assert proc.returncode == 0, proc.stderr
    report = (out / "lifetime_report.txt").read_text()
    summary = json.loads((out / "lifetime.json").read_text())
    assert summary["complete"] and summary["finished_runs"] == 11
    labels = ["high-speed shaft", "stage1 sun_planet mesh", "stage1 ring_planet mesh", "stage2 sun_planet mesh",
              "stage2 ring_planet mesh", "stage3 parallel mesh"]
    assert list(summary["rankings"]) == labels
    assert summary["rankings"]["high-speed shaft"]["channel"] == "gearbox.shaft3.torque"
    for label in labels:
        block = report.split(f"{label} (", 1)[1].split("\n\n")[0]
        shares = [float(s) for s in re.findall(r"^\s+\d+\. \[[^)]+\) m/s\s+([\d.]+) %", block, re.M)]
        assert len(shares) == 11 and shares == sorted(shares, reverse=True), label
        assert sum(shares) == pytest.approx(100.0, abs=0.05), label
        # the shafts have S-N curves; the tooth loads are rated by ISO 6336 (their damage per gear below)
        assert ("lifetime damage" if label == "high-speed shaft" else "no S-N curve") in block.splitlines()[0]
    assert "gear ratings (ISO 6336-2/-3/-5/-6" in report and (out / "gear_rating.csv").is_file()
    assert (out / "damage_by_bin.png").stat().st_size > 10_000


@pytest.mark.parametrize("stopped", [True, False])
def test_a_full_disk_the_sweep_told_is_not_told_again_for_the_lifetime_results(tmp_path, fmu_dir, monkeypatch,
                                                                              capsys, stopped):
    """A load set on a full disk printed a second error line for the lifetime results it then could not write."""
    import os

    from orchestrator.commands import cli
    from orchestrator.study import sweep
    from tests.helpers.failing_files import FullAt

    out = tmp_path / "out"
    told = f"cannot write {out / 'journal.jsonl'}: No space left on device; the sweep stopped, ..." if stopped else ""

    def full_disk_sweep(prepared, out_dir, **kwargs):  # what run_sweep reports when the disk filled up
        report = sweep.SweepReport(total=len(prepared.points), out_dir=out_dir, problems=[told] if told else [])
        out_dir.mkdir(parents=True, exist_ok=True)
        return report

    monkeypatch.setattr(sweep, "run_sweep", full_disk_sweep)
    monkeypatch.setattr(os, "replace", FullAt("bins.csv"))
    assert cli.main(["loads", "paper-turbine", "--seeds", "1", "--out", str(out), "--fmu-dir", str(fmu_dir),
                     "-q", "--no-plots"]) == 1
    err = [line for line in capsys.readouterr().err.strip().splitlines() if ": error: " in line]
    if stopped:
        assert err == [f"dtcosim loads: error: {told}"]
    else:  # the lifetime results are the first file the disk refused: their own line
        assert err == [f"dtcosim loads: error: cannot write {out / 'bins.csv'}: No space left on device; the lifetime "
                       f"results are not all written; every finished run is kept in {out / 'journal.jsonl'} and "
                       f"{out}/runs: free some space and run the same command with --report to write them"]


@pytest.mark.parametrize("argv", [["loads", "paper-turbine", "--check"], ["sweep", "shaft3-seeds", "--check"]],
                         ids=["loads", "sweep"])
def test_what_preparing_the_fmus_says_reaches_the_user_once(argv, tmp_path, fmu_dir, monkeypatch, capsys):
    """A study's commands show what their FMU preparation says (the kernels' compile: a minute on a new machine),
    each line once, though a load set prepares its base scenario's FMUs more than once."""
    import orchestrator.provision.project_fmus as project_fmus
    from orchestrator.commands.cli import main

    asked = []
    monkeypatch.setattr(project_fmus, "ensure_compiled_kernels",
                        lambda report=None, background=False: asked.append(background) or (report and report("the kernels: a note")))
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--fmu-dir", str(fmu_dir)]) == 0
    assert capsys.readouterr().err.count("the kernels: a note") == 1
    assert asked and not any(asked)  # a study waits for its kernels: its points would all run interpreted


def test_a_set_at_a_step_too_coarse_for_its_drivetrain_is_warned_about(tmp_path, fmu_dir):
    text = (Path(__file__).resolve().parents[3] / "orchestrator" / "load_cases" / "paper-turbine.toml").read_text()
    text = text.replace("[base]", "[simulation]\nstep = 0.25\n\n[base]", 1)
    (tmp_path / "coarse.toml").write_text(text)
    proc = dtcosim("loads", "coarse.toml", "--check", "--transient", "3", "--length", "601", "--fmu-dir", str(fmu_dir),
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "dtcosim loads: warning: the communication step 0.25 s is longer than 1/20 of the period of the 0.953 Hz " \
           "mode" in proc.stderr
