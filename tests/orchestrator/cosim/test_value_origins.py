"""A message about a parameter value names where the value was given (issue 30: no silent wrong answer).

The scenario file, ``--set`` on top of it, a study's axis, point, seed or base, a load-case set's row, law or
base, an SSP's parameter set: each value keeps its origin (:mod:`orchestrator.inputs.origins`), and the
refusal - its type, its unit, the FMU's bounds, the model, plausibility by physics - names that place.
"""

from __future__ import annotations

import re
import zipfile

import pytest

from components.analysis.plausibility import Judgement
from orchestrator.commands.cli import main
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import EntryError, ScenarioError
from orchestrator.inputs.load_case_file import load_cases_from_dict
from orchestrator.inputs.load_cases import LoadCaseError
from orchestrator.inputs.origins import Origin, command_line, last_given
from orchestrator.inputs.overrides import apply_assignments
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import load_study
from orchestrator.interop.ssp import import_ssp
from orchestrator.study.load_cases import prepare_load_cases
from orchestrator.study.prepare import prepare_study

PAPER = str(find_scenario("paper-60s"))
ON_TOP = rf"\(on top of {re.escape(PAPER)}\): invalid scenario entry "
BACKLASH = r"expected a plausible value within \[0, 0\.002952\] m \(0\.295 modules: .*\); it is 0\.3 m in SI; "


@pytest.fixture(scope="module")
def paper(fmu_dir):
    """``paper(*--set items, scenario=None)`` -> the resolved paper scenario (or another file) with them applied."""
    from orchestrator.provision.project_fmus import ensure_fmus

    base = load_scenario(PAPER)
    paths = ensure_fmus(base, fmu_dir, build=False)

    def resolve(*items: str, scenario=None):
        return resolve_system(apply_assignments(scenario or base, items), fmu_paths=paths)

    return resolve


# ------------------------------------------------------------------ --set on top of a scenario file
SET_REFUSED = [
    # plausibility by physics: the 0.3 (meant in mm, read as m)
    (["gearbox.stage1.backlash=0.3"], rf"^--set gearbox\.stage1\.backlash=0\.3 {ON_TOP}components\.gearbox\.parameters"
     rf"\.stage1\.backlash = 0\.3: {BACKLASH}.* in the scenario or --allow-implausible gearbox\.stage1\.backlash$"),
    # the FMI type
    (["wind.omega0=abc"], rf"^--set wind\.omega0=abc {ON_TOP}components\.wind\.parameters\.omega0 = 'abc': expected a "
     r"Real value for omega0$"),
    # a quantity converted to the declared unit keeps its origin, and one of another dimension is refused there
    (["gearbox.stage1.backlash=300 mm"], rf"^--set gearbox\.stage1\.backlash=300 mm {ON_TOP}.*backlash = 0\.3: "
                                         rf"{BACKLASH}"),
    (["gearbox.stage1.backlash=0.3 kg"], rf"^--set gearbox\.stage1\.backlash=0\.3 kg {ON_TOP}.*backlash = '0\.3 kg': "
                                         r"expected a quantity of dimension \[length\]"),
    # the FMU's declared bounds, an event slot's own check, an unknown component, a bound parameter
    (["gearbox.stage1.k0=-1"], rf"^--set gearbox\.stage1\.k0=-1 {ON_TOP}.*k0 = -1: expected > 0"),
    (["generator.event1.kind=1", "generator.event1.start=-1"],
     rf"^--set generator\.event1\.start=-1 {ON_TOP}.*event1\.start = -1: expected a finite time >= 0 \[s\]$"),
    (["turbine.seed=2"], rf"^--set turbine\.seed=2 {ON_TOP}components = 'turbine': expected a declared component"),
    (["gearbox.generator_inertia=100"], rf"^--set gearbox\.generator_inertia=100 {ON_TOP}.*generator_inertia = 100: "
                                        r"expected no value: gearbox\.generator_inertia takes its value from "
                                        r"generator\.inertia"),
    (["generator.initial_speed=5"], rf"^--set generator\.initial_speed=5 {ON_TOP}initial\[0\]\.to = "
                                    r"'generator\.initial_speed': expected a variable without a value in "
                                    r"components\.generator\.parameters$"),
    # a value the FMU keeps, refused by the model or by physics with the one given: named by the one given
    (["gearbox.stage1.sun_radius=2.0"], rf"^--set gearbox\.stage1\.sun_radius=2\.0 {ON_TOP}components\.gearbox\."
                                        r"parameters\.stage1\.ring_radius = 0\.9: expected > sun radius"),
    (["gearbox.stage3.module=0.0015"], rf"^--set gearbox\.stage3\.module=0\.0015 {ON_TOP}.*stage3\.backlash = "
                                       r"'0\.00056 \(as built\)'"),
    # a dimensionless value is printed without a unit (was "it is 1e+30  in SI")
    (["generator.event1.kind=1", "generator.event1.start=1", "generator.event1.factor=1e30"],
     rf"^--set generator\.event1\.factor=1e30 {ON_TOP}.*factor = 1e\+30: expected a plausible value within \[-3, 3\] "
     r"\(.*\); it is 1e\+30 in SI; a deliberate"),
]


@pytest.mark.parametrize("items, match", SET_REFUSED, ids=[r[0][-1] for r in SET_REFUSED])
def test_a_set_value_is_named_by_its_option_on_top_of_the_scenario(paper, items, match):
    with pytest.raises(ScenarioError, match=match):
        paper(*items)


@pytest.mark.parametrize("entry, given, match", [
    ('"stage1.backlash" = 0.3', [], rf"components\.gearbox\.parameters\.stage1\.backlash = 0\.3: {BACKLASH}"),
    ('"stage1.backlash" = 0.3', ["wind.seed=2"], r"stage1\.backlash = 0\.3: expected a plausible value"),
    ('"stage1.k0" = -1.0', ["gearbox.stage1.backlash=0.5 mm"], r"stage1\.k0 = -1\.0: expected > 0"),
])
def test_a_value_of_the_scenario_file_is_named_by_the_file_also_under_a_set(paper, tmp_path, entry, given, match):
    path = tmp_path / "mine.toml"
    path.write_text(open(PAPER).read().replace("[components.gearbox.parameters]\n",
                                               f"[components.gearbox.parameters]\n{entry}\n"))
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(path))}: invalid scenario entry .*{match}"):
        paper(*given, scenario=load_scenario(path))


@pytest.mark.parametrize("item, rest", [
    ("gearbox.stage1.backlash=0.3", r"components\.gearbox\.parameters\.stage1\.backlash = 0\.3: expected a plausible "),
    ("wind.omega0=abc", r"components\.wind\.parameters\.omega0 = 'abc': expected a Real value for omega0$"),
])
def test_run_check_names_the_set_not_the_scenario_file(fmu_dir, capsys, item, rest):
    assert main(["run", "--fmu-dir", str(fmu_dir), "--check", "--set", item]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert re.match(rf"dtcosim run: error: --set {re.escape(item)} {ON_TOP}{rest}", err), err


# ------------------------------------------------------------------ a study's axis, point, seed and base
STUDY = """
name = "origins"
engine = "cosim"
measures = ["cpu_time"]
{head}
[base]
scenario = "paper-60s"
{base}
[simulation]
stop = 0.1
{axes}
"""


@pytest.mark.parametrize("head, base, axes, match", [
    ("", "", '[[axes]]\nparameter = "gearbox.stage1.backlash"\nvalues = [0.0005, 0.3]\n',
     r"study\.toml: invalid study entry axes\[0\]\.values\[1\] \(gearbox\.stage1\.backlash\) = 0\.3: " + BACKLASH
     + r".* in the study or --allow-implausible gearbox\.stage1\.backlash \(point 1\)$"),
    ('points = [{ "wind.seed" = 2 }, { "wind.omega0" = "abc" }]', "", "",
     r"study\.toml: invalid study entry points\[1\]\.wind\.omega0 = 'abc': expected a Real value for wind\.omega0 "
     r"\(point 1\)$"),
    ('points = [{ "gearbox.stage1.backlash" = "300 mm" }]', "", "",
     r"study\.toml: invalid study entry points\[0\]\.gearbox\.stage1\.backlash = 0\.3: " + BACKLASH),
    ("seeds = [1, 4294967297]", "", "",
     r"study\.toml: invalid study entry seeds\[1\] \(wind\.seed\) = 4294967297: expected an FMI Integer within "
     r"\[-2147483648, 2147483647\] \(32 bits\) for wind\.seed \(point 1\)$"),
    ("", '[base.parameters]\n"gearbox.stage1.backlash" = 0.3', "",
     r"study\.toml: invalid study entry base\.parameters\.gearbox\.stage1\.backlash = 0\.3: " + BACKLASH
     + r".* in the study or --allow-implausible gearbox\.stage1\.backlash$"),
    ("", '[base.parameters]\n"turbine.seed" = 2', "",
     r"study\.toml: invalid study entry components = 'turbine': expected a declared component: wind, gearbox, "
     r"generator \(given with base\.parameters\.turbine\.seed\)$"),
    # a value the FMU keeps, implausible with an axis value: named with that axis value and its point
    ("", "", '[[axes]]\nparameter = "gearbox.stage3.module"\nvalues = [0.0015]\n',
     r"study\.toml: invalid study entry components\.gearbox\.parameters\.stage3\.backlash = '0\.00056 \(as built\)'"
     r".* \(given with axes\[0\]\.values\[0\] \(gearbox\.stage3\.module\), point 0\)$"),
])
def test_a_study_value_is_named_by_its_axis_point_seed_or_base(fmu_dir, write_study, head, base, axes, match):
    with pytest.raises(StudyError, match=match):
        prepare_study(load_study(write_study(STUDY.format(head=head, base=base, axes=axes))), fmu_dir=fmu_dir,
                      build=False)


def test_a_built_in_models_value_is_named_by_its_axis(write_study):
    from tests.helpers.studies import MODEL_BASE

    text = MODEL_BASE + '[[axes]]\nparameter = "gearbox.stage3.backlash"\nvalues = [0.0005, 0.3]\n'
    with pytest.raises(StudyError, match=r"study\.toml: invalid study entry axes\[0\]\.values\[1\] "
                                         r"\(gearbox\.stage3\.backlash\) = 0\.3: expected a plausible value .*\(point 1\)$"):
        prepare_study(load_study(write_study(text)))


# ------------------------------------------------------------------ a load-case set's rows, law and base
def load_case_set(**changes):
    doc = {"base": {"scenario": "paper-60s"}, "runs": {"length": 2.0, "transient": 1.0, "seeds": 1},
           "wind": {"distribution": "weibull", "k": 2.0, "A": "9 m/s"}, "bins": {"edges": [8.0, 12.0]},
           "operating_points": [{"wind_speed": 10.0, "rotor_speed_rpm": 12.0, "generator_torque": "20 kN m"}]}
    doc.update(changes)
    return load_cases_from_dict(doc, source="set.toml")


RUN = r"\(run 0, bin \[8, 12\) m/s, seed 1\)$"


@pytest.mark.parametrize("changes, match", [
    ({"operating_points": [{"wind_speed": 10.0, "generator_torque": "100 kN m"}]},
     r"operating_points\[0\]\.generator_torque \(generator\.counter_torque\) = 100000\.0: expected a plausible value "
     r".* in the load-case set or --allow-implausible generator\.counter_torque " + RUN),
    ({"operating_points": [{"wind_speed": 10.0, "parameters": {"gearbox.stage1.backlash": 0.3}}]},
     r"operating_points\[0\]\.parameters\.gearbox\.stage1\.backlash = 0\.3: " + BACKLASH + ".*" + RUN),
    ({"operating_points": [{"wind_speed": 10.0, "parameters": {"wind.f_max": "abc"}}]},
     r"operating_points\[0\]\.parameters\.wind\.f_max = 'abc': expected a Real value for wind\.f_max " + RUN),
    ({"operating_points": [], "operating_law": {"rated_wind_speed": 9.0, "rated_torque": 1.0e5}},
     r"operating_law \(generator\.counter_torque at 10 m/s\) = 100000\.0: expected a plausible value .*" + RUN),
    ({"base": {"scenario": "paper-60s", "parameters": {"gearbox.stage1.backlash": 0.3}}},
     r"base\.parameters\.gearbox\.stage1\.backlash = 0\.3: " + BACKLASH + r".* in the load-case set or "
     r"--allow-implausible gearbox\.stage1\.backlash$"),
])
def test_a_load_case_value_is_named_by_its_entry_and_run(fmu_dir, changes, match):
    with pytest.raises(LoadCaseError, match=r"^set\.toml: invalid load-case set entry " + match):
        prepare_load_cases(load_case_set(**changes), fmu_dir=fmu_dir, build=False)


# ------------------------------------------------------------------ an SSP's parameter set
def test_an_ssp_value_is_named_by_its_parameter_in_the_ssd(fmu_dir, tmp_path):
    ssp = tmp_path / "paper.ssp"
    assert main(["export-ssp", "--fmu-dir", str(fmu_dir), "--no-build", "--out", str(ssp), "--set",
                 "gearbox.stage1.backlash=0.3", "--allow-implausible", "gearbox.stage1.backlash"]) == 0
    with zipfile.ZipFile(ssp) as zf:
        ssd = zf.read("SystemStructure.ssd").decode().splitlines()
    line = next(i for i, text in enumerate(ssd, 1) if '<ssv:Parameter name="stage1.backlash"' in text)
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(ssp))}!SystemStructure\.ssd, line {line}: invalid "
                                            rf"scenario entry components\.gearbox\.parameters\.stage1\.backlash = 0\.3: "
                                            rf"{BACKLASH}"):
        resolve_system(import_ssp(ssp))


# ------------------------------------------------------------------ the origin itself
@pytest.mark.parametrize("origin, own, message", [
    (Origin("paper-60s.toml"), True, "paper-60s.toml: invalid scenario entry k = 1: expected > 2"),
    (command_line("--set c.p=1", "s.toml"), True, "--set c.p=1 (on top of s.toml): invalid scenario entry k = 1: "
                                                  "expected > 2"),
    (Origin("study.toml", "axes[0].values[3] (c.p)", "point 3", StudyError), True,
     "study.toml: invalid study entry axes[0].values[3] (c.p) = 1: expected > 2 (point 3)"),
    (Origin("study.toml", "axes[0].values[3] (c.q)", "point 3", StudyError), False,
     "study.toml: invalid study entry k = 1: expected > 2 (given with axes[0].values[3] (c.q), point 3)"),
    (Origin("set.toml", "base.parameters.c.p", error=LoadCaseError), True,
     "set.toml: invalid load-case set entry base.parameters.c.p = 1: expected > 2"),
])
def test_an_origin_names_its_place_in_the_message(origin, own, message):
    error = origin.refusal("k", 1, "> 2", own)
    assert isinstance(error, EntryError) and str(error) == message and error.source == origin.source


def test_the_last_value_given_is_blamed_for_one_nobody_gave():
    scenario = apply_assignments(load_scenario(PAPER), ["gearbox.stage3.module=0.0015", "gearbox.stage1.k0=1e10",
                                                        "gearbox.stage3.module=0.0016"])
    origins = scenario.component("gearbox").origins
    assert last_given(origins, ["stage3.module", "stage1.k0"], Origin(None)).source.startswith(
        "--set gearbox.stage3.module=0.0016")
    assert last_given(origins, ["stage2.module"], Origin("s.toml")).source == "s.toml"


@pytest.mark.parametrize("unit, shown", [("m", "0.3 m"), ("", "1e+30")])
def test_a_value_in_si_is_printed_with_its_unit_or_alone(unit, shown):
    value = 0.3 if unit else 1e30
    assert Judgement("r", "k", value, 0.0, 1.0, unit, "why").in_si == shown
