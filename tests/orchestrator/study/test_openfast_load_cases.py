"""The packaged load-case set ``openfast-dlc11``: the four OpenFAST DLC 1.1 records of ``../shared/openfast-data``,
one per wind-speed bin (their mean Wind1VelX: 14, 16, 18, 20 m/s), checked, run on a LocalCluster of 2 workers,
each run playing its own record, and the lifetime report ranking the bins."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from orchestrator.inputs.load_case_file import find_load_cases, load_load_cases
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.inputs.series_file import read_load_record
from tests.helpers.openfast_data import openfast_file

RECORDS = [f"DLC1.1_0_NREL5MW_OC3_spar_{i}.outb" for i in range(4)]


def _records():
    return [read_load_record(openfast_file(name)) for name in RECORDS]  # skips without the shared data


def test_each_bin_plays_the_record_whose_mean_wind_speed_it_holds():
    records = _records()
    lcs = load_load_cases(find_load_cases("openfast-dlc11"))
    series = load_scenario(find_scenario("openfast-dlc11-records")).component("loads").series
    assert [r.record.name for r in series.records] == RECORDS
    assert len(lcs.bins) == 4 and lcs.seeds == (1,) and lcs.seed_parameter == ""
    for b in lcs.bins:
        number = b.parameters["loads.record"]
        wind = records[number - 1].channel("Wind1VelX")[1]
        assert b.low_m_s <= wind.mean() < b.high_m_s
        assert b.centre_m_s == pytest.approx(wind.mean(), abs=0.01)  # bins centred on the records' means
    assert sorted(b.parameters["loads.record"] for b in lcs.bins) == [1, 2, 3, 4]
    assert lcs.transient_s is None and lcs.length_s is None  # "settled", "to_stop"
    settled, _ = lcs.settled(2.753, "", 10.0)
    assert settled.time_grid().window_s == (2.8, 10.0)  # runs inside the 10 s records, to their end


def _dtcosim(*args, cwd):
    exe = Path(sys.executable).parent / "dtcosim"
    return subprocess.run([str(exe), *args], cwd=cwd, capture_output=True, text=True, env=dict(os.environ),
                          timeout=900)


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    _records()
    work = tmp_path_factory.mktemp("openfast-loads")
    fmus, out = work / "fmus", work / "out"
    check = _dtcosim("loads", "openfast-dlc11", "--check", "--fmu-dir", str(fmus), cwd=work)
    run = _dtcosim("loads", "openfast-dlc11", "--workers", "2", "--out", str(out), "--fmu-dir", str(fmus), "-q",
                   cwd=work)
    return check, run, out, work, fmus


@pytest.mark.slow
def test_the_set_validates_and_counts_its_runs(ran):
    check = ran[0]
    assert check.returncode == 0, check.stderr
    assert "valid" in check.stdout and "4 bins x 1 seeds = 4 runs of 2.8 + 7.2 s" in check.stdout
    assert "warning" not in check.stderr, check.stderr


@pytest.mark.slow
def test_a_record_out_of_range_is_refused_before_running(ran, tmp_path):
    work, fmus = ran[3], ran[4]
    text = find_load_cases("openfast-dlc11").read_text().replace('"loads.record" = 4', '"loads.record" = 5')
    text = text.replace('scenario = "openfast-dlc11-records"', f'scenario = "{find_scenario("openfast-dlc11-records")}"')
    (tmp_path / "bad.toml").write_text(text)
    res = _dtcosim("loads", str(tmp_path / "bad.toml"), "--check", "--fmu-dir", str(fmus), cwd=work)
    assert res.returncode != 0
    assert "loads.record" in res.stderr and "an integer within [1, 4]" in res.stderr and "Traceback" not in res.stderr


@pytest.mark.slow
def test_four_runs_play_four_records_and_the_report_ranks_the_bins(ran):
    _, run, out, _, _ = ran
    assert run.returncode == 0, run.stderr
    for name in ("bins.csv", "runs.csv", "lifetime_del.csv", "damage_by_bin.csv", "ldd.csv", "lrd.csv",
                 "lifetime.json", "lifetime_report.txt", "damage_by_bin.png", "ldd.png", "lrd.png"):
        assert (out / name).is_file(), name
    records = _records()
    rows = _rows(out / "runs.csv")
    lcs = load_load_cases(find_load_cases("openfast-dlc11"))
    summary = json.loads((out / "lifetime.json").read_text())
    assert summary["transient_s"] == 2.8 and summary["length_s"] == pytest.approx(7.2)
    assert summary["settling"]["frequency_hz"] == pytest.approx(6.88, abs=0.01)
    assert "settling time of the drivetrain: 2.75 s = 5 time constants of the 6.88 Hz mode" in \
        (out / "lifetime_report.txt").read_text()
    w0, w1 = 2.8, 10.0
    speeds = []
    for b in lcs.bins:
        rec = records[b.parameters["loads.record"] - 1]
        inside = (rec.time_s >= w0) & (rec.time_s <= w1)
        by = {r["channel"]: r for r in rows if int(r["bin"]) == b.index}
        assert {r["status"] for r in by.values()} == {"ok"}
        # the played generator torque: linear between the record's samples, so its extremes are the record's
        gen = rec.channel("GenTq")[1][inside] * 1e3
        played = by["loads.generator_torque"]
        assert float(played["max"]) == pytest.approx(gen.max(), rel=1e-9)
        assert float(played["min"]) == pytest.approx(gen.min(), rel=1e-3)
        assert float(played["mean"]) == pytest.approx(gen.mean(), rel=1e-3)
        speed = rec.channel("RotSpeed")[1][inside] * np.pi / 30
        assert float(by["loads.rotor_speed"]["mean"]) == pytest.approx(speed.mean(), rel=1e-4)
        assert float(by["loads.rotor_speed"]["std"]) == pytest.approx(speed.std(), rel=0.05)
        speeds.append((float(by["loads.rotor_speed"]["std"]), float(played["mean"])))
    assert len(set(speeds)) == 4  # four different records
    report = (out / "lifetime_report.txt").read_text()
    hss = report.split("high-speed shaft (gearbox.hss_coupling.torque)")[1].split("\n\n")[0]
    ranked = [line.split()[1] for line in hss.splitlines()[1:] if line.strip()[:2] in ("1.", "2.", "3.", "4.")]
    assert sorted(ranked) == ["[13,", "[15,", "[17,", "[19,"]
    for stage in ("planetary1 sun_planet", "planetary2 sun_planet", "high_speed parallel"):
        assert f"{stage} mesh" in report
    hss_rows = [r for r in _rows(out / "damage_by_bin.csv") if r["channel"] == "gearbox.hss_coupling.torque"]
    assert float(hss_rows[0]["damage [-]"]) > 0 and hss_rows[0]["bin"] == "lifetime"
    assert sum(float(r["share [-]"]) for r in hss_rows[1:]) == pytest.approx(1.0, rel=1e-9)


@pytest.mark.slow
def test_the_report_says_when_one_cycle_carries_the_shaft_lifetime(ran):
    # the 10 s records drift (the rotor slows from 12.1 to 11.3-11.6 rpm): with m = 5 one half cycle of the
    # residue in the 14 m/s run, spanning that drift, carries most of the high-speed shaft's lifetime damage
    out = ran[2]
    summary = json.loads((out / "lifetime.json").read_text())
    big = summary["channels"]["gearbox.hss_coupling.torque"]["largest_cycle"]
    assert big["count"] == 0.5 and big["bin"] == "[13, 15) m/s" and big["share"] > 0.5
    report = (out / "lifetime_report.txt").read_text()
    hss = report.split("high-speed shaft (gearbox.hss_coupling.torque)")[1].split("\n\n")[0]
    assert f"NOTE: {100 * big['share']:.0f} % of this lifetime damage comes from one cycle, a half cycle" in hss


@pytest.mark.slow
def test_the_5mw_gears_are_rated_within_their_endurance_limits(ran):
    # the 5-MW gears (nrel5mw-oc3: 600 / 350 / 250 mm faces) stay below the ISO 6336-5 endurance limits in these
    # records: no damage, spectrum safety factors above 1 in contact and bending
    out = ran[2]
    gears = json.loads((out / "lifetime.json").read_text())["ratings"]["gears"]
    assert len(gears) == 12
    assert all(g["contact_damage"] == 0.0 and g["bending_damage"] == 0.0 for g in gears)
    assert min(g["S_H_life"] for g in gears) > 1.0 and min(g["S_F_life"] for g in gears) > 1.0
    assert (out / "gear_rating.csv").is_file() and not (out / "bearing_life.csv").exists()
