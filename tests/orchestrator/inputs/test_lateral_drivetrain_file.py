"""Drivetrain files with lateral-torsional stages: bearings, ring, pin errors, gravity, and what is refused."""

from __future__ import annotations

import copy
import math
import tomllib

import pytest

from components.model.parameter_map import flatten, unflatten
from orchestrator.inputs.drivetrain_file import drivetrain_from_dict, find_drivetrain, load_drivetrain_file
from orchestrator.inputs.drivetrain_schema import DrivetrainFileError


def _doc(name: str = "paper-table6-lateral") -> dict:
    return tomllib.loads(find_drivetrain(name).read_text())


def test_the_packaged_lateral_gearbox_names_its_bearings_and_exposes_their_parameters():
    dt = load_drivetrain_file(find_drivetrain("paper-table6-lateral")).drivetrain
    names = [b.name for b in dt.bearings]
    assert names == [f"stage{s}.{b}" for s in (1, 2) for b in
                     ("sun_bearing", "carrier_bearing", "planet_bearing[1]", "planet_bearing[2]", "planet_bearing[3]")] \
        + ["stage3.drive_bearing", "stage3.driven_bearing"]
    planet = dt.bearings[2]
    assert (planet.type, planet.dynamic_load_rating_n) == ("roller", 1.0e7)
    assert dt.stages[0].lateral.planet_bearing.stiffness_n_per_m == 5e9
    values = flatten(dt)
    assert values["stage1.planet_bearing_stiffness"] == 5e9 and values["stage1.pin_error_tangential[1]"] == 0.0
    changed = unflatten(dt, {"stage1.pin_error_tangential[1]": 5e-5, "stage2.sun_bearing_damping": 3.0})
    assert changed.stages[0].pin_errors_m[0] == (0.0, 5e-5) and changed.stages[1].lateral.sun_bearing.damping_ns_per_m == 3.0


def test_gravity_sees_the_shaft_tilt():
    doc = _doc()
    doc["gravity"] = {"acceleration": "9.81 m/s^2", "shaft_tilt": "5 deg"}
    dt = drivetrain_from_dict(doc).drivetrain
    assert dt.gravity.in_plane_m_s2 == pytest.approx(9.81 * math.cos(math.radians(5.0)))


def _set(doc: dict, path: tuple, value) -> dict:
    doc = copy.deepcopy(doc)
    node = doc
    for key in path[:-1]:
        node = node[key]
    if value is None:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return doc


@pytest.mark.parametrize("path, value, match", [
    (("stages", 0, "model"), "torsional", r"stages\[0\].bearings = 'given': expected model = \"lateral\""),
    (("stages", 0, "bearings"), None, r'stages\[0\].bearings = None: expected a value for bearings'),
    (("stages", 0, "pin_errors"), [{}, {}], r"pin_errors = 2: expected 3 tables"),
    (("stages", 0, "pin_errors"), [{"tangential": "2 mm"}, {}, {}], r"at most a tenth of the module"),
    (("stages", 1, "carrier_inertia"), 0.0, r'stages\[1\].carrier_inertia = 0.0: expected > 0 with model = "lateral"'),
    (("stages", 0, "bearings", "planet", "type"), "needle", r"planet.type"),
    (("stages", 2, "bearings", "drive", "stiffness"), "-1 N/m", r"drive.stiffness"),
])
def test_inconsistent_lateral_entries_are_refused_naming_the_key(path, value, match):
    with pytest.raises(DrivetrainFileError, match=match):
        drivetrain_from_dict(_set(_doc(), path, value))


def test_gravity_needs_a_lateral_stage():
    doc = _doc("paper-table6")
    doc["gravity"] = {}
    with pytest.raises(DrivetrainFileError, match=r"gravity = 'given': expected a stage with model = \"lateral\""):
        drivetrain_from_dict(doc)
