"""Load-case set files: the packaged set, the bins and operating points, and one clear error per mistake."""

from __future__ import annotations

import numpy as np
import pytest

from components import units
from orchestrator.inputs.load_case_file import (
    find_load_cases,
    load_cases_from_dict,
    load_load_cases,
    packaged_load_cases,
)
from orchestrator.inputs.load_cases import LoadCaseError
from tests.helpers.scenarios import dtcosim


def _doc(**changes):
    doc = {
        "base": {"scenario": "paper-60s"},
        "runs": {"length": 20.0, "transient": 5.0, "seeds": 2},
        "wind": {"distribution": "weibull", "k": 2.0, "A": 9.0},
        "bins": {"cut_in": 4.0, "cut_out": 16.0, "width": 4.0},
        "operating_law": {"rated_wind_speed": 12.0},
    }
    for key, value in changes.items():
        table, _, field = key.partition("__")
        if field:
            doc.setdefault(table, {})
            if value is None:
                doc[table].pop(field, None)
            else:
                doc[table][field] = value
        elif value is None:
            doc.pop(table, None)
        else:
            doc[table] = value
    return doc


def test_the_packaged_paper_turbine_set_has_bins_from_cut_in_to_cut_out_with_three_seeds():
    assert "paper-turbine" in packaged_load_cases()
    lcs = load_load_cases(find_load_cases("paper-turbine"))
    assert lcs.edges_m_s[0] == 3.0 and lcs.edges_m_s[-1] == 25.0 and len(lcs.bins) == 11
    assert lcs.seeds == (1, 2, 3) and lcs.length_s == 600.0 and lcs.n_runs == 33
    assert lcs.wind.mean_speed_m_s == pytest.approx(8.5)
    rated = lcs.bins[-1].point
    assert rated.region == "3" and rated.generator_torque_nm == 25.4e3
    assert rated.rotor_speed_rad_s == pytest.approx(units.rpm(16.0))
    assert lcs.transient_s is None  # "settled": derived from the base drivetrain when the set is prepared
    settled, notes = lcs.settled(2.8163, "2.82 s = ...", 60.0)
    assert settled.time_grid().window_s == (2.9, 602.9) and settled.time_grid().stop_s == 602.9 and notes == []


def test_bins_take_the_law_and_a_row_overrides_it_for_its_bin():
    rows = [{"wind_speed": 5.0, "generator_torque": 1234.0, "parameters": {"wind": {"n_harmonics": 64}}}]
    lcs = load_cases_from_dict(_doc(operating_points=rows))
    b0, b1, b2 = lcs.bins
    assert (b0.low_m_s, b0.high_m_s) == (4.0, 8.0)
    assert b0.point.generator_torque_nm == 1234.0 and b0.point.region == "table"
    assert b0.point.rotor_speed_rad_s == pytest.approx(units.rpm(16.0) * 6.0 / 12.0)
    assert dict(b0.parameters) == {"wind.n_harmonics": 64}
    assert b2.point.region == "3" and b1.point.region == "2"
    probs = [b.probability for b in lcs.bins]
    edges = np.array([4.0, 8.0, 12.0, 16.0])
    assert probs == pytest.approx(np.diff(1 - np.exp(-((edges / 9.0) ** 2))), rel=1e-13)


def test_a_table_without_a_law_needs_a_row_for_every_bin():
    rows = [{"wind_speed": 6.0, "rotor_speed_rpm": 8.0}, {"wind_speed": 10.0}]
    with pytest.raises(LoadCaseError, match=r"operating_points .*\[12, 16\) m/s.*every bin"):
        load_cases_from_dict(_doc(operating_law=None, operating_points=rows))


@pytest.mark.parametrize("changes, match", [
    ({"wind__k": None}, r"wind\.k = None: expected a Weibull shape"),
    ({"wind": {"distribution": "rayleigh", "iec_class": "IV"}}, r"wind\.iec_class = 'IV': expected one of"),
    ({"wind": {"distribution": "rayleigh"}}, r"exactly one of iec_class"),
    ({"bins__width": 5.0}, r"bins\.width = 5\.0: expected a width that divides"),
    ({"bins": {"edges": [5.0, 3.0]}}, r"bins\.edges .* increasing"),
    ({"runs__length": -1.0}, r"runs\.length = -1\.0: expected the analysed length"),
    ({"runs__seeds": [1, 1]}, r"runs\.seeds = \[1, 1\]: expected distinct seeds"),
    ({"runs__seed": 3}, r"runs\.seed = 3: expected a known key.*did you mean seeds"),
    ({"life": {"availability": 1.5}}, r"life\.availability = 1\.5: expected an availability in \(0, 1\]"),
    ({"operating_points": [{"wind_speed": 30.0}]}, r"operating_points\[0\]\.wind_speed = 30\.0: expected a wind speed inside"),
    ({"operating_points": [{"wind_speed": 5.0}, {"wind_speed": 6.0}]}, r"operating_points\[1\]\.wind_speed .* a bin of its own"),
    ({"sn_curves": [{"applies_to": ["shaft_torque"], "slope": 5.0}]}, r"sn_curves\[0\] .* reference_range"),
    ({"sn_curves": [{"applies_to": ["x"], "slope": 5.0, "reference_range": 1.0}]}, r"sn_curves\[0\]\.reference_cycles = None"),
    ({"sn_curves": [{"applies_to": ["x"], "slope": 5.0, "reference_range": 1.0, "reference_cycles": 1e6,
                     "goodman": True}]}, r"sn_curves\[0\]\.goodman = True: expected an ultimate load"),
    ({"fatigue": {"residue": "drop"}}, r"fatigue\.residue = 'drop': expected one of"),
    ({"base": {"scenario": "no-such-scenario"}}, r"base\.scenario = 'no-such-scenario'"),
])
def test_each_mistake_is_one_error_naming_the_key(changes, match):
    with pytest.raises(LoadCaseError, match=match):
        load_cases_from_dict(_doc(**changes), source="set.toml")


def test_seed_placeholders_are_kept_for_the_study_and_seed_counts_expand():
    rows = [{"wind_speed": 5.0, "parameters": {"wind.file": "records/5ms-{seed}.outb"}}]
    lcs = load_cases_from_dict(_doc(operating_points=rows, runs={"seeds": [4, 7]}))
    assert lcs.seeds == (4, 7)
    assert lcs.bins[0].parameters["wind.file"] == "records/5ms-{seed}.outb"


@pytest.mark.parametrize("seeds, match", [
    (3_000_000, r"runs\.seeds = 3000000: expected at most 1000 seeds per bin"),
    (list(range(1001)), r"runs\.seeds = 1001: expected at most 1000 seeds per bin"),
])
def test_a_seed_count_beyond_the_bound_is_refused_before_it_is_allocated(seeds, match):
    # --seeds 3000000 hung and 2147483648 raised MemoryError (issue 35.7): the count is checked first
    with pytest.raises(LoadCaseError, match=match):
        load_cases_from_dict(_doc(runs={"length": 20.0, "transient": 5.0, "seeds": seeds}))


def test_a_bin_count_beyond_the_bound_is_refused_before_the_edges_are_made():
    # width 1e-9 between 3 and 25 m/s would make 2.2e10 edges (a hang); 1.1e-5 makes 2 million
    with pytest.raises(LoadCaseError, match=r"bins\.width = 1\.1e-05: expected a width of at least \(cut_out - "
                                            r"cut_in\) / 100000 = 0\.00022 m/s \(at most 100000 bins"):
        load_cases_from_dict(_doc(bins={"cut_in": 3.0, "cut_out": 25.0, "width": 1.1e-5}))


def test_the_command_refuses_a_huge_seed_count_at_once(tmp_path):
    res = dtcosim("loads", "paper-turbine", "--seeds", "2147483648", "--check", cwd=tmp_path, timeout=60)
    assert res.returncode == 1 and "--seeds = 2147483648: expected an integer from 1 to 1000" in res.stderr
