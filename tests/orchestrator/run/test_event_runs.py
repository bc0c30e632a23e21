"""Load events, contact loss, fatigue loads and time-varying mesh stiffness through the three FMUs:
`dtcosim run grid-fault`, the paper run's analyses, a short TVMS run's spectrum, `dtcosim modes SCENARIO`."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from components.analysis.contact_loss import contact_loss_summary
from components.analysis.spectrum import amplitude_spectrum
from orchestrator.commands.cli import main
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.provision.locate import resolve_fmu_paths
from orchestrator.result_files import read_timeseries
from orchestrator.run.comparison import run_reference
from orchestrator.run.runner import run_scenario
from tests.helpers.scenarios import dtcosim, write_scenario

pytestmark = pytest.mark.slow

FORCES = [f"gearbox.stage{s}.F_{k}[{i}]" for s in (1, 2) for k in ("sp", "rp") for i in (1, 2, 3)] + ["gearbox.stage3.F_mesh"]
SHAFTS = [f"gearbox.shaft{k}.torque" for k in (1, 2, 3)]


@pytest.fixture(scope="module")
def grid_fault_run(fmu_dir, tmp_path_factory):
    """``dtcosim run grid-fault`` (15 s, grid fault at 10 s for 0.5 s) with the session's FMUs."""
    work = tmp_path_factory.mktemp("grid-fault")
    proc = dtcosim("run", "grid-fault", "--out", "out", cwd=work, env={"DTCOSIM_FMU_DIR": str(fmu_dir)})
    assert proc.returncode == 0, proc.stderr
    out = work / "out"
    return out, json.loads((out / "summary.json").read_text()), proc


def test_grid_fault_crosses_the_backlash_in_every_mesh_without_solver_failure(grid_fault_run):
    out, summary, proc = grid_fault_run
    assert summary["complete"] is True and summary["steps"] == 15000 and "fmu_messages" not in summary
    assert summary["events"] == [{"kind": "grid_fault", "start_s": 10.0, "duration_s": 0.5, "factor": None,
                                  "component": "generator", "slot": 1}]
    cl = summary["contact_loss"]
    assert cl["window_s"] == [5.0, 15.0] and cl["threshold_n"] == 1.0
    assert sorted(cl["meshes"]) == sorted(FORCES)
    for name, m in cl["meshes"].items():
        # torque gone: shaft 3 swings through zero and back, every mesh changes flank twice
        assert m["separations"] == 2 and m["flank_changes"] == 2, (name, m)
        assert 0.005 < m["time_in_backlash_s"] < 0.5 and m["longest_episode_s"] <= m["time_in_backlash_s"]
    assert cl["total_separations"] == 26 and sorted(cl["meshes_with_contact_loss"]) == sorted(FORCES)
    assert "contact loss over [5, 15] s (|F| < 1 N):\n  13 of 13 meshes separate, 26 separations" in proc.stdout
    assert all(len(line) <= 80 for line in proc.stdout.splitlines())  # the tables fit a terminal
    assert "load event: grid_fault at 10 s for 0.5 s (generator, slot 1)" in proc.stdout
    # the counter torque really dropped to zero for 0.5 s (the generator FMU applied the event slot)
    header, data = read_timeseries(out / "timeseries.csv")
    t, torque = data[:, 0], data[:, header.index("generator.generator_torque [N.m]")]
    assert np.all(torque[(t >= 10.0) & (t < 10.5)] == 0.0) and np.all(torque[(t < 10.0) | (t >= 10.5)] == 25.4e3)


def test_grid_fault_contact_loss_matches_the_monolithic_reference(grid_fault_run, fmu_dir):
    """The reference carries the event too (from the generator's slot parameters) and counts the same."""
    _, summary, _ = grid_fault_run
    grid_fault = load_scenario(find_scenario("grid-fault"))
    system = resolve_system(grid_fault, fmu_paths=resolve_fmu_paths(grid_fault, fmu_dir))
    ref = run_reference(system)
    assert ref.complete
    mono = contact_loss_summary(ref, window=(5.0, 15.0))
    for name, m in summary["contact_loss"]["meshes"].items():
        r = mono[name.removeprefix("gearbox.")]
        assert (m["separations"], m["flank_changes"]) == (r.separations, r.flank_changes), name
        assert m["time_in_backlash_s"] == pytest.approx(r.time_in_backlash_s, abs=2e-3), name  # 1 ms samples


def test_grid_fault_files_agree_with_the_summary(grid_fault_run):
    out, summary, _ = grid_fault_run
    for name in ("contact_loss.csv", "fatigue_del.csv", "fatigue_ldd.csv", "load_duration.png", "event_response.png"):
        assert (out / name).stat().st_size > 500, name
        assert summary["files"][{"contact_loss.csv": "contact_loss", "fatigue_del.csv": "fatigue_del",
                                 "fatigue_ldd.csv": "fatigue_ldd", "load_duration.png": "plot:load_duration",
                                 "event_response.png": "plot:event_response"}[name]] == name
    assert "spectrum" not in summary and not (out / "contact_force_spectra.png").exists()  # no TVMS: spectrum "auto"
    rows = {r["name"]: r for r in csv.DictReader((out / "contact_loss.csv").open())}
    for name, m in summary["contact_loss"]["meshes"].items():
        assert int(rows[name]["separations"]) == m["separations"]
        assert float(rows[name]["time_in_backlash_s"]) == pytest.approx(m["time_in_backlash_s"], rel=1e-12)


def _check_fatigue_outputs(out, summary, window, exponents=(3.0, 5.0, 8.0, 10.0), bins=64):
    fat = summary["fatigue"]
    T = window[1] - window[0]
    assert fat["wohler_exponents"] == list(exponents) and fat["window_s"] == list(window)
    assert sorted(fat["del"]) == sorted(FORCES + SHAFTS) and sorted(fat["ldd"]) == sorted(SHAFTS)
    dels = list(csv.DictReader((out / "fatigue_del.csv").open()))
    assert len(dels) == len(exponents) * len(FORCES + SHAFTS)
    for row in dels:
        entry = fat["del"][row["variable"]]
        m = float(row["wohler_exponent"])
        assert float(row["del"]) == pytest.approx(entry["del"][f"m={m:g}"], rel=1e-12)
        assert float(row["analysed_time_s"]) == pytest.approx(T, abs=1e-9)
        assert float(row["reference_cycles"]) == pytest.approx(T * 1.0, abs=1e-9)  # N_ref = 1 Hz x T
        assert row["unit"] == ("N.m" if "torque" in row["variable"] else "N")
        assert 0.0 <= float(row["del"]) <= entry["max_range"] * (entry["cycles"] / T) ** (1 / m) * (1 + 1e-12)
    ldd_rows = list(csv.DictReader((out / "fatigue_ldd.csv").open()))
    for shaft in SHAFTS:
        entry = fat["ldd"][shaft]
        assert len(entry["time_s"]) == bins and entry["unit"] == "N.m"
        assert sum(entry["time_s"]) == pytest.approx(T, rel=1e-9)  # LDD sums to the analysed time
        mine = [r for r in ldd_rows if r["variable"] == shaft]
        assert sum(float(r["time_s"]) for r in mine) == pytest.approx(T, rel=1e-9)
        assert float(mine[0]["bin_low"]) == pytest.approx(summary["statistics"][shaft]["min"], rel=1e-12)
        assert float(mine[-1]["bin_high"]) == pytest.approx(summary["statistics"][shaft]["max"], rel=1e-12)
    # revolutions per bin where the shaft speed is recorded: shaft 3 turns with the generator
    assert fat["revolution_speeds"] == {"gearbox.shaft3.torque": "generator.omega"}
    revs = sum(fat["ldd"]["gearbox.shaft3.torque"]["revolutions"])
    assert revs == pytest.approx(summary["statistics"]["generator.omega"]["mean"] * T / (2 * math.pi), rel=1e-3)


def test_grid_fault_fatigue_loads_and_ldd(grid_fault_run):
    out, summary, _ = grid_fault_run
    _check_fatigue_outputs(out, summary, (5.0, 15.0))
    d = summary["fatigue"]["del"]["gearbox.shaft3.torque"]
    # the fault's swing (-12.5 to +42.7 kN m) is the largest range and dominates the high-exponent DELs
    assert d["max_range"] == pytest.approx(summary["statistics"]["gearbox.shaft3.torque"]["max"]
                                           - summary["statistics"]["gearbox.shaft3.torque"]["min"], rel=1e-9)
    assert d["del"]["m=3"] < d["del"]["m=5"] < d["del"]["m=8"] < d["del"]["m=10"]


def test_paper_run_counts_no_contact_loss_and_writes_consistent_fatigue_files(paper_run):
    """The default scenario (60 s, window [5, 60] s): no separation, no time inside the backlash."""
    out, summary, proc = paper_run
    cl = summary["contact_loss"]
    assert cl["window_s"] == [5.0, 60.0] and cl["total_separations"] == 0 and cl["meshes_with_contact_loss"] == []
    assert all(m["time_in_backlash_s"] == 0.0 and m["flank_changes"] == 0 for m in cl["meshes"].values())
    assert "contact loss over [5, 60] s (|F| < 1 N): none (13 meshes)" in proc.stdout
    _check_fatigue_outputs(out, summary, (5.0, 60.0))
    assert "events" not in summary and "spectrum" not in summary


@pytest.fixture(scope="module")
def tvms_runs(fmu_dir, tmp_path_factory):
    """The packaged mesh-stiffness scenario shortened to 0.6 s (window [0.1, 0.6] s, 0.5 ms sampling),
    with the stage-3 stiffness varying (v = 0.3) and, for contrast, constant (v = 0)."""
    base = load_scenario(find_scenario("mesh-stiffness")).with_simulation(stop_s=0.6, window_s=(0.1, 0.6))
    runs = {}
    for v in (0.3, 0.0):
        sc = base.with_parameters("gearbox", **{"stage3.stiffness_variation": v})
        out = tmp_path_factory.mktemp(f"tvms-{v}")
        report = run_scenario(resolve_system(sc, fmu_paths=resolve_fmu_paths(sc, fmu_dir)), out, handle_sigint=False, plots=v > 0)
        assert report.outcome.complete
        runs[v] = (out, report)
    return runs


def test_tvms_through_the_fmus_peaks_at_the_stage3_mesh_frequency(tvms_runs):
    out, report = tvms_runs[0.3]
    header, data = read_timeseries(out / "timeseries.csv")
    t = data[:, 0]
    sel = (t >= 0.1 - 1e-12) & (t <= 0.6 + 1e-12)
    h = 5e-4
    np.testing.assert_allclose(np.diff(t[sel]), h, rtol=1e-9)
    omega = data[sel, header.index("wind.omega [rad/s]")].mean()
    f_mesh = 20 * 80 * omega / (2 * math.pi)  # Z_drive x stage-3 drive speed (ratio 80): ~426.7 Hz
    assert f_mesh == pytest.approx(426.67, rel=0.01)
    results = {}
    for v, (o, _) in tvms_runs.items():
        hd, dd = read_timeseries(o / "timeseries.csv")
        freq, amp = amplitude_spectrum(dd[sel, hd.index("gearbox.stage3.F_mesh [N]")], h)
        results[v] = (freq, amp)
    freq, amp = results[0.3]
    bin_hz = freq[1] - freq[0]
    assert bin_hz == pytest.approx(1 / (sel.sum() * h))  # ~2 Hz
    above = freq > 100.0  # above the start-up transient and the wind
    k = np.flatnonzero(above)[np.argmax(amp[above])]
    assert abs(freq[k] - f_mesh) <= bin_hz, (freq[k], f_mesh)
    # constant stiffness: nothing at the mesh frequency (the FMU path really applies the variation)
    near = np.abs(freq - f_mesh) <= bin_hz
    assert amp[near].max() > 100 * results[0.0][1][near].max()
    spec = report.summary["spectrum"]
    assert spec["file"] == "contact_force_spectra.png" and (out / "contact_force_spectra.png").stat().st_size > 1000
    f3 = spec["forces"]["gearbox.stage3.F_mesh"]
    assert f3["mesh_frequency_hz"] == pytest.approx(f_mesh, rel=1e-12)
    assert abs(f3["peak_within_5_percent_hz"] - f_mesh) <= bin_hz
    assert spec["stiffness_variation"] == {"stage1": 0.0, "stage2": 0.0, "stage3": 0.3}
    assert "spectrum" not in tvms_runs[0.0][1].summary  # "auto": only when a stiffness varies


def test_tvms_keeps_the_mean_force(tvms_runs):
    """The cycle-mean stiffness is the paper's: the stage-3 force's mean is unchanged within 0.1 %."""
    means = [r.summary["statistics"]["gearbox.stage3.F_mesh"]["mean"] for _, r in tvms_runs.values()]
    assert means[0] == pytest.approx(means[1], rel=1e-3)


def test_analysis_table_reaches_the_results(fmu_dir, tmp_path):
    """Woehler exponents, LDD bins and the spectrum switch of a scenario's [analysis] table."""
    text = find_scenario("paper-60s").read_text().replace("stop = 60.0", "stop = 1.0").replace(
        "window = [5.0, 60.0]", "window = [0.5, 1.0]") + (
        '\n[analysis]\nwoehler_exponents = [4, 9]\nreference_frequency_hz = 2.0\nldd_bins = 16\nspectrum = "always"\n')
    sc = load_scenario(write_scenario(tmp_path, text))
    report = run_scenario(resolve_system(sc, fmu_paths=resolve_fmu_paths(sc, fmu_dir)), tmp_path / "out", handle_sigint=False, plots=False)
    s = report.summary
    assert s["analysis_settings"]["woehler_exponents"] == [4.0, 9.0]
    d = s["fatigue"]["del"]["gearbox.shaft1.torque"]
    assert sorted(d["del"]) == ["m=4", "m=9"] and d["reference_cycles"] == pytest.approx(2.0 * 0.5)
    assert all(len(v["time_s"]) == 16 for v in s["fatigue"]["ldd"].values())
    assert "spectrum" in s and "file" not in s["spectrum"]  # computed; no plot without plots


def test_dtcosim_modes_of_a_scenario(fmu_dir, tmp_path, capsys):
    """Drivetrain and operating point from a scenario: the paper's equals the table6 preset; a stiffer
    shaft 3 and a slower rotor in the scenario move the generator mode."""
    def generator_mode(out):
        rows = list(csv.DictReader((out / "modes.csv").open()))
        return float(rows[0]["undamped_frequency_hz"])

    args = ["--fmu-dir", str(fmu_dir), "--speed-points", "3", "--shapes", "2"]
    assert main(["modes", "paper-60s", "--out", str(tmp_path / "a"), *args]) == 0
    text = capsys.readouterr().out
    assert "dtcosim modes: scenario paper-60s at 16 rpm, output torque 25400 N m" in text
    assert main(["modes", "--preset", "table6", "--out", str(tmp_path / "p"), "--speed-points", "3", "--shapes", "2"]) == 0
    capsys.readouterr()
    assert generator_mode(tmp_path / "a") == pytest.approx(generator_mode(tmp_path / "p"), rel=1e-12)
    paper = find_scenario("paper-60s").read_text()
    stiff = paper.replace('[components.gearbox.parameters]\n',
                          '[components.gearbox.parameters]\n"shaft3.stiffness" = 2.0e4\n').replace("seed = 1 ", "seed = 1\nomega0 = 1.2566370614359172 ").replace('name = "paper-60s"', 'name = "stiff"')
    path = write_scenario(tmp_path, stiff, "stiff.toml")
    assert main(["modes", str(path), "--out", str(tmp_path / "b"), *args]) == 0
    assert "scenario stiff at 12 rpm" in capsys.readouterr().out
    from components.analysis.equilibrium import OperatingPoint
    from components.analysis.modes import drivetrain_modes
    from components.model.presets import table6_gearbox
    from components.units import rpm

    base = table6_gearbox()
    expected = drivetrain_modes(replace(base, output_shaft=replace(base.output_shaft, stiffness_nm_per_rad=2.0e4)),
                                OperatingPoint(rpm(12.0), 25.4e3)).modes[0].mode.undamped_frequency_hz
    assert generator_mode(tmp_path / "b") == pytest.approx(expected, rel=1e-9)
    assert generator_mode(tmp_path / "b") > 1.3 * generator_mode(tmp_path / "a")
    assert main(["modes", "paper-60s", "--preset", "table6", "--out", str(tmp_path / "c")]) == 1
    assert "--preset" in capsys.readouterr().err
