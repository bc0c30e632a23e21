"""The longest communication step that resolves the modes split across FMUs (components.analysis.coupling_step).

The paper's drivetrain has one such mode: the generator's inertia on the shafts, 0.953 Hz at 30 % damping (the
modal analysis of ``dtcosim modes`` gives the same mode and energy share from its own eigenvectors); at 20 steps
per period the step limit is 1 / (20 x 0.953 Hz) = 52.5 ms. A co-simulation at 0.25 s (beyond it) came out 4.7 %
off the monolithic reference in the gear forces' standard deviation, and is warned about; so is an output interval
that samples that mode fewer than 10 times per period (0.105 s: a DEL 14.5 % low at 0.5 s).
"""

from __future__ import annotations

import json

import pytest

from components.analysis.coupling_step import SAMPLES_PER_PERIOD, STEPS_PER_PERIOD, drivetrain_coupling_limit
from components.analysis.equilibrium import OperatingPoint
from components.analysis.modes import drivetrain_modes
from components.analysis.rotor_coupling import ROTOR_BODY
from components.model.generator import GENERATOR_BODY
from components.model.presets import cosim_preset
from components.model.rotor import RotorParameters
from tests.helpers.scenarios import dtcosim

RATED = OperatingPoint(16.0 * 3.141592653589793 / 30.0, 25400.0)


def test_the_paper_drivetrain_s_split_mode_is_the_generator_s_and_agrees_with_the_modal_analysis():
    limit = drivetrain_coupling_limit(cosim_preset("table6"), RATED, [GENERATOR_BODY])
    analysis = drivetrain_modes(cosim_preset("table6"), RATED)
    first = analysis.modes[0].mode
    generator_share = dict(zip(analysis.dof_names, first.energy_fraction))[GENERATOR_BODY]
    assert limit.frequency_hz == pytest.approx(first.undamped_frequency_hz, rel=1e-9)  # 0.953 Hz
    assert limit.frequency_hz == pytest.approx(0.95309, abs=5e-6)
    assert limit.damping_ratio == pytest.approx(first.damping_ratio, rel=1e-9) and generator_share > 0.995
    assert limit.bodies == "generator 100 %"
    assert limit.step_s == pytest.approx(1.0 / (STEPS_PER_PERIOD * 0.95309), rel=1e-5)  # 52.5 ms


def test_a_torque_driven_rotor_counts_where_it_moves():
    limit = drivetrain_coupling_limit(cosim_preset("table6"), RATED, [GENERATOR_BODY, ROTOR_BODY],
                                      rotor=RotorParameters())
    assert limit.bodies.startswith("rotor ") and "generator" in limit.bodies
    assert 0.95 < limit.frequency_hz < 1.0


def test_without_bodies_of_other_fmus_nothing_is_split():
    assert drivetrain_coupling_limit(cosim_preset("table6"), RATED, []) is None


@pytest.mark.parametrize("step_s, warned", [(0.02, False), (0.0524, False), (0.0526, True), (0.25, True)])
def test_a_step_beyond_the_limit_is_warned_about_with_the_mode_the_bound_and_why(step_s, warned):
    limit = drivetrain_coupling_limit(cosim_preset("table6"), RATED, [GENERATOR_BODY])
    note = limit.note(step_s)
    assert (note is not None) == warned
    if warned:
        assert note.startswith(f"the communication step {step_s:g} s is longer than 1/20 of the period of the "
                               "0.953 Hz mode (damping ratio 0.3) whose motion is split across FMUs (generator 100 % "
                               "of its kinetic energy), 0.0525 s: each FMU holds the other's outputs over a step")
        assert note.endswith("use a step of 0.0525 s or less (`dtcosim run --compare-reference` measures the "
                             "difference)")


def test_a_run_at_a_coarse_step_says_so_and_its_summary_keeps_it(tmp_path, fmu_dir):
    out = tmp_path / "coarse"
    res = dtcosim("run", "paper-60s", "--stop", "2", "--step", "0.25", "--no-plots", "--fmu-dir", str(fmu_dir),
                  "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "dtcosim run: warning: the communication step 0.25 s is longer than 1/20 of the period of the 0.953 Hz " \
           "mode" in res.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["coupling"]["step_s"] == pytest.approx(0.05246, abs=1e-5) and "step_warning" in summary
    res = dtcosim("run", "paper-60s", "--stop", "2", "--no-plots", "--fmu-dir", str(fmu_dir), "--out",
                  str(tmp_path / "fine"), cwd=tmp_path)
    assert res.returncode == 0 and "communication step" not in res.stderr, res.stderr  # the paper's 20 ms
    assert "step_warning" not in json.loads((tmp_path / "fine" / "summary.json").read_text())


@pytest.mark.parametrize("interval_s, warned", [(0.02, False), (0.1049, False), (0.1051, True), (0.5, True)])
def test_an_output_interval_that_samples_the_mode_too_coarsely_is_warned_about(interval_s, warned):
    limit = drivetrain_coupling_limit(cosim_preset("table6"), RATED, [GENERATOR_BODY])
    assert limit.output_interval_s == pytest.approx(1.0 / (SAMPLES_PER_PERIOD * 0.95309), rel=1e-5)  # 0.105 s
    note = limit.sampling_note(interval_s)
    assert (note is not None) == warned
    if warned:
        assert note.startswith(f"the output interval {interval_s:g} s samples the 0.953 Hz mode (the gear forces' "
                               "fluctuation: generator 100 % of its kinetic energy) ")
        assert "times per period, fewer than 10: the statistics and fatigue loads come from the samples" in note
        assert note.endswith("use an output interval of 0.105 s or less")


def test_a_run_sampled_too_coarsely_says_so(tmp_path, fmu_dir):
    out = tmp_path / "sparse"
    res = dtcosim("run", "paper-60s", "--stop", "2", "--output-interval", "0.5", "--no-plots", "--fmu-dir",
                  str(fmu_dir), "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "dtcosim run: warning: the output interval 0.5 s samples the 0.953 Hz mode" in res.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert "output_warning" in summary and "step_warning" not in summary
    assert summary["coupling"]["output_interval_s"] == pytest.approx(0.1049, abs=1e-4)


@pytest.mark.parametrize("window_s, warned", [((5.0, 60.0), False), ((5.0, 6.05), False), ((5.0, 6.0), True),
                                              ((5.0, 5.25), True)])
def test_a_window_shorter_than_one_period_of_the_mode_is_warned_about(window_s, warned):
    limit = drivetrain_coupling_limit(cosim_preset("table6"), RATED, [GENERATOR_BODY])  # period 1.049 s
    note = limit.window_note(window_s)
    assert (note is not None) == warned
    if warned:
        assert note.startswith(f"the analysis window [{window_s[0]:g}, {window_s[1]:g}] s is shorter than one period "
                               "(1.05 s) of the 0.953 Hz mode in which the gear forces fluctuate")
        assert note.endswith("use a window of 1.05 s or more")
