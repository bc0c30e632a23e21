"""``dtcosim loads`` writes ``gear_rating.csv`` (ISO 6336) from real runs: one bin of the paper turbine, 6 s.

The hand values are those of ``tests/components/analysis/test_gear_rating.py`` (Table 6 stage 1 at the
rated 9.01e5 N: sigma_H(sun) 4978.0 MPa, sigma_F(sun) 5211.8 MPa); the load cycles follow from the
stage kinematics: over one carrier revolution the stage-1 ring meets each planet once, the sun
r_ring / r_sun = 9 times, a planet r_ring / r_planet = 2.25 times.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow

SET = """
name = "one-bin"
[base]
scenario = "paper-60s"
[runs]
length = 6.0
seeds = 1
[wind]
distribution = "rayleigh"
iec_class = "II"
[bins]
edges = [10.0, 12.0]
[operating_law]
rated_wind_speed = 11.0
[life]
design_life = 20.0
availability = 0.97
"""


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def rated(tmp_path_factory, fmu_dir):
    work = tmp_path_factory.mktemp("ratings")
    (work / "set.toml").write_text(SET)
    res = dtcosim("loads", "set.toml", "--workers", "1", "--out", "out", "--fmu-dir", str(fmu_dir), "--no-plots",
                  cwd=work, timeout=900)
    assert res.returncode == 0, res.stderr
    return work, work / "out"


def test_every_mesh_and_gear_is_rated_with_the_hand_stresses(rated):
    _, out = rated
    rows = _rows(out / "gear_rating.csv")
    assert len(rows) == 26  # 2 planetary stages x 6 meshes x 2 gears + the parallel mesh's 2 gears
    sun = next(r for r in rows if r["mesh"] == "gearbox.stage1.F_sp[1]" and r["gear"] == "stage1.sun")
    assert (sun["role"], float(sun["teeth [-]"]), sun["material"]) == ("pinion", 20.0, "case-carburised steel (ISO 6336-5 Eh, MQ)")
    f = float(sun["F_max [N]"])
    assert 8.5e5 < f < 9.5e5
    assert float(sun["sigma_H_max [MPa]"]) == pytest.approx(4978.0 * math.sqrt(f / 9.01e5), rel=2e-5)
    assert float(sun["sigma_F_max [MPa]"]) == pytest.approx(5211.8 * f / 9.01e5, rel=2e-5)
    assert float(sun["S_H_static [-]"]) == pytest.approx(1500 * 1.6 / float(sun["sigma_H_max [MPa]"]), rel=1e-9)
    # the paper's gearbox (846 kN on 50 mm of face) is far beyond case-carburised steel: said, not hidden
    assert sun["design_life_met"] == "False" and float(sun["damage_bending [-]"]) > 1.0
    planet = next(r for r in rows if r["mesh"] == "gearbox.stage1.F_sp[1]" and r["gear"] == "stage1.planet[1]")
    assert float(planet["Y_M"]) == 0.7 and float(sun["Y_M"]) == 1.0


def test_load_cycles_follow_the_stage_kinematics(rated):
    _, out = rated
    rows = {(r["mesh"], r["gear"]): float(r["cycles [-]"]) for r in _rows(out / "gear_rating.csv")}
    ring = rows["gearbox.stage1.F_rp[1]", "stage1.ring"]
    assert rows["gearbox.stage1.F_sp[1]", "stage1.sun"] == pytest.approx(9.0 * ring, rel=1e-4)
    assert rows["gearbox.stage1.F_sp[1]", "stage1.planet[1]"] == pytest.approx(2.25 * ring, rel=1e-4)
    # the planet's revolutions summed over the level bins of either mesh's force: equal up to the summation's rounding
    assert rows["gearbox.stage1.F_rp[1]", "stage1.planet[1]"] == pytest.approx(
        rows["gearbox.stage1.F_sp[1]", "stage1.planet[1]"], rel=1e-12)
    # the ring meets each planet once per carrier revolution: the design life's hours in the bin at 16 rpm
    hours = float(_rows(out / "bins.csv")[0]["lifetime_operation [h]"])
    assert ring == pytest.approx(hours * 60.0 * 16.0, rel=0.01)
    # stage 3: the drive gear turns with the stage-2 sun (80 x the rotor), the driven 1.25 x faster
    assert rows["gearbox.stage3.F_mesh", "stage3.drive"] == pytest.approx(80.0 * ring, rel=1e-3)
    assert rows["gearbox.stage3.F_mesh", "stage3.driven"] == pytest.approx(100.0 * ring, rel=1e-3)


def test_the_report_and_summary_state_the_ratings_and_why_there_is_no_bearing_life(rated):
    _, out = rated
    report = (out / "lifetime_report.txt").read_text()
    assert "gear ratings (ISO 6336-2/-3/-5/-6; case-carburised steel" in report
    assert "stage1.planet[1]       (planet, 2 meshes)" in report and "BEYOND the design life" in report
    assert "bearing_life.csv not written: the gearbox (component gearbox) declares no bearing forces" in report
    assert not (out / "bearing_life.csv").exists()
    summary = json.loads((out / "lifetime.json").read_text())
    gears = {g["gear"]: g for g in summary["ratings"]["gears"]}
    assert len(gears) == 12 and summary["files"]["gear_rating"] == "gear_rating.csv"
    # the sun's flank meets three planets: its damage is theirs together
    rows = [r for r in _rows(out / "gear_rating.csv") if r["gear"] == "stage1.sun"]
    assert gears["stage1.sun"]["contact_damage"] == pytest.approx(sum(float(r["damage_contact [-]"]) for r in rows),
                                                                  rel=1e-9)


def test_new_factors_are_applied_by_report_without_running_again(rated, fmu_dir):
    work, out = rated
    (work / "set.toml").write_text(SET + "[gear_rating]\nfactors = { K_Hbeta = 1.3 }\n")
    journal = (out / "journal.jsonl").read_text()
    before = {(r["mesh"], r["gear"]): r for r in _rows(out / "gear_rating.csv")}
    res = dtcosim("loads", "set.toml", "--out", "out", "--report", "--no-plots", "--fmu-dir", str(fmu_dir), cwd=work,
                  timeout=300)
    assert res.returncode == 0, res.stderr
    assert (out / "journal.jsonl").read_text() == journal
    after = {(r["mesh"], r["gear"]): r for r in _rows(out / "gear_rating.csv")}
    key = ("gearbox.stage1.F_sp[1]", "stage1.sun")
    assert float(after[key]["sigma_H_max [MPa]"]) == pytest.approx(
        float(before[key]["sigma_H_max [MPa]"]) * math.sqrt(1.3 / 1.15), rel=1e-12)
    assert float(after[key]["K_Fbeta"]) == pytest.approx(1.3 ** (9.0 / 13.0), rel=1e-12)


def test_a_stage_the_gearbox_does_not_have_is_refused_before_running(rated, fmu_dir):
    work, _ = rated
    (work / "bad.toml").write_text(SET + "[gear_rating.stages.stage7]\nfactors = { K_A = 1.2 }\n")
    res = dtcosim("loads", "bad.toml", "--check", "--fmu-dir", str(fmu_dir), cwd=work, timeout=300)
    assert res.returncode != 0 and "Traceback" not in res.stderr
    assert "gear_rating.stages.stage7" in res.stderr and "a stage of the gearbox: stage1, stage2, stage3" in res.stderr
