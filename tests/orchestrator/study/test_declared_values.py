"""Study axes and points with units, converted before anything runs, and every point judged by physics (issue 30)."""

from __future__ import annotations

import math

import pytest

from components import units
from orchestrator.inputs.load_case_file import find_load_cases, load_cases_from_dict, load_load_cases, packaged_load_cases
from orchestrator.inputs.load_cases import LoadCaseError
from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import load_study
from orchestrator.study.load_cases import prepare_load_cases
from orchestrator.study.prepare import prepare_study
from tests.helpers.openfast_data import openfast_file
from tests.helpers.studies import MODEL_BASE as MODEL

COSIM = """
name = "units"
engine = "cosim"
measures = ["cpu_time"]
[base]
scenario = "paper-60s"
[simulation]
stop = 0.1
"""


def axis(parameter: str, values, unit: str = "", extra: str = "") -> str:
    text = ", ".join(repr(v) if not isinstance(v, str) else f'"{v}"' for v in values)
    return f'[[axes]]\nparameter = "{parameter}"\nvalues = [{text}]\n' + (f'unit = "{unit}"\n' if unit else "") + extra


def test_an_axis_unit_converts_the_values_and_the_table_shows_them_as_written(write_study):
    prepared = prepare_study(load_study(write_study(MODEL + axis("gearbox.stage3.lambda", [10.0, 1000.0], "1/mm"))))
    lam = prepared.study.axes[0]
    assert lam.values == (1.0e4, 1.0e6)  # 1/mm -> the model's 1/m
    assert [lam.display(v) for v in lam.values] == [10.0, 1000.0] and lam.axis_label == "gearbox.stage3.lambda [1/mm]"
    assert [p.parameters["gearbox.stage3.lambda"] for p in prepared.points] == [1.0e4, 1.0e6]


@pytest.mark.parametrize("name, values, unit, si", [
    ("gearbox.stage3.lambda", ["600 1/mm", "601 1/mm"], "", [6.0e5, 6.01e5]),     # each value with its own unit
    ("input.speed", [5.0, 7.0], "rpm", [units.rpm(5.0), units.rpm(7.0)]),          # the axis's unit: rpm -> rad/s
])
def test_values_with_their_own_unit_or_the_axis_unit(write_study, name, values, unit, si):
    prepared = prepare_study(load_study(write_study(MODEL + axis(name, values, unit))))
    assert list(prepared.study.axes[0].values) == pytest.approx(si, rel=1e-14)


def test_points_and_the_base_take_quantities_too(write_study):
    text = MODEL.replace('measures = ["I_max_acc"]\n', 'measures = ["I_max_acc"]\n'
                         'points = [{ "gearbox.stage3.backlash" = "0.4 mm" }]\n')
    text = text.replace('model = "sensitivity-variant"\n', 'model = "sensitivity-variant"\n[base.parameters]\n'
                        '"gearbox.output_torque" = "2 kN m"\n')
    prepared = prepare_study(load_study(write_study(text)))
    assert prepared.points[0].parameters["gearbox.stage3.backlash"] == pytest.approx(4.0e-4, rel=1e-14)
    assert prepared.payload.model_parameters["gearbox.output_torque"] == 2000.0


@pytest.mark.parametrize("text, match", [
    (axis("gearbox.stage3.lambda", [10.0], "N m"),
     r"axes\[0\]\.values\[0\] = '10\.0 N m': expected a quantity of dimension \[length\]\^-1 \(SI unit 1/m\); the unit "
     r"'N m' is .* \(for gearbox\.stage3\.lambda\)"),
    (axis("gearbox.stage3.lambda", ["10 1/mm"], "1/mm"),
     r"axes\[0\]\.values\[0\] = '10 1/mm': expected a number in the axis's unit '1/mm'"),
    (axis("gearbox.stage3.lambda", [10.0], "1/mm", "scale = 1.0e-3\n"),
     r"axes\[0\]\.scale = 0\.001: expected no scale: an axis's unit is the unit of its values, converted to the "
     r"parameter's"),
])
def test_a_unit_that_cannot_hold_is_refused_before_anything_runs(write_study, text, match):
    with pytest.raises(StudyError, match=match):
        prepare_study(load_study(write_study(MODEL + text)))


def test_an_implausible_point_is_refused_naming_the_axis_value_and_kept_when_allowed(write_study):
    text = MODEL + axis("gearbox.stage3.backlash", [0.5, 300.0], "mm")
    with pytest.raises(StudyError, match=r"axes\[0\]\.values\[1\] \(gearbox\.stage3\.backlash\) = 0\.3: expected a "
                                         r"plausible value within \[0, 0\.002952\] m .*allow = \[\"gearbox\.stage3\."
                                         r"backlash\"\] in the study or --allow-implausible .*\(point 1\)"):
        prepare_study(load_study(write_study(text)))
    allowed = text.replace("[simulation]", '[plausibility]\nallow = ["gearbox.stage3.backlash"]\n[simulation]')
    assert prepare_study(load_study(write_study(allowed))).study.n_points == 2
    assert prepare_study(load_study(write_study(text)).with_allowed("gearbox.stage3.backlash")).study.n_points == 2


def test_a_built_in_models_speed_and_torque_are_judged_against_its_rating(write_study):
    # the Sec. 4.1 model as defined: 5 rpm, 1 kN m on the output gear
    with pytest.raises(StudyError, match=r"axes\[0\]\.values\[0\] \(input\.speed\) = 0\.8377.*within \[-0\.7854, "
                                         r"0\.7854\] rad/s \(at most 1\.5 x the drivetrain's rated rotor speed 5 rpm"):
        prepare_study(load_study(write_study(MODEL + axis("input.speed", [8.0], "rpm"))))


def test_a_cosim_axis_converts_to_the_fmus_declared_unit_and_is_judged(write_study, fmu_dir):
    text = COSIM + axis("gearbox.shaft3.stiffness", [2.8648, 5.7296], "kN m/rad") + axis("wind.omega0", [12.0], "rpm")
    prepared = prepare_study(load_study(write_study(text)), fmu_dir=fmu_dir, build=False)
    assert prepared.study.axes[0].values == (2864.8, 5729.6)  # N.m/rad, 15 significant digits
    assert prepared.study.axes[1].values[0] == pytest.approx(12.0 * math.pi / 30.0, rel=1e-14)
    with pytest.raises(StudyError, match=r"axes\[0\]\.values\[0\] \(wind\.omega0\) = 20\.94.*within \[-2\.513, 2\.513\] "
                                         r"rad/s .*in the study or --allow-implausible wind\.omega0 \(point 0\)$"):
        prepare_study(load_study(write_study(COSIM + axis("wind.omega0", [200.0], "rpm"))), fmu_dir=fmu_dir,
                      build=False)


def _set(**changes):
    doc = {"base": {"scenario": "paper-60s"}, "runs": {"length": 2.0, "transient": 1.0, "seeds": 1},
           "wind": {"distribution": "weibull", "k": 2.0, "A": "9 m/s"}, "bins": {"edges": [8.0, 12.0]},
           "operating_points": [{"wind_speed": "10 m/s", "rotor_speed_rpm": "1.2566 rad/s",
                                 "generator_torque": "20 kN m"}]}
    doc.update(changes)
    return load_cases_from_dict(doc, source="set.toml")


def test_a_load_case_set_takes_quantities_and_judges_every_run(fmu_dir):
    lcs = _set()
    row = lcs.rows[0]
    assert row.rotor_speed_rad_s == pytest.approx(1.2566, rel=1e-12) and row.generator_torque_nm == 2.0e4
    plc = prepare_load_cases(lcs, fmu_dir=fmu_dir)
    assert plc.cases[0].parameters["generator.counter_torque"] == 2.0e4
    heavy = _set(operating_points=[{"wind_speed": 10.0, "generator_torque": "100 kN m"}])
    with pytest.raises(LoadCaseError, match=r"set\.toml: invalid load-case set entry operating_points\[0\]\.generator_torque "
                                            r"\(generator\.counter_torque\) = 100000\.0: expected a plausible value within "
                                            r"\[-7\.62e\+04, 7\.62e\+04\] N m .* in the load-case set or --allow-implausible "
                                            r"generator\.counter_torque \(run 0, bin \[8, 12\) m/s, seed 1\)$"):
        prepare_load_cases(heavy, fmu_dir=fmu_dir)
    allowed = _set(operating_points=[{"wind_speed": 10.0, "generator_torque": "100 kN m"}],
                   plausibility={"allow": ["generator.counter_torque"]})
    assert prepare_load_cases(allowed, fmu_dir=fmu_dir).cases[0].parameters["generator.counter_torque"] == 1.0e5


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(packaged_load_cases()))
def test_every_run_of_every_packaged_load_case_set_is_plausible(name, tmp_path_factory):
    if name.startswith("openfast"):
        openfast_file("DLC1.1_0_NREL5MW_OC3_spar_0.outb")  # skips without the shared data
    plc = prepare_load_cases(load_load_cases(find_load_cases(name)),
                             fmu_dir=tmp_path_factory.getbasetemp() / "plausible-fmus")
    assert plc.cases and len(set(plc.keys)) == len(plc.cases)
