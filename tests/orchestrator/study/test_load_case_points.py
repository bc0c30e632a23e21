"""A load-case set's runs: operating points on the declared roles, independent seeds per bin, distinct keys."""

from __future__ import annotations

import pytest

from components import units
from orchestrator.inputs.load_case_file import load_cases_from_dict
from orchestrator.inputs.load_cases import LoadCaseError
from orchestrator.study.load_cases import SEED_STRIDE, prepare_load_cases


def _set(**changes):
    doc = {"base": {"scenario": "paper-60s"}, "runs": {"length": 2.0, "transient": 1.0, "seeds": 2},
           "wind": {"distribution": "weibull", "k": 2.0, "A": 9.0}, "bins": {"edges": [8.0, 12.0, 16.0, 20.0]},
           "operating_law": {"rated_wind_speed": 12.0}}
    doc.update(changes)
    return load_cases_from_dict(doc, source="set.toml")


def test_region_3_bins_are_runs_of_their_own_with_their_own_seeds(fmu_dir):
    plc = prepare_load_cases(_set(), fmu_dir=fmu_dir)
    assert len(plc.cases) == 6 and len(set(plc.keys)) == 6
    b1, b2 = [[c for c in plc.cases if c.bin == b] for b in (1, 2)]
    assert b1[0].parameters["wind.omega0"] == pytest.approx(units.rpm(16.0))
    assert {k: v for k, v in b1[0].parameters.items() if k != "wind.seed"} == \
           {k: v for k, v in b2[0].parameters.items() if k != "wind.seed"}
    assert [c.parameters["wind.seed"] for c in b1 + b2] == [1 + SEED_STRIDE, 2 + SEED_STRIDE,
                                                            1 + 2 * SEED_STRIDE, 2 + 2 * SEED_STRIDE]
    assert plc.cases[0].parameters["generator.counter_torque"] == pytest.approx(25.4e3 * (10.0 / 12.0) ** 2)


def test_a_parameter_set_twice_names_the_run(fmu_dir):
    lcs = _set(base={"scenario": "paper-60s", "parameters": {"generator.counter_torque": 1.0e4}})
    with pytest.raises(LoadCaseError, match=r"points.*generator\.counter_torque.*set in one place only"):
        prepare_load_cases(lcs, fmu_dir=fmu_dir)


def test_an_unknown_channel_and_an_unknown_curve_target_are_errors(fmu_dir):
    from orchestrator.study.lifetime_results import check_curves

    with pytest.raises(LoadCaseError, match=r"fatigue\.channels\[0\] = 'gearbox\.shaft9\.torque'.*did you mean"):
        prepare_load_cases(_set(fatigue={"channels": ["gearbox.shaft9.torque"]}), fmu_dir=fmu_dir)
    plc = prepare_load_cases(_set(sn_curves=[{"applies_to": ["shaft_torq"], "slope": 5.0, "ultimate": 1e6}]),
                             fmu_dir=fmu_dir)
    with pytest.raises(LoadCaseError, match=r"sn_curves\[0\]\.applies_to\[0\] = 'shaft_torq'.*did you mean shaft_torque"):
        check_curves(plc)
