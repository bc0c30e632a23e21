"""``dtcosim loads`` on real FMUs: 2 bins x 2 seeds on a LocalCluster of 2 workers, killed and resumed."""

from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow

SET = """
name = "two-by-two"
[base]
scenario = "paper-60s"
[runs]
length = 6.0
transient = 3.0
seeds = 2
[wind]
distribution = "rayleigh"
iec_class = "II"
[bins]
edges = [8.0, 10.0, 12.0]
[operating_law]
rated_wind_speed = 11.0
[life]
design_life = 20.0
availability = 0.97
[fatigue]
residue = "repeat"
channels = ["wind.phi", "generator.phi"]   # the rotor and generator angles: the exact integrals of their speeds
[[sn_curves]]
applies_to = ["shaft_torque", "rotor_torque"]
slope = 5.0
ultimate = 5.0e7
goodman = true
"""


def _journal(out: Path) -> list[dict]:
    path = out / "journal.jsonl"
    if not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip().endswith("}")]


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def killed_and_resumed(tmp_path_factory, fmu_dir):
    """The set started, killed (SIGKILL to its whole process group) after its first finished run, run again."""
    work = tmp_path_factory.mktemp("loads")
    (work / "set.toml").write_text(SET)
    out = work / "out"
    exe = Path(sys.executable).parent / "dtcosim"
    cmd = [str(exe), "loads", "set.toml", "--workers", "2", "--out", str(out), "--fmu-dir", str(fmu_dir), "-q",
           "--executor", "dask"]
    proc = subprocess.Popen(cmd, cwd=work, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 600
    try:
        while not any(r["status"] == "ok" for r in _journal(out)):
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "no run finished in 600 s"
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the command, its LocalCluster and its workers, as a crash would
        proc.wait(timeout=60)
        proc.stderr.close()
    before = _journal(out)
    second = dtcosim("loads", "set.toml", "--workers", "2", "--out", str(out), "--fmu-dir", str(fmu_dir), cwd=work,
                     timeout=900)
    assert second.returncode == 0, second.stderr
    return out, before, second


@pytest.mark.slow
def test_sigterm_stops_the_set_with_128_plus_the_signal_and_keeps_what_finished(tmp_path, fmu_dir):
    """``dtcosim loads`` exited 130 whatever the signal (issue 35.8): SIGTERM gives 143, as ``sweep``."""
    (tmp_path / "set.toml").write_text(SET)
    out = tmp_path / "out"
    cmd = [str(Path(sys.executable).parent / "dtcosim"), "loads", "set.toml", "--workers", "1", "--out", str(out),
           "--fmu-dir", str(fmu_dir), "-q"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600
    while not any(r["status"] == "ok" for r in _journal(out)) and proc.poll() is None:
        assert time.monotonic() < deadline, "no run finished in 600 s"
        time.sleep(0.05)
    if proc.poll() is not None:
        pytest.skip("the set finished before it could be stopped")
    os.killpg(proc.pid, signal.SIGTERM)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 143, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    assert any(r["status"] == "ok" for r in _journal(out))


def test_killing_and_starting_again_repeats_no_finished_run(killed_and_resumed):
    out, before, second = killed_and_resumed
    done_before = {r["key"] for r in before if r["status"] == "ok"}
    assert 1 <= len(done_before) < 4  # killed in the middle
    after = _journal(out)[len(before):]
    assert not done_before & {r["key"] for r in after}
    ok = [r for r in _journal(out) if r["status"] == "ok"]
    assert len(ok) == 4 and len({r["key"] for r in ok}) == 4
    assert f"{len(done_before)} already in" in second.stderr
    assert all((out / r["run_file"]).is_file() for r in ok)


def test_per_run_and_lifetime_tables_are_written(killed_and_resumed):
    out, _, second = killed_and_resumed
    runs = _rows(out / "runs.csv")
    assert {(r["run"], r["status"]) for r in runs} == {(str(i), "ok") for i in range(4)}
    assert {r["unit"] for r in runs if r["channel"] == "gearbox.shaft3.torque"} == {"N.m"}
    life = _rows(out / "lifetime_del.csv")
    channels = {r["channel"] for r in life}
    assert {"gearbox.shaft1.torque", "gearbox.shaft3.torque", "gearbox.torque_rotor", "gearbox.stage3.F_mesh"} <= channels
    assert all(float(r["lifetime_del"]) > 0 for r in life if r["channel"].startswith("gearbox."))
    damage = _rows(out / "damage_by_bin.csv")
    hss = [r for r in damage if r["channel"] == "gearbox.shaft3.torque" and r["bin"] != "lifetime"]
    assert sum(float(r["share [-]"]) for r in hss) == pytest.approx(1.0, rel=1e-12)
    for name in ("bins.csv", "ldd.csv", "lrd.csv", "lifetime.json", "lifetime_report.txt", "damage_by_bin.png",
                 "ldd.png", "lrd.png"):
        assert (out / name).is_file(), name
    report = (out / "lifetime_report.txt").read_text()
    assert "high-speed shaft (gearbox.shaft3.torque)" in report and "stage3 parallel mesh" in report


def _run_stats(out: Path) -> dict[int, dict]:
    return {r["index"]: r for r in _journal(out) if r["status"] == "ok"}


def test_load_revolutions_equal_the_integral_of_the_speed_and_bin_times_sum_to_the_runs(killed_and_resumed):
    from orchestrator.inputs.load_case_file import load_load_cases
    from orchestrator.study.lifetime_results import read_run_file

    out, _, _ = killed_and_resumed
    lcs = load_load_cases(out.parent / "set.toml")
    for index, rec in _run_stats(out).items():
        run = read_run_file(out / rec["run_file"])
        assert run.analysed_time_s == pytest.approx(lcs.length_s, rel=1e-12)
        for column, gear, angle in (("gearbox.torque_rotor", "rotor", "wind.phi"),
                                    ("gearbox.shaft3.torque", "generator", "generator.phi")):
            levels = run.levels[column]
            turned = rec["loads"][angle]["max"] - rec["loads"][angle]["min"]  # monotonic angle over the window
            assert levels.total_revolutions(gear) * 2 * math.pi == pytest.approx(turned, rel=1e-6)
            assert levels.total_time_s == pytest.approx(lcs.length_s, rel=1e-12)
    # per bin: the times of its runs' levels sum to seeds x run length, on the lifetime's lattice too
    rows = _rows(out / "ldd.csv")
    for b in (0, 1):
        times = [float(r["time [s]"]) for r in rows if r["channel"] == "gearbox.shaft2.torque" and r["scope"] == f"bin {b}"]
        assert sum(times) == pytest.approx(len(lcs.seeds) * lcs.length_s, rel=1e-12)
    lifetime = [float(r["time [s]"]) for r in rows if r["channel"] == "gearbox.shaft2.torque" and r["scope"] == "lifetime"]
    share = sum(b.probability for b in lcs.bins)
    assert sum(lifetime) == pytest.approx(lcs.life.availability * share * lcs.life.seconds, rel=1e-12)


def test_report_recomputes_after_a_changed_design_life_without_running(killed_and_resumed, fmu_dir):
    out, _, _ = killed_and_resumed
    text = (out.parent / "set.toml").read_text().replace("design_life = 20.0", "design_life = 40.0")
    (out.parent / "set40.toml").write_text(text)
    before = {r["channel"]: float(r["lifetime_del"]) for r in _rows(out / "lifetime_del.csv")
              if r["wohler_exponent [-]"] == "5.0"}
    proc = dtcosim("loads", "set40.toml", "--out", str(out), "--fmu-dir", str(fmu_dir), "--report", cwd=out.parent)
    assert proc.returncode == 0, proc.stderr
    after = {r["channel"]: float(r["lifetime_del"]) for r in _rows(out / "lifetime_del.csv")
             if r["wohler_exponent [-]"] == "5.0"}
    for channel, value in before.items():
        assert after[channel] == pytest.approx(value * 2 ** (1 / 5), rel=1e-12)


def test_workers_publish_the_progress_of_each_running_case(tmp_path, fmu_dir):
    from dataclasses import replace

    from orchestrator.inputs.load_case_file import load_cases_from_dict
    from orchestrator.study.lifetime_results import store_run_data
    from orchestrator.study.load_cases import prepare_load_cases
    from orchestrator.study.sweep import run_sweep

    lcs = load_cases_from_dict({"base": {"scenario": "paper-60s"}, "runs": {"length": 1.0, "transient": 0.5, "seeds": 2},
                                "wind": {"distribution": "weibull", "k": 2.0, "A": 9.0},
                                "bins": {"edges": [10.0, 12.0]}, "operating_law": {"rated_wind_speed": 11.0}})
    plc = prepare_load_cases(lcs, fmu_dir=fmu_dir)
    prepared = replace(plc.prepared, payload=replace(plc.prepared.payload, progress_topic="test-progress"))
    events, records = [], []
    report = run_sweep(prepared, tmp_path, workers=1, plots=False, progress=records.append,
                       on_result=store_run_data(plc, tmp_path), case_progress=events.append)
    assert report.ok == 2
    steps = round(1.5 / plc.prepared.payload.system.scenario.simulation.step_s)
    for case in plc.cases:
        mine = [e for e in events if e["index"] == case.index]
        # events arrive through the scheduler, apart from the results: the last ones may come after the sweep
        assert mine and all(e["total"] == steps and 0 < e["done"] <= steps for e in mine)
        assert [e["done"] for e in mine] == sorted(e["done"] for e in mine)
    assert all(r["run_file"].startswith("runs/") for r in records)
