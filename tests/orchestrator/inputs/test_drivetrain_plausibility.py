"""A drivetrain file's implausible values: refused naming file, key, value as written, bound and reason (issue 30.2)."""

from __future__ import annotations

import re

import pytest

from orchestrator.inputs.drivetrain_file import (
    DrivetrainFileError,
    drivetrain_from_dict,
    load_drivetrain_file,
    packaged_drivetrains,
)
from orchestrator.reports.drivetrain_table import format_design_table
from tests.orchestrator.inputs.test_drivetrain_file import _both, _delete, _set, base

#: (what, change of the two-stage base file, file key, allowed flat name, expected message after the key)
CASES = [
    ("backlash of 0.3 m", _set(["stages", 0, "mesh"], {"backlash": "0.3 m"}), r"stages\[0\]\.mesh\.backlash = '0\.3 m'",
     ["sp.backlash"], r"within \[0, 0\.002952\] m \(0\.295 modules: the circular backlash j_n / cos\(alpha\) at most 10% "
     r"of the circular pitch pi m = 31\.42 mm.*\); it is 0\.3 m in SI \(sp\.backlash\)"),
    ("module of radii-given gears too large for them",
     _both(_delete(["stages", 0, "teeth"]), _set(["stages", 0, "radii"], {"sun": 105.0, "ring": 495.0}),
           _set(["stages", 0, "module"], 30.0)),
     r"stages\[0\]\.module = 30\.0", ["sp.module", "sp.width"],  # 50 mm is also under its 67.5 mm tooth height
     r"within \[0\.00099, 0\.02625\] m \(each gear between 8 and 1000 teeth z = 2 r / m \(here sun 7, planet 13, "),
    ("face width under the tooth height", _set(["stages", 1, "face_width"], 2.0), r"stages\[1\]\.face_width = 2\.0",
     ["par.width", "par.k0"], r"within \[0\.01125, 0\.22\] m \(at least the tooth height 2\.25 m = 11\.25 mm and at "
     r"most 2 x the driven's pitch diameter 110 mm\)"),
    ("planet mass in g", _set(["stages", 0, "planet", "mass"], 1.0e5), r"stages\[0\]\.planet\.mass = 100000\.0",
     ["sp.planet_mass"], r"within \[4\.659, 232\.9\] kg \(0\.1 to 5 x the 46\.59 kg of the solid steel disc of the "
     r"planet's pitch diameter 390 mm"),
    ("planet inertia in kg mm^2", _set(["stages", 0, "planet", "inertia"], 2.0e6),
     r"stages\[0\]\.planet\.inertia = 2000000\.0", ["sp.planet_inertia"],
     r"within \[0\.08858, 4\.203\] kg m\^2 .*at most m r_a\^2 = 4\.203 kg m\^2: no mass outside the tip radius 205 mm"),
    ("carrier inertia in kg mm^2", _set(["stages", 0, "carrier_inertia"], 1.5e5),
     r"stages\[0\]\.carrier_inertia = 150000\.0", ["sp.carrier_inertia"],
     r"within \[0, 183\.9\] kg m\^2 \(the carrier lies inside the ring"),
    ("k0 in N/mm^1.5 in a N/m^e file", _set(["stages", 0, "mesh"], {"k0": 5.0e5}),
     r"stages\[0\]\.mesh\.k0 = 500000\.0", ["sp.k0"],
     r"within \[2\.393e\+10, 6\.46e\+11\] N/m\^e \(the sun-planet mesh's secant stiffness per face width at the rated "
     r"force 5\.405e\+04 N, .* = 0\.00476 N/\(mm um\), within 3x of ISO 6336-1's c_gamma_alpha 18\.8 N/\(mm um\)"),
    ("lengths in mm named m in [units]", _set(["units", "length"], "m"), r"stages\[0\]\.module = 10\.0", ["sp.module"],
     r"within \[0\.99, 0\.1\] m .*module between 0\.1 and 100 mm\); it is 10 m in SI"),
]


@pytest.mark.parametrize("what, change, key, allow, expected", CASES, ids=[c[0] for c in CASES])
def test_an_implausible_entry_is_refused_and_kept_when_allowed(what, change, key, allow, expected):
    doc = base()
    change(doc)
    with pytest.raises(DrivetrainFileError, match=rf"^bad\.toml: invalid drivetrain entry {key}: expected a plausible "
                                                  rf"value {expected}.*; a deliberate value is kept by \[plausibility\] "
                                                  rf"allow = \[\"{re.escape(allow[0])}\"\] in this file$"):
        drivetrain_from_dict(doc, source="bad.toml")
    if what.startswith("lengths in mm"):
        return  # not one value: every length is 1000 x too large
    doc["plausibility"] = {"allow": allow}
    spec = drivetrain_from_dict(doc, source="bad.toml")
    assert {j.key for j in spec.judgements if not j.passed} == set(allow)


def test_an_allowed_name_must_be_a_parameter_of_the_drivetrain():
    doc = base()
    doc["plausibility"] = {"allow": ["sp.backlsh"]}
    with pytest.raises(DrivetrainFileError, match=r"plausibility\.allow\[0\] = 'sp\.backlsh': expected a parameter "
                                                  r"name of this drivetrain .*did you mean sp\.backlash"):
        drivetrain_from_dict(doc, source="bad.toml")


def test_a_study_adds_allowed_names_to_the_files():
    doc = base()
    doc["mesh"]["backlash"] = "0.3 m"
    assert drivetrain_from_dict(doc, source="bad.toml", allow=["sp.backlash", "par.backlash"]).judgements


@pytest.mark.parametrize("name", sorted(packaged_drivetrains()))
def test_every_packaged_drivetrain_is_plausible_or_says_why_not(name):
    """Each failure is allowed in the file, and each allowance is needed (none kept for a passing value)."""
    spec = load_drivetrain_file(packaged_drivetrains()[name])
    allowed = set(spec.data.get("plausibility", {}).get("allow", []))
    failed = {j.key for j in spec.judgements if not j.passed}
    assert failed == allowed
    assert len(spec.judgements) >= 5 * len(spec.drivetrain.stages)


def test_the_design_table_lists_every_rule_and_the_allowed_values():
    spec = load_drivetrain_file(packaged_drivetrains()["paper-table6"])
    text = format_design_table(spec.design_table(), spec.origin)
    assert "check plausible backlash against module and tooth thickness: ok (backlash 0.00056 m, plausible within " \
           "[0, 0.002952] m)" in text
    assert "check plausible face width against module and gear size: not met (allowed by [plausibility]: " \
           "width 0.005 m, plausible within [0.0225, 0.4] m (at least the tooth height 2.25 m = 22.5 mm" in text
    assert text.count("check plausible") == 15  # 5 rules x 3 stages
