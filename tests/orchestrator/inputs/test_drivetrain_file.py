"""Drivetrain description files: what they describe, their units, and one named error per bad file."""

from __future__ import annotations

import copy
import math
import re
import tomllib

import pytest

from components import units
from components.model.parameter_map import flatten
from orchestrator.inputs.drivetrain_entries import with_entries
from orchestrator.inputs.drivetrain_file import (
    DrivetrainFileError,
    drivetrain_from_dict,
    load_drivetrain_file,
)

#: a valid two-stage file (paper units for lengths and angles, SI otherwise: [units] names every dimension it uses)
BASE = """
name = "two-stage"
[units]
length = "mm"
angle = "deg"
mass = "kg"
inertia = "kg.m2"
contact_stiffness = "N/m^e"
contact_damping = "N.s/m2"
regularisation = "1/m"
torsional_stiffness = "N.m/rad"
torsional_damping = "N.m.s/rad"
torque = "N.m"

[mesh]
k0 = 1.2e11
c0 = 5.0e10
lambda = 6.0e5
backlash = 0.5

[[stages]]
name = "sp"
kind = "planetary"
module = 10.0
pressure_angle = 20.0
face_width = 50.0
teeth = { sun = 21, planet = 39, ring = 99 }
planets = 3
sun = { disc = "solid" }
planet = { mass = 100.0, inertia = 2.0 }

[[stages]]
name = "par"
kind = "parallel"
module = 5.0
pressure_angle = 20.0
face_width = 40.0
teeth = { drive = 88, driven = 22 }
drive = { disc = "bored", bore_diameter = 100.0 }
driven = { disc = "solid" }

[[shafts]]
stiffness = 1.0e7
damping = 1.0e3
[[shafts]]
stiffness = 6.0e4
damping = 600.0

[generator]
inertia = 24.0
counter_torque = 4000.0
"""


def base() -> dict:
    return tomllib.loads(BASE)


def read(doc: dict):
    return drivetrain_from_dict(doc, source="bad.toml")


def test_the_base_file_reads_in_si():
    spec = read(base())
    sp, par = spec.drivetrain.stages
    assert sp.sun_radius_m == pytest.approx(0.105) and sp.ring_radius_m == pytest.approx(0.495)
    assert sp.planet_radius_m == pytest.approx(0.195)
    assert sp.sun_mesh.pressure_angle_rad == pytest.approx(math.radians(20.0))
    assert sp.sun_mesh.backlash_normal_m == pytest.approx(5e-4)  # length unit mm
    assert sp.sun_mesh.stiffness == 1.2e11  # contact stiffness in N/m^e, as [units] names it
    # derived sun: solid steel disc of the pitch diameter and face width, by hand
    mass = 7800.0 * math.pi * 0.105**2 * 0.05
    assert sp.sun_mass_kg == pytest.approx(mass, rel=1e-12)
    assert sp.sun_inertia_kgm2 == pytest.approx(0.5 * mass * 0.105**2, rel=1e-12)
    # derived bored wheel: m = rho pi (ro^2 - ri^2) b, J = m (ro^2 + ri^2) / 2
    ro, ri = 0.22, 0.05
    m = 7800.0 * math.pi * (ro**2 - ri**2) * 0.04
    assert par.drive_mass_kg == pytest.approx(m, rel=1e-12)
    assert par.drive_inertia_kgm2 == pytest.approx(0.5 * m * (ro**2 + ri**2), rel=1e-12)
    assert spec.drivetrain.ratio == pytest.approx((1 + 99 / 21) * 4)
    sources = {b.name: b.source for rows in spec.bodies.values() for b in rows}
    assert sources["sp.planet"] == "given" and sources["sp.sun"].startswith("derived: solid disc")
    assert sources["par.drive"].startswith("derived: bored disc (bore 100 mm)")
    assert [c.name for c in spec.checks["sp"]][:3] == ["ring teeth", "assembly", "planet clearance"]
    assert all(c.passed for c in spec.checks["sp"]) and all(j.passed for j in spec.judgements)


def test_paper_units_convert_like_the_paper_tables():
    doc = base()
    doc["units"].update(contact_stiffness="N/mm^e", contact_damping="N.s/mm2", regularisation="1/mm",
                        torsional_stiffness="N.mm/deg", torsional_damping="N.mm.s/deg", torque="N.mm",
                        inertia="kg.mm2", speed="rpm")
    doc["mesh"].update(k0=5.0e5, c0=5.0e4, **{"lambda": 600.0})
    doc["operating_point"] = {"rotor_speed": 16.0}
    # the same numbers in other units: a 2e-6 kg m^2 planet and a 4 N m load are implausible, on purpose
    doc["plausibility"] = {"allow": ["sp.planet_inertia", "sp.k0", "par.k0"]}
    spec = read(doc)
    mesh = spec.drivetrain.stages[0].sun_mesh
    assert mesh.stiffness == pytest.approx(5.0e5 * 1e3**1.5)   # N/mm^1.5 -> N/m^1.5
    assert mesh.damping == pytest.approx(5.0e4 * 1e6)          # N s/mm^2 -> N s/m^2
    assert mesh.regularisation == pytest.approx(6.0e5)
    assert spec.drivetrain.shafts[0].stiffness_nm_per_rad == pytest.approx(1.0e7 * 1e-3 * 180 / math.pi)
    assert spec.drivetrain.generator.counter_torque_nm == pytest.approx(4.0)  # 4000 N mm
    assert spec.drivetrain.generator.inertia_kgm2 == pytest.approx(24.0e-6)
    assert spec.drivetrain.stages[0].planet_inertia_kgm2 == pytest.approx(2.0e-6)
    assert spec.rotor_speed_rad_s == pytest.approx(units.rpm(16.0))


def test_per_mesh_contact_overrides_the_defaults_and_separates_the_flat_names():
    doc = base()
    doc["stages"][0]["sun_mesh"] = {"k0": 2.0e11}
    doc["stages"][0]["mesh"] = {"c0": 1.0e9}
    doc["stages"][1]["mesh"] = {"law": "impact", "impact_depth": 0.2}
    dt = read(doc).drivetrain
    sp, par = dt.stages
    assert sp.sun_mesh.stiffness == 2.0e11 and sp.ring_mesh.stiffness == 1.2e11
    assert sp.sun_mesh.damping == sp.ring_mesh.damping == 1.0e9  # the stage's mesh table, under both
    assert par.mesh.law == "impact" and par.mesh.impact_depth_m == pytest.approx(2e-4)
    names = flatten(dt)
    assert names["sp.sun_mesh.k0"] == 2.0e11 and names["sp.ring_mesh.k0"] == 1.2e11
    assert "sp.k0" not in names and names["par.contact_law"] == 1.0


def test_explicit_planet_angles_reach_the_mesh_phasing():
    from components.model.assembly import Assembly

    doc = base()
    doc["stages"][0]["planet_angles"] = [0.0, 123.0, 240.0]  # (21 + 99) psi / 360 = 0, 41, 80
    dt = read(doc).drivetrain
    assert dt.stages[0].planet_positions_rad == pytest.approx(tuple(math.radians(a) for a in (0, 123, 240)))
    mesh = {m.name: m for m in Assembly(dt).meshes}
    assert mesh["sp.F_sp[2]"].phase_offset_rad == pytest.approx(-21 * math.radians(123.0))
    assert mesh["sp.F_rp[3]"].phase_offset_rad == pytest.approx(99 * math.radians(240.0))


def test_with_entries_changes_numbers_and_structure():
    spec = read(base())
    changed = with_entries(spec, {"stages[0].planets": 4, "generator.inertia": 30.0})
    assert changed.drivetrain.stages[0].n_planets == 4 and changed.drivetrain.generator.inertia_kgm2 == 30.0
    assert changed.sha256 != spec.sha256 and spec.drivetrain.stages[0].n_planets == 3
    with pytest.raises(DrivetrainFileError, match=r"stages\[0\]\.teeth\.sunn"):
        with_entries(spec, {"stages[0].teeth.sunn": 3})
    with pytest.raises(DrivetrainFileError, match=r"stages\[0\]\.planets .*assembled"):
        with_entries(spec, {"stages[0].planets": 7})


def _set(path, value):
    def change(doc):
        node = doc
        *head, last = path
        for p in head:
            node = node[p]
        node[last] = value
    return change


def _delete(path):
    def change(doc):
        node = doc
        *head, last = path
        for p in head:
            node = node[p]
        del node[last]
    return change


def _both(*changes):
    def change(doc):
        for c in changes:
            c(doc)
    return change


#: (what is wrong, change of the base document, expected message pattern: key path and expectation)
BAD_FILES = [
    ("missing stage field", _delete(["stages", 0, "module"]), r"stages\[0\]\.module = None: expected .*module.*missing"),
    ("negative module", _set(["stages", 1, "module"], -5.0), r"stages\[1\]\.module = -5\.0: expected a number > 0"),
    ("ring teeth not Z_sun + 2 Z_planet", _set(["stages", 0, "teeth", "ring"], 100),
     r"stages\[0\]\.teeth\.ring = 100: expected Z_sun \+ 2 Z_planet = 99"),
    ("failed assembly condition", _set(["stages", 0, "planets"], 7),
     r"stages\[0\]\.planets = 7: expected planets that can be assembled: \(Z_sun \+ Z_ring\) / n = 120 / 7"),
    ("overlapping planets", _both(_set(["stages", 0, "teeth"], {"sun": 20, "planet": 80, "ring": 180}),
                                  _set(["stages", 0, "planets"], 4)),
     r"stages\[0\]\.planets = 4: expected planets that do not overlap \(smallest gap .* -11[0-9.]* mm"),
    ("zero planets", _set(["stages", 0, "planets"], 0), r"stages\[0\]\.planets = 0: expected a whole number of planets >= 1"),
    ("duplicate stage names", _set(["stages", 1, "name"], "sp"), r"stages\[1\]\.name = 'sp': expected a stage name not used"),
    ("shaft count that does not match", _delete(["shafts", 1]),
     r"shafts = 1: expected 2 \[\[shafts\]\] for 2 stage\(s\) and a generator"),
    ("unknown contact law", _set(["mesh", "law"], "hertz"), r"mesh\.law = 'hertz': expected one of 'cfs' or 'impact'"),
    ("wrong type", _set(["stages", 0, "face_width"], "50"), r"stages\[0\]\.face_width = '50': expected a number > 0"),
    ("unknown key with a did you mean", _set(["stages", 0, "modul"], 10.0),
     r"stages\[0\]\.modul = 10\.0: expected a known key here: .*\(did you mean module\?\)"),
    ("unknown top-level key", _set(["generater"], {}), r"generater = \{\}: expected a known key .*did you mean generator"),
    ("unknown stage kind", _set(["stages", 1, "kind"], "worm"),
     r"stages\[1\]\.kind = 'worm': expected the stage kind: \"planetary\" or \"parallel\""),
    ("teeth and radii both given", _set(["stages", 1, "radii"], {"drive": 220.0, "driven": 55.0}),
     r"stages\[1\]\.teeth = 'both teeth and radii': expected either teeth"),
    ("mass without inertia", _set(["stages", 0, "planet"], {"mass": 100.0}),
     r"stages\[0\]\.planet\.inertia = None: expected a value \(mass and inertia are given together"),
    ("bored disc without a bore", _set(["stages", 1, "drive"], {"disc": "bored"}),
     r"stages\[1\]\.drive\.bore_diameter = None: expected a bore diameter"),
    ("bore larger than the gear", _set(["stages", 1, "driven"], {"disc": "bored", "bore_diameter": 200.0}),
     r"stages\[1\]\.driven\.bore_diameter = 0\.2: expected < the pitch diameter 0\.11 m"),
    ("generator and output both given", _set(["output"], {"torque": 1.0}), r"generator = None: expected either a \[generator\]"),
    ("planet angles of the wrong count", _set(["stages", 0, "planet_angles"], [0.0, 180.0]),
     r"stages\[0\]\.planet_angles = \[0\.0, 180\.0\]: expected 3 angles, one per planet"),
    ("planet angles that cannot be assembled", _set(["stages", 0, "planet_angles"], [0.0, 100.0, 240.0]),
     r"stages\[0\]\.planet_angles = \[0\.0, 100\.0, 240\.0\]: expected planets that can be assembled: .*planet\(s\) 2 fail"),
    ("contact parameter given nowhere", _delete(["mesh", "k0"]),
     r"stages\[0\]\.sun_mesh\.k0 = None: expected a value for k0 \(missing: give it in this mesh"),
    ("unknown unit", _set(["units", "length"], "blorps"), r"units\.length = 'blorps': expected a unit dtcosim knows"),
    ("[units] entry of another dimension", _set(["units", "length"], "kg"),
     r"units\.length = 'kg': expected a quantity of dimension \[length\] \(SI unit m\); the unit 'kg' is \[mass\]"),
    ("value with a unit of another dimension", _set(["mesh", "backlash"], "0.56 N"),
     r"mesh\.backlash = '0\.56 N': expected a length: a quantity of dimension \[length\] \(SI unit m\); the unit 'N' is"),
    ("torque given for a shaft stiffness", _set(["shafts", 0, "stiffness"], "1e7 N m"),
     r"shafts\[0\]\.stiffness = '1e\+07 N m': expected a torsional stiffness: .*\[angle\]\^-1 \(SI unit N\.m/rad\)"),
    ("[units] that leaves out a dimension the file uses", _delete(["units", "inertia"]),
     r"stages\[0\]\.planet\.inertia = 2\.0: expected a value with its unit \(e\.g\. \"2 kg\.m2\"\), or a \[units\] "
     r"entry inertia = \"\.\.\.\": this file's \[units\] names length, angle, mass, contact_stiffness, .* or none"),
    ("[units] without length reads no module in metres", _delete(["units", "length"]),
     r"stages\[0\]\.module = 10\.0: expected a value with its unit .*\[units\] entry length"),
    ("reserved stage name", _set(["stages", 1, "name"], "generator"), r"stages\[1\]\.name = 'generator': expected a stage name"),
    ("pressure angle of 90 deg or more", _set(["stages", 1, "pressure_angle"], 90.0),
     r"stages\[1\]\.pressure_angle = 90\.0: expected an angle below 90 deg"),
    ("ring radius below the sun's", _both(_delete(["stages", 0, "teeth"]),
                                          _set(["stages", 0, "radii"], {"sun": 100.0, "ring": 90.0})),
     r"stages\[0\]\.radii\.ring = 90\.0: expected > the sun radius 100"),
    ("force exponent out of range", _set(["mesh", "exponent"], 5.0), r"mesh\.exponent = 5\.0: expected a number in \[1, 3\]"),
    ("no stages", _set(["stages"], []), r"stages = \[\]: expected an array of tables \[\[stages\]\], at least one"),
    ("negative shaft stiffness", _set(["shafts", 0, "stiffness"], -1.0), r"shafts\[0\]\.stiffness = -1\.0: expected a number > 0"),
]


@pytest.mark.parametrize("change, pattern", [b[1:] for b in BAD_FILES], ids=[b[0] for b in BAD_FILES])
def test_a_bad_file_is_one_named_error(change, pattern, tmp_path):
    doc = copy.deepcopy(base())
    change(doc)
    path = tmp_path / "bad.toml"
    path.write_text(_toml(doc))
    with pytest.raises(DrivetrainFileError, match=r"^" + re.escape(str(path)) + r": invalid drivetrain entry "
                       + pattern) as info:
        load_drivetrain_file(path)
    assert "Traceback" not in str(info.value)


def test_a_scenario_naming_a_bad_drivetrain_file_fails_before_any_build(tmp_path):
    from orchestrator.inputs.scenario_file import load_scenario

    doc = base()
    doc["stages"][0]["planets"] = 0
    (tmp_path / "gearbox.toml").write_text(_toml(doc))
    scenario = tmp_path / "s.toml"
    scenario.write_text('[simulation]\nstop = 1.0\nstep = 0.001\n[components.gearbox]\nfmu = "Gearbox.fmu"\n'
                        'drivetrain = "gearbox.toml"\n')
    with pytest.raises(DrivetrainFileError, match=r"gearbox\.toml: invalid drivetrain entry stages\[0\]\.planets = 0"):
        load_scenario(scenario)
    assert not (tmp_path / "fmus").exists()


def test_a_file_without_generator_cannot_become_a_gearbox_fmu():
    doc = base()
    del doc["generator"]
    del doc["shafts"][1]
    doc["output"] = {"torque": 1000.0}
    spec = read(doc)
    assert spec.drivetrain.generator is None and spec.drivetrain.output_torque_nm == 1000.0
    with pytest.raises(DrivetrainFileError, match=r"generator = None: expected a \[generator\] table"):
        spec.cosim_drivetrain()


def _toml(doc: dict) -> str:
    """A minimal TOML writer for the test documents (tables, arrays of tables, inline tables)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return '"' + v + '"'
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v)

    lines = [f"{k} = {value(v)}" for k, v in doc.items() if not isinstance(v, (dict, list)) or
             (isinstance(v, list) and not (v and all(isinstance(x, dict) for x in v)))]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{kk} = {value(x)}" for kk, x in v.items()]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for item in v:
                lines.append(f"[[{k}]]")
                lines += [f"{kk} = {value(x)}" for kk, x in item.items()]
    return "\n".join(lines) + "\n"


def test_the_documented_example_is_a_valid_file_with_the_stated_checks():
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[3] / "docs" / "drivetrains.md").read_text()
    section = doc.split("# Your own gearbox", 1)[1]
    text = section.split("```toml\n", 1)[1].split("```", 1)[0]
    spec = drivetrain_from_dict(tomllib.loads(text), source="docs/drivetrains.md")
    assert spec.drivetrain.ratio == pytest.approx((1 + 99 / 21) * 82 / 23)
    assert [c.passed for c in spec.checks["planetary"]] == [True] * 8  # 3 geometry checks, 5 plausibility rules
    assert spec.rotor_speed_rad_s == pytest.approx(units.rpm(22.0))
    sources = {b.name: b.source for rows in spec.bodies.values() for b in rows}
    assert sources["output.driven"] == "given" and sources["planetary.planet"].startswith("derived: bored disc")
