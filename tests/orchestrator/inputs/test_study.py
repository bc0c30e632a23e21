"""Study files: the packaged paper study, point expansion, validation errors naming the key."""

from __future__ import annotations

import re

import numpy as np
import pytest

from components.errors import DtcosimError
from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import find_study, load_study, study_from_dict
from orchestrator.study.prepare import prepare_study
from tests.helpers.studies import MODEL_BASE, SMALL_STUDY, run_cli


def test_paper_sensitivity_is_the_sec41_grid():
    study = load_study(find_study("paper-sensitivity"))
    assert study.engine == "monolithic" and study.base.kind == "model" and study.base.name == "sensitivity-variant"
    assert study.n_points == 49 and study.shape == (1, 7, 7, 1)
    r1, lam = study.axes
    np.testing.assert_allclose(r1.values, np.linspace(6.0, 10.0, 7))
    np.testing.assert_allclose([lam.display(v) for v in lam.values], np.linspace(10.0, 1000.0, 7))  # 1/mm
    assert lam.parameters == ("gearbox.stage1.lambda", "gearbox.stage2.lambda", "gearbox.stage3.lambda")
    assert lam.axis_label == "lambda [1/mm]"
    assert [m.name for m in study.measures][:2] == ["I_max_acc", "cpu_time"]
    assert study.simulation.stop_s == 1.0 and study.base.parameters["gearbox.output_torque"] == 1000.0
    assert abs(study.base.parameters["input.speed"] - 5.0 * 2.0 * np.pi / 60.0) < 1e-12
    points = study.expand()
    assert points[8].parameters == {"gearbox.R1": r1.values[1], "gearbox.stage1.lambda": lam.values[1],
                                    "gearbox.stage2.lambda": lam.values[1], "gearbox.stage3.lambda": lam.values[1]}
    assert points[8].coords == (0, 1, 1, 0)


def test_expansion_points_times_grid_times_seeds():
    study = study_from_dict({
        "engine": "cosim", "base": {"scenario": "paper-60s"}, "measures": ["cpu_time"],
        "points": [{"gearbox.shaft3.damping": 10.0}, {"gearbox.shaft3.damping": 20.0}],
        "axes": [{"parameter": "gearbox.shaft3.stiffness", "start": 1e3, "stop": 1e5, "num": 3, "spacing": "log"}],
        "seeds": [4, 5],
    }, name="x")
    pts = study.expand()
    assert len(pts) == study.n_points == 2 * 3 * 2
    assert [p.parameters["wind.seed"] for p in pts[:4]] == [4, 5, 4, 5]  # seeds innermost
    np.testing.assert_allclose([p.parameters["gearbox.shaft3.stiffness"] for p in pts[:6:2]], [1e3, 1e4, 1e5])
    assert {p.parameters["gearbox.shaft3.damping"] for p in pts[6:]} == {20.0}  # explicit points outermost
    assert study.varied_parameters == ["gearbox.shaft3.damping", "gearbox.shaft3.stiffness", "wind.seed"]


@pytest.mark.parametrize("edit, key", [
    (lambda d: d.pop("engine"), r"entry engine = None"),
    (lambda d: d.update(engine="fmu"), r"entry engine = 'fmu'"),
    (lambda d: d["base"].update(scenario="paper-60s"), r"entry base = .*exactly one of scenario"),
    (lambda d: d.update(mesures=["cpu_time"]), r"entry mesures = .*did you mean measures"),
    (lambda d: d.update(axes=[{"parameter": "gearbox.R1"}]), r"entry axes\[0\] = .*either values"),
    (lambda d: d.update(axes=[{"parameter": "gearbox.R1", "start": 6, "stop": 10, "num": 0}]), r"axes\[0\]\.num = 0"),
    (lambda d: d.update(axes=[{"parameter": "gearbox.R1", "start": 0, "stop": 10, "num": 3, "spacing": "log"}]),
     r"axes\[0\]\.start = 0.*log spacing"),
    (lambda d: d.update(axes=[{"parameter": "R1", "values": [6]}]), r"axes\[0\]\.parameter = 'R1'"),
    (lambda d: d.update(axes=[{"parameter": "gearbox.R1", "values": [6, 7]},
                              {"parameter": "gearbox.R1", "values": [8]}]), r"axes\[1\] = 'gearbox.R1'.*also set by axes\[0\]"),
    (lambda d: d["base"].update(parameters={"gearbox.R1": 7.0}) or d.update(axes=[{"parameter": "gearbox.R1", "values": [6]}]),
     r"also set by base.parameters"),
    (lambda d: d.update(measures=["I_max_acc", "gearbox.omega_out:median"]), r"measures\[1\] = 'gearbox.omega_out:median'"),
    (lambda d: d.update(measures=[]), r"entry measures = \[\]"),
    (lambda d: d.update(plots=[{"measure": "cpu_time"}]), r"plots\[0\]\.measure = 'cpu_time'"),
    (lambda d: d.update(axes=[{"parameter": "gearbox.R1", "values": [6], "measures": ["x"]}]),
     r"axes\[0\]\.measures = .*top-level key"),
    (lambda d: d.update(engine="cosim"), r"entry engine = 'cosim'.*give base.scenario"),
    (lambda d: d["simulation"].pop("stop"), r"simulation\.stop = None"),
    (lambda d: d.update(solver={"rtol": -1.0}), r"solver\.rtol = -1.0"),
    (lambda d: d.update(seeds=[1, "2"]), r"entry seeds\[1\] = '2': expected an integer \(seeds: a list of integers >= 0\)"),
    (lambda d: d.update(points=[{"gearbox.R1": [6, 7]}]), r"points\[0\]\.gearbox\.R1 = \[6, 7\]"),
    (lambda d: d.update(timeout=0.0), r"entry timeout = 0\.0: expected a finite number of seconds > 0"),
    (lambda d: d.update(timeout="1 min"), r"entry timeout = '1 min'"),
])
def test_structural_mistakes_name_the_key(edit, key):
    import tomllib

    data = tomllib.loads(MODEL_BASE)
    edit(data)
    with pytest.raises(StudyError, match=key):
        study_from_dict(data, source="t.toml")


def test_error_is_a_dtcosim_error_with_the_file(write_study):
    path = write_study(MODEL_BASE.replace('engine = "monolithic"', 'engine = "gpu"'), name="bad.toml")
    with pytest.raises(DtcosimError, match=r"bad\.toml: invalid study entry engine = 'gpu'"):
        load_study(path)


@pytest.mark.parametrize("base_parameters, axes, key", [
    ("", '[[axes]]\nparameter = "gearbox.stage1.lamda"\nvalues = [1e5]\n',
     r"axes\[0\]\.parameter = 'gearbox.stage1.lamda'.*did you mean gearbox.stage1.lambda"),
    ("", '[[axes]]\nparameter = "gearbox.R1"\nvalues = ["eight"]\n', r"axes\[0\]\.parameter = 'eight': expected a number"),
    ('[base.parameters]\n"gearbox.R1" = 12.0\n', "", r"base\.parameters \(R1\) = 12\.0: expected within \[6, 10\]"),
])
def test_model_base_is_checked_before_anything_runs(write_study, base_parameters, axes, key):
    text = MODEL_BASE.replace("[simulation]", base_parameters + "[simulation]") + axes
    with pytest.raises(StudyError, match=key):
        prepare_study(load_study(write_study(text)))


def test_measure_variables_are_checked_against_the_model(write_study):
    text = MODEL_BASE.replace('measures = ["I_max_acc"]', 'measures = ["gearbox.stage3.F_mash:max"]')
    with pytest.raises(StudyError, match=r"measures\[0\] = 'gearbox.stage3.F_mash:max'.*did you mean stage3.F_mesh"):
        prepare_study(load_study(write_study(text)))


@pytest.mark.slow
@pytest.mark.parametrize("engine, top, axes, measures, key", [
    ("cosim", "", '[[axes]]\nparameter = "gearbox.shaft3.stifness"\nvalues = [1e3]\n', '["cpu_time"]',
     r"axes\[0\]\.parameter = 'gearbox.shaft3.stifness'.*did you mean shaft3.stiffness"),
    ("cosim", "seeds = [1]\n", "", '["steps"]', r"measures\[0\] = 'steps'.*needs the monolithic engine"),
    ("cosim", "", "", '["generator.omeg:std"]', r"measures\[0\] = 'generator.omeg:std'.*did you mean generator.omega"),
    ("cosim", "", '[[axes]]\nparameter = "wind.seed"\nvalues = [1, 2.5]\n', '["cpu_time"]',
     r"axes\[0\]\.values\[1\] \(wind\.seed\) = 2\.5: expected an Integer value for wind\.seed \(point 1\)"),
    ("cosim", "", '[[axes]]\nparameter = "gearbox.omega_gen"\nvalues = [1.0]\n', '["cpu_time"]',
     r"not an input a connection drives"),
    ("monolithic", "", "", '["gearbox.shaft_torque_mode:mean"]', r"measures\[0\] = .*counterpart in the monolithic model"),
])
def test_scenario_base_is_checked_against_the_fmus(write_study, fmu_dir, engine, top, axes, measures, key):
    text = (f'name = "s"\nengine = "{engine}"\nmeasures = {measures}\n{top}'
            '[base]\nscenario = "paper-60s"\n[simulation]\nstop = 0.1\n' + axes)
    with pytest.raises(StudyError, match=key):
        prepare_study(load_study(write_study(text)), fmu_dir=fmu_dir)


def test_cli_reports_an_invalid_study_and_runs_nothing(write_study, tmp_path):
    path = write_study(SMALL_STUDY.replace("stop = 0.02", "stop = -1.0"))
    proc = run_cli("sweep", str(path), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert proc.returncode == 1
    assert "dtcosim sweep: error:" in proc.stderr and "simulation.stop = -1.0" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_point_timeout_fails_the_point_and_leaves_the_keys_alone(write_study):
    """A point past the study's timeout fails with the limit and the time reached; keys ignore the limit."""
    from orchestrator.study.engine import PointTask, run_point

    text = MODEL_BASE.replace("stop = 0.01", "stop = 1.0") + '[[axes]]\nparameter = "gearbox.R1"\nvalues = [8.0]\n'
    free = prepare_study(load_study(write_study(text, "free.toml")))
    limited = prepare_study(load_study(write_study("timeout = 0.001\n" + text, "limited.toml")))
    assert limited.payload.timeout_s == 0.001 and free.payload.timeout_s is None
    assert limited.keys == free.keys  # a larger timeout with --retry-failed re-runs the same points
    point = limited.points[0]
    record = run_point(limited.payload, PointTask(limited.keys[0], 0, point.parameters))
    assert record["status"] == "failed" and record["error_type"] == "WallTimeLimitError"
    assert re.fullmatch(r"wall-time limit of 0\.001 s reached \(at t = [0-9.e-]+ s\)", record["error"])


def test_cli_timeout_overrides_the_study_and_is_checked(write_study, tmp_path):
    path = write_study(MODEL_BASE)
    proc = run_cli("sweep", str(path), "--check", "--timeout", "-5", cwd=tmp_path)
    assert proc.returncode == 1 and "invalid study entry --timeout = -5.0" in proc.stderr


@pytest.mark.parametrize("name", ["paper-sensitivity", "shaft3-seeds"])
def test_every_packaged_study_is_valid_against_its_base(name, fmu_dir):
    from orchestrator.inputs.study_file import packaged_studies

    assert set(packaged_studies()) == {"paper-sensitivity", "shaft3-seeds"}
    prepared = prepare_study(load_study(find_study(name)), fmu_dir=fmu_dir, build=False)
    assert len(prepared.keys) == len(set(prepared.keys)) == prepared.study.n_points
    if name == "shaft3-seeds":
        assert prepared.study.shape == (1, 3, 6) and prepared.payload.engine == "cosim"
        assert [prepared.study.axes[0].display(v) for v in prepared.study.axes[0].values] == [2.8648, 5.7296, 11.4592]
