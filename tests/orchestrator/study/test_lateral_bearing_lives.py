"""``dtcosim loads`` on the lateral-torsional gearbox: every bearing's force from the Gearbox FMU, ISO 281 lives.

One bin at the paper turbine's rated point (16 rpm, 25.4 kN m; the wind's fluctuation of 0.12 rpm) of
``paper-60s-lateral``. Hand values: a stage-1 planet bearing carries the planet's share of the carrier torque at
the carrier radius, ``P = T_c / (N r_c) = 2.54e6 N m / (3 x 0.5 m) = 1.6933e6 N``, turning at the planet's speed
relative to the carrier, ``16 rpm x r_ring / r_planet = 36 rpm``; so ``L10h = (C / P)^(10/3) 1e6 / (60 x 36)``
with the file's C = 1e7 N (roller). The drive gear of the parallel stage carries its mesh force, ``T / r_b =
31.75 kN m / (0.1 m cos 20 deg) = 3.3788e5 N`` at 1280 rpm.
"""

from __future__ import annotations

import csv
import math

import pytest

from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow

SET = """
[base]
scenario = "paper-60s-lateral"
[runs]
length = 4.0
transient = 3.0
seeds = 1
[wind]
distribution = "rayleigh"
iec_class = "II"
[bins]
edges = [11.0, 13.0]
[operating_law]
rated_wind_speed = 12.0
rated_rotor_speed_rpm = 16.0
rated_torque = 25.4e3
rated_sigma_rpm = 0.12
rated_spectrum_level = 0.02
[life]
design_life = 20.0
availability = 0.97
[bearing_life]
reliability = 90.0
"""


def test_planet_and_gear_bearings_have_their_iso_281_lives(tmp_path):
    (tmp_path / "lateral.toml").write_text(SET)
    out = tmp_path / "out"
    proc = dtcosim("loads", "lateral.toml", "--out", str(out), "--fmu-dir", str(tmp_path / "fmus"), cwd=tmp_path,
                   timeout=1800)
    assert proc.returncode == 0, proc.stderr
    rows = {r["bearing"]: r for r in csv.DictReader((out / "bearing_life.csv").open())}
    planets = [f"stage{s}.planet_bearing[{i}]" for s in (1, 2) for i in (1, 2, 3)]
    assert set(rows) == set(planets) | {f"stage{s}.{m}_bearing" for s in (1, 2) for m in ("sun", "carrier")} | {
        "stage3.drive_bearing", "stage3.driven_bearing"}
    planet = rows["stage1.planet_bearing[1]"]
    load = 2.54e6 / (3 * 0.5)
    assert float(planet["P_eq [N]"]) == pytest.approx(load, rel=5e-3)  # the wind's 0.7 % fluctuation on top
    hours = float(planet["operating_hours [h]"])
    assert float(planet["revolutions [-]"]) == pytest.approx(hours * 60.0 * 36.0, rel=5e-3)
    p_eq = float(planet["P_eq [N]"])
    assert float(planet["L10 [h]"]) == pytest.approx((1e7 / p_eq) ** (10.0 / 3.0) * 1e6 / (60.0 * 36.0), rel=5e-3)
    assert float(rows["stage3.drive_bearing"]["P_eq [N]"]) == pytest.approx(31.75e3 / (0.1 * math.cos(math.radians(20.0))),
                                                                            rel=5e-3)
    # the planets share alike: equal lives
    assert float(rows["stage1.planet_bearing[3]"]["L10 [h]"]) == pytest.approx(float(planet["L10 [h]"]), rel=1e-6)
    # the suns and carriers float: round-off, reported as no load (not an L10 of ~1e50 h)
    for s in (1, 2):
        for m in ("sun", "carrier"):
            row = rows[f"stage{s}.{m}_bearing"]
            assert float(row["P_eq [N]"]) < 1e-9 * float(row["C [N]"]) and row["L10 [h]"] == ""
            assert row["note"].startswith("unloaded: P_eq at round-off") and row["met"] == "True"
    line = next(x for x in (out / "lifetime_report.txt").read_text().splitlines() if x.strip().startswith("stage1.sun_bearing "))
    assert "no load to rate" in line and "L10" not in line
