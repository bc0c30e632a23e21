"""Study measures: parsing and the window statistics, damage-equivalent loads included."""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.fatigue import FatigueSettings, fatigue_loads
from orchestrator.inputs.measures import MeasureError, parse_measure
from orchestrator.study.measure_values import window_statistic


@pytest.mark.parametrize("text, statistic", [
    ("gearbox.shaft1.torque:del4", "del4"),
    ("gearbox.stage3.F_mesh:del10", "del10"),
    ("gearbox.stage1.F_sp[1]:del3.5", "del3.5"),
    ("generator.omega:rms", "rms"),
])
def test_statistic_measures_parse_without_a_unit_read_from_the_name(text, statistic):
    m = parse_measure(text)
    assert (m.statistic, m.unit, m.builtin) == (statistic, "", False)  # the base declares it (prepare_study)


@pytest.mark.parametrize("measure, unit", [
    ("gearbox.stage3.F_mesh:mean", "N"),
    ("gearbox.shaft2.torque:del4", "N.m"),
    ("gearbox.omega_out:rms", "rad/s"),
    ("gearbox.stage3.d_mesh:max", "m"),
    ("gearbox.alpha_out:absmax", "rad/s2"),
])
def test_a_model_base_measure_has_the_unit_the_monolithic_solver_declares(write_study, measure, unit):
    from orchestrator.inputs.study_file import load_study
    from orchestrator.study.prepare import prepare_study
    from tests.helpers.studies import SMALL_TABLES

    head = f'name = "small"\nengine = "monolithic"\nmeasures = ["cpu_time", "{measure}"]\n'
    prepared = prepare_study(load_study(write_study(head + SMALL_TABLES)))
    assert [m.column for m in prepared.study.measures] == ["cpu_time [s]", f"{measure} [{unit}]"]
    assert prepared.payload.measures == prepared.study.measures


@pytest.mark.parametrize("text", ["gearbox.shaft1.torque:del0", "gearbox.shaft1.torque:del", "x.y:delm", "x.y:del-3"])
def test_bad_del_measures_name_what_is_expected(text):
    with pytest.raises(MeasureError, match=r"del<m> \(damage-equivalent load, e\.g\. del4\)"):
        parse_measure(text)


def test_del_of_a_sine_is_its_range_times_the_frequency_ratio():
    """f T cycles of range 2A (from peak to peak: no residue), N_ref = 1 Hz x T: DEL_m = 2A f^(1/m)."""
    t = np.linspace(0.0, 10.0, 20001)
    f_hz, amplitude = 2.0, 3.0
    load = 100.0 + amplitude * np.cos(2 * np.pi * f_hz * t)
    for m in (3.0, 4.0, 10.0):
        assert window_statistic(t, load, (0.0, 10.0), f"del{m:g}") == pytest.approx(2 * amplitude * f_hz ** (1 / m), rel=1e-6)


def test_del_over_a_window_is_what_the_run_analysis_computes():
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 60.0, 1e-2)
    load = np.cumsum(rng.normal(size=t.size))
    window = (5.0, 60.0)
    expected = fatigue_loads(t, load, FatigueSettings(wohler_exponents=(4.0,)), window=window).del_by_exponent[4.0]
    assert window_statistic(t, load, window, "del4") == pytest.approx(expected, rel=1e-12)
    assert np.isnan(window_statistic(t, load, (100.0, 200.0), "del4"))
    assert window_statistic(t, load, window, "max") == pytest.approx(load[t >= 5.0 - 1e-12].max())


def test_cells_combine_dels_by_damage_and_other_measures_arithmetically(fmu_dir):
    """Six seeds per cell of shaft3-seeds: a DEL cell is (mean DEL^m)^(1/m), a std cell the plain mean."""
    from orchestrator.inputs.study_file import find_study, load_study
    from orchestrator.study.plots import grid
    from orchestrator.study.prepare import prepare_study

    prepared = prepare_study(load_study(find_study("shaft3-seeds")), fmu_dir=fmu_dir, build=False)
    values = np.array([500.0, 520.0, 610.0, 640.0, 660.0, 700.0])  # the six seeds of every cell
    recs = [{"status": "ok", "measures": {"gearbox.shaft3.torque:del4": values[p.coords[-1]],
                                          "generator.omega:std": values[p.coords[-1]]}} for p in prepared.points]
    recs[0] = {"status": "failed", "measures": {}}  # seed 1 of the first stiffness
    dels, count, failed = grid(prepared, recs, "gearbox.shaft3.torque:del4", 0, None)
    assert count.tolist() == [[5, 6, 6]] and failed.tolist() == [[1, 0, 0]]
    np.testing.assert_allclose(dels[0], [np.mean(values[1:] ** 4) ** 0.25] + [np.mean(values**4) ** 0.25] * 2)
    stds, _, _ = grid(prepared, recs, "generator.omega:std", 0, None)
    np.testing.assert_allclose(stds[0], [values[1:].mean(), values.mean(), values.mean()])


TOY_GEARBOX_SCENARIO = """
name = "foreign-gearbox"
[simulation]
stop = 1.0
step = 0.01
[components.gearbox]
fmu = "ToyGearbox.fmu"
"""
TOY_GEARBOX_STUDY = """
name = "units"
engine = "cosim"
measures = ["gearbox.F_x:max", "gearbox.shaft1.torque:del4", "cpu_time"]
[base]
scenario = "scenario.toml"
[[axes]]
parameter = "gearbox.amplitude"
values = [500.0, 1000.0]
"""


def test_a_study_measure_has_the_unit_its_fmu_declares_not_one_read_from_its_name(toy_dir, tmp_path):
    import shutil

    from orchestrator.inputs.study_file import load_study
    from orchestrator.study.prepare import prepare_study

    shutil.copy(toy_dir / "ToyGearbox.fmu", tmp_path / "ToyGearbox.fmu")
    (tmp_path / "scenario.toml").write_text(TOY_GEARBOX_SCENARIO)
    (tmp_path / "study.toml").write_text(TOY_GEARBOX_STUDY)
    study = load_study(tmp_path / "study.toml")
    prepared = prepare_study(study, build=False)
    # F_x is declared in N.m (a name starting F_ would say N), shaft1.torque in N (the name would say N.m)
    assert [m.column for m in prepared.study.measures] == ["gearbox.F_x:max [N.m]", "gearbox.shaft1.torque:del4 [N]",
                                                          "cpu_time [s]"]
    assert prepared.payload.measures == prepared.study.measures


def test_a_stage_measure_parses_as_the_load_sharing_of_a_stage():
    m = parse_measure("gearbox.stage1:load_sharing")
    assert (m.variable, m.statistic, m.unit, m.of_stage, m.builtin) == ("gearbox.stage1", "load_sharing", "1", True,
                                                                         False)
    with pytest.raises(MeasureError, match="'component.stage:load_sharing'"):
        parse_measure("stage1:load_sharing")
