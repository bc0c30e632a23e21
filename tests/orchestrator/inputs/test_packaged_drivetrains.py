"""The packaged drivetrain files: the paper presets unchanged, the 4-planet Table 6, the GRC-like gearbox."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from components.model.parameter_map import flatten
from components.model.presets import cosim_preset, preset
from components.reference.cases import CASES, run_case, run_reference_case
from orchestrator.inputs.drivetrain_file import (
    find_drivetrain,
    load_drivetrain_file,
    packaged_drivetrains,
)
from tests.helpers.scenarios import dtcosim


def spec(name):
    return load_drivetrain_file(find_drivetrain(name))


def test_the_packaged_files():
    assert {"paper-table3", "paper-table5", "paper-table6", "paper-table6-4planets", "grc-like"} <= set(packaged_drivetrains())


@pytest.mark.parametrize("name, code", [("paper-table3", "table3"), ("paper-table5", "table5"), ("paper-table6", "table6")])
def test_paper_files_are_the_presets(name, code):
    dt = spec(name).drivetrain
    assert dt == preset(code)  # the same frozen objects, field by field
    a, b = flatten(dt), flatten(preset(code))
    assert a.keys() == b.keys() and all(a[k] == b[k] for k in a)
    if code == "table6":
        assert dt == cosim_preset("table6")


@pytest.mark.parametrize("case, name", [("table2", "paper-table3"), ("table4", "paper-table5")])
def test_table2_and_table4_cases_through_the_files_are_unchanged(case, name):
    paper = CASES[case]
    from dataclasses import replace

    _, driver = paper.build()
    dt = spec(name).drivetrain
    through_file = replace(paper, build=lambda: (dt, driver))
    _, stats_file = run_reference_case(through_file)
    _, stats_preset = run_case(case)
    assert stats_file.keys() == stats_preset.keys()
    for k in stats_preset:
        for m in ("mean", "std", "min", "max"):
            assert stats_file[k][m] == stats_preset[k][m], (k, m)


def test_grc_like_ratio_and_design_table(tmp_path):
    proc = dtcosim("drivetrain", "show", "grc-like", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "total ratio 81.491 " in proc.stdout
    assert "drivetrain file grc-like.toml (sha256 " in proc.stdout
    for text in ("check ring teeth: ok", "check assembly: ok", "check planet clearance: ok", "derived: bored disc"):
        assert text in proc.stdout
    assert math.isclose(spec("grc-like").drivetrain.ratio, (1 + 99 / 21) * (82 / 23) * (88 / 22), rel_tol=1e-15)
    table = json.loads(dtcosim("drivetrain", "show", "grc-like", "--json", cwd=tmp_path).stdout)
    assert [s["name"] for s in table["stages"]] == ["planetary", "intermediate", "high_speed"]
    assert table["stages"][0]["teeth"] == {"sun": 21.0, "planet": 39.0, "ring": 99.0}
    # 750 kW at the rated point
    gen = table["generator"]
    assert gen["counter_torque_nm"] * gen["speed_rad_s"] == pytest.approx(750e3, rel=1e-3)


def test_four_planets_static_force_in_the_design_table(tmp_path):
    proc = dtcosim("drivetrain", "show", "paper-table6-4planets", "--json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    table = json.loads(proc.stdout)
    stage1 = table["stages"][0]
    assert stage1["n_planets"] == 4 and stage1["ratio"] == 6.0 and table["ratio"] == 60.0
    t_sun = 25400.0 * 60.0 / 6.0  # generator torque x total ratio = rotor torque; / R1 on the sun
    r_b_sun = 0.1 * math.cos(math.radians(20.0))
    sp = next(m for m in stage1["meshes"] if m["kind"] == "sun_planet")
    assert sp["static_force_n"] == pytest.approx(t_sun / (4 * r_b_sun), rel=1e-6)
    # the text table prints the same number
    text = dtcosim("drivetrain", "show", "paper-table6-4planets", cwd=tmp_path).stdout
    assert f"static sun-planet force {sp['static_force_n']:.10g} N per planet (x4)" in text


def test_four_planets_constant_load_run_means_are_the_static_forces(tmp_path):
    proc = dtcosim("reference", "--drivetrain", "paper-table6-4planets", "--file-case", "constant", "--json",
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    runs = json.loads(proc.stdout)
    (summary,) = runs
    static = summary["static_force_n"]
    assert {f"stage1.F_sp[{i}]" for i in range(1, 5)} <= set(static)
    for name, force in static.items():
        mean = summary["statistics"][name]["mean"]
        assert abs(mean / force - 1.0) < 1e-3, (name, mean, force)
    assert static["stage1.F_sp[1]"] == pytest.approx(25400.0 * 10.0 / (4 * 0.1 * math.cos(math.radians(20.0))))


@pytest.mark.slow
def test_four_planets_modes_have_the_planet_modes_of_stage1_three_times(tmp_path):
    proc = dtcosim("modes", "--drivetrain", "paper-table6-4planets", "--out", str(tmp_path / "m"),
                   "--speed-points", "3", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    modes = json.loads((tmp_path / "m" / "modes.json").read_text())["modes"]
    planet = [m for m in modes if m["kind"] == "planet" and m["stage"] == "stage1"]
    assert len(planet) == 3  # n - 1 = 3
    f = [m["undamped_frequency_hz"] for m in planet]
    assert max(f) - min(f) < 1e-6 * f[0]
    others = [m["undamped_frequency_hz"] for m in modes if m not in planet]
    assert min(abs(np.array(others) - f[0])) > 1e-3 * f[0]  # a multiplicity of exactly three
    assert "drivetrain file paper-table6-4planets.toml" in proc.stdout


def test_cli_errors_name_the_file_and_key_without_a_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(find_drivetrain("grc-like").read_text().replace("planets = 3", "planets = 0"))
    proc = dtcosim("drivetrain", "show", str(bad), cwd=tmp_path)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert f"{bad}: invalid drivetrain entry stages[0].planets = 0: expected a whole number of planets >= 1" in proc.stderr
    proc = dtcosim("build", "--drivetrain", "paper-table3", "--out", str(tmp_path / "f"), cwd=tmp_path)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert "paper-table3.toml: invalid drivetrain entry generator = None: expected a [generator] table" in proc.stderr
    assert not (tmp_path / "f").exists()
    proc = dtcosim("drivetrain", "show", "no-such-gearbox", cwd=tmp_path)
    assert proc.returncode == 1 and "one of the packaged drivetrain files: " in proc.stderr and "grc-like" in proc.stderr


@pytest.mark.slow
def test_reference_of_a_drivetrain_file_runs_the_constant_and_the_wind_case(tmp_path):
    proc = dtcosim("reference", "--drivetrain", "grc-like", "--t-end", "6", "--json", "--out", str(tmp_path / "r"),
                   "--no-plots", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    constant, wind = json.loads(proc.stdout)
    assert constant["case"] == "constant" and wind["case"] == "wind"
    assert constant["drivetrain"].startswith("drivetrain file grc-like.toml (sha256 ")
    assert (tmp_path / "r" / "constant" / "summary.json").is_file() and (tmp_path / "r" / "wind" / "summary.json").is_file()
    for name in ("planetary.F_sp[2]", "intermediate.F_mesh", "high_speed.F_mesh"):
        assert constant["statistics"][name]["mean"] == pytest.approx(constant["static_force_n"][name], rel=1e-3)
    assert wind["statistics"]["omega_rotor"]["std"] > 1e-3 > 1e-12 > constant["statistics"]["omega_rotor"]["std"]
