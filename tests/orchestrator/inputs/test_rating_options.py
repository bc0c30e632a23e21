"""``[gear_rating]`` and ``[bearing_life]`` of a load-case file: defaults, overrides and one error per mistake."""

from __future__ import annotations

import pytest

from orchestrator.inputs.load_case_file import find_load_cases, load_cases_from_dict, load_load_cases
from orchestrator.inputs.load_cases import LoadCaseError
from tests.orchestrator.inputs.test_load_cases import _doc


def test_without_the_tables_the_defaults_apply():
    lcs = load_cases_from_dict(_doc())
    g = lcs.gear_rating
    assert g.enabled and g.material == "case-carburised" and g.beyond_knee == "decline"
    assert g.materials[g.material].sigma_hlim_pa == 1500e6 and g.materials[g.material].sigma_flim_pa == 500e6
    assert (g.factors.K_A, g.factors.K_v, g.factors.K_Hbeta, g.factors.S_Hmin, g.factors.S_Fmin) == (1, 1, 1.15, 1.25, 1.56)
    assert g.stage("stage1").factors == g.factors
    b = lcs.bearing_life.of("any")
    assert b.reliability_percent == 90.0 and b.a1 == 1.0 and not b.given


def test_stage_and_gear_overrides_and_a_material_of_the_file():
    lcs = load_cases_from_dict(_doc(gear_rating={
        "material": "soft", "factors": {"K_Hbeta": 1.2},
        "materials": {"soft": {"sigma_Hlim": 1000.0, "sigma_Flim": 300.0, "Y_NT": [[1e3, 2.0], [3e6, 1.0]]}},
        "stages": {"stage1": {"material": "case-carburised", "factors": {"K_A": 1.25},
                              "gears": {"sun": {"profile_shift": 0.3, "Y_M": 0.9}}}}}))
    g = lcs.gear_rating
    soft = g.materials["soft"]
    assert soft.sigma_hlim_pa == 1000e6 and soft.bending_life == ((1e3, 2.0), (3e6, 1.0))
    assert soft.contact_life == g.materials["case-carburised"].contact_life  # the default curve where none is given
    s1 = g.stage("stage1")
    assert s1.material == "case-carburised" and s1.factors.K_A == 1.25 and s1.factors.K_Hbeta == 1.2  # inherits
    assert s1.gears["sun"].profile_shift == 0.3 and s1.gears["sun"].Y_M == 0.9
    assert g.stage("stage2").material == "soft" and g.stage("stage2").factors.K_A == 1.0


def test_bearing_life_defaults_and_per_bearing_inputs():
    lcs = load_cases_from_dict(_doc(bearing_life={
        "reliability": 99.0, "a_iso": 1.5,
        "bearings": {"planet_1": {"kappa": 1.2, "e_C": 0.5, "C_u": 5.0e4}, "sun": {"reliability": 95.0}}}))
    b = lcs.bearing_life
    assert b.of("other").a_iso == 1.5 and b.of("other").a1 == 0.25
    p1 = b.of("planet_1")  # its kappa, e_C, C_u replace the default a_iso; the reliability is inherited
    assert p1.a_iso is None and p1.viscosity_ratio == 1.2 and p1.a1 == 0.25
    assert b.of("sun").a1 == 0.64 and b.of("sun").a_iso == 1.5


def test_the_packaged_sets_rate_their_tooth_loads_by_iso_6336():
    for name in ("paper-turbine", "openfast-dlc11"):
        lcs = load_load_cases(find_load_cases(name))
        assert lcs.gear_rating.enabled and lcs.gear_rating.factors.K_Hbeta == 1.15
        assert not any(entry.startswith("contact_force") for rule in lcs.curves for entry in rule.applies_to)


@pytest.mark.parametrize("changes, match", [
    ({"gear_rating": {"factors": {"K_Hbeat": 1.2}}}, r"gear_rating\.factors\.K_Hbeat = 1\.2: .*did you mean K_Hbeta"),
    ({"gear_rating": {"factors": {"K_A": -1.0}}}, r"gear_rating\.factors\.K_A = -1\.0: expected a number > 0"),
    ({"gear_rating": {"material": "steel"}}, r"gear_rating\.material = 'steel': expected a material: case-carburised"),
    ({"gear_rating": {"beyond_knee": "flat"}}, r"gear_rating\.beyond_knee = 'flat'"),
    ({"gear_rating": {"stages": {"stage1": {"gears": {"moon": {}}}}}}, r"gear_rating\.stages\.stage1\.gears"),
    ({"gear_rating": {"materials": {"m": {"sigma_Hlim": 1000.0, "sigma_Flim": 300.0,
                                          "Z_NT": [[1e5, 1.0], [5e7, 1.6]]}}}}, r"gear_rating\.materials\.m\.Z_NT"),
    ({"bearing_life": {"reliability": 93.0}}, r"bearing_life\.reliability = 93\.0: expected one of the reliabilities"),
    ({"bearing_life": {"a_iso": 2.0, "kappa": 1.0, "e_C": 0.5, "C_u": 1e4}}, r"bearing_life\.a_iso .* either a_iso"),
    ({"bearing_life": {"bearings": {"b": {"kappa": 1.0}}}}, r"bearing_life\.bearings\.b .* all three"),
    ({"bearing_life": {"kappa": 0.05}}, r"bearing_life\.kappa = 0\.05"),
])
def test_each_rating_mistake_is_one_error_naming_the_key(changes, match):
    with pytest.raises(LoadCaseError, match=match):
        load_cases_from_dict(_doc(**changes), source="set.toml")
