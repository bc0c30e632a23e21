"""Recorded inputs checked before any run (issue 29.3): quantisation and sampling, the warning for a
quantised prescribed speed, the zero-phase low-pass and its cut-off in the record model and the summary.

The hand-made records: a rotor speed of 12 rpm with a 0.1 Hz wave of 0.5 rpm sampled at 20 Hz, written
with 3 significant digits (0.1 rpm steps: the staircase moves one step every 6 or more samples, step
ratio about 10, far above 0.5) or with 9 (no step seen). The packaged grid-loss scenario (FAST's 3-digit RotSpeed)
with its 1 Hz low-pass gives a low-speed-shaft torque std over [35, 59] s within 0.6-1.6x the record's.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from orchestrator.errors import ScenarioError
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.inputs.series_file import read_load_record
from tests.helpers.openfast_data import openfast_file
from tests.helpers.scenarios import dtcosim

ROTOR_CHANNEL = 'channel = "RotSpeed"          # rpm -> rad/s'


def _record(folder, digits: int, times=None):
    t = np.arange(0.0, 12.0001, 0.05) if times is None else np.asarray(times)
    rotor = 12.0 + 0.5 * np.sin(2 * np.pi * 0.1 * t)
    fmt = f"%.{digits - 1}E"
    rows = [f"{a:.6g}, {fmt % b}, {fmt % (96.0 * b)}, 40, 3800" for a, b in zip(t, rotor)]
    path = folder / "quantised.csv"
    path.write_text("Time [s], RotSpeed [rpm], GenSpeed [rpm], GenTq [kN-m], RotTorq [kN-m]\n" + "\n".join(rows) + "\n")
    return path


def _scenario(folder, rotor_extra: str = ""):
    text = find_scenario("openfast-dlc11").read_text()
    text = text.replace('record = "openfast-data/DLC1.1_0_NREL5MW_OC3_spar_0.outb"', 'record = "quantised.csv"')
    text = text.replace(ROTOR_CHANNEL, f'channel = "RotSpeed"\n{rotor_extra}')
    text = text.replace('name = "openfast-dlc11"', 'name = "quantised"')
    path = folder / "quantised.toml"
    path.write_text(text)
    return path


def test_a_three_digit_rotor_speed_is_found_and_warned_about_before_the_run(tmp_path):
    _record(tmp_path, 3)
    res = dtcosim("run", str(_scenario(tmp_path)), "--check", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    warnings = [line for line in res.stderr.splitlines() if "warning:" in line]
    assert len(warnings) == 1, res.stderr  # GenSpeed is quantised too, but only recorded: no warning for it
    line = warnings[0]
    # 11.5 to 12.5 rpm, one decade: 3 significant digits are 1 decimal here
    for part in ("quantised.csv", "components.loads.series.channels[0] = RotSpeed", "1 decimal: step 0.1 rpm", "every 0.05 s", "lowpass_hz = 1.0", "Rotor FMU"):
        assert part in line, line
    spec = load_scenario(_scenario(tmp_path)).component("loads").series
    rotor = spec.model()["series"]["channels"][0]
    assert rotor["channel"] == "RotSpeed" and rotor["step_ratio"] > 5.0 and rotor["lowpass_hz"] is None
    assert rotor["resolution"]["step_si"] == pytest.approx(0.1 * 2 * np.pi / 60)


def test_full_precision_speeds_and_a_low_passed_one_get_no_warning(tmp_path):
    _record(tmp_path, 9)
    res = dtcosim("run", str(_scenario(tmp_path)), "--check", cwd=tmp_path)
    assert res.returncode == 0 and "warning" not in res.stderr, res.stderr
    _record(tmp_path, 3)
    res = dtcosim("run", str(_scenario(tmp_path, "lowpass_hz = 1.0")), "--check", cwd=tmp_path)
    assert res.returncode == 0 and "warning" not in res.stderr, res.stderr


def test_the_low_pass_removes_the_steps_keeps_the_wave_and_is_stated_in_the_model(tmp_path):
    _record(tmp_path, 3)
    raw = load_scenario(_scenario(tmp_path)).component("loads").series
    spec = load_scenario(_scenario(tmp_path, "lowpass_hz = 1.0")).component("loads").series
    assert spec.model()["series"]["outputs"][0]["lowpass_hz"] == 1.0
    assert spec.model()["series"]["channels"][0]["lowpass_hz"] == 1.0
    assert spec.key != raw.key  # another FMU
    t = spec.time_s
    exact = (12.0 + 0.5 * np.sin(2 * np.pi * 0.1 * t)) * 2 * np.pi / 60
    inner = slice(40, -40)
    assert np.max(np.abs(raw.samples[inner, 0] - exact[inner])) == pytest.approx(0.05 * 2 * np.pi / 60, rel=0.05)
    rms_raw = np.sqrt(np.mean((raw.samples[inner, 0] - exact[inner]) ** 2))  # ~ step / sqrt(12)
    rms_filtered = np.sqrt(np.mean((spec.samples[inner, 0] - exact[inner]) ** 2))
    print(f"\nRMS error of the 0.1 rpm staircase {rms_raw:.3g} rad/s, low-passed at 1 Hz {rms_filtered:.3g} rad/s")
    assert rms_raw == pytest.approx(0.1 * 2 * np.pi / 60 / np.sqrt(12), rel=0.2)
    assert rms_filtered < 0.4 * rms_raw
    # no delay: the filtered speed crosses its mean where the wave does
    assert np.max(np.abs(np.diff(spec.samples[:, 0]))) < 0.2 * np.max(np.abs(np.diff(raw.samples[:, 0])))


@pytest.mark.parametrize("extra, match", [
    ("lowpass_hz = 10.5", r"channels\[0\]\.lowpass_hz.*\(0, 10\) Hz"),
    ("lowpass_hz = 0.0", r"lowpass_hz"),
])
def test_a_cut_off_outside_the_record_s_band_is_refused(tmp_path, extra, match):
    _record(tmp_path, 3)
    with pytest.raises(ScenarioError, match=match):
        load_scenario(_scenario(tmp_path, extra))


def test_an_unevenly_sampled_record_is_not_filtered(tmp_path):
    t = np.concatenate((np.arange(0.0, 6.0, 0.05), np.arange(6.0, 12.0001, 0.1)))
    _record(tmp_path, 3, t)
    with pytest.raises(ScenarioError, match=r"lowpass_hz.*sampled evenly.*0\.05 to 0\.1 s"):
        load_scenario(_scenario(tmp_path, "lowpass_hz = 1.0"))


@pytest.mark.slow
def test_grid_loss_shaft_torque_std_is_the_record_s_with_the_low_pass(tmp_path):
    openfast_file("DLC2.3_1.out")  # skips without the shared data
    out = tmp_path / "run"
    res = dtcosim("run", "openfast-grid-loss", "--out", str(out), "--no-plots", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "warning" not in res.stderr, res.stderr
    summary = json.loads((out / "summary.json").read_text())
    rotor = summary["fmus"]["loads"]["records"][0]["channels"][0]
    assert rotor["channel"] == "RotSpeed" and rotor["lowpass_hz"] == 1.0
    assert rotor["resolution"]["kind"] == "significant_digits" and rotor["resolution"]["digits"] == 3
    header = (out / "timeseries.csv").open().readline().strip().split(",")
    names = [h.split(" [")[0] for h in header]
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1, usecols=(0, names.index("gearbox.torque_rotor")))
    inside = (data[:, 0] >= 35.0) & (data[:, 0] <= 59.0)
    record = read_load_record(openfast_file("DLC2.3_1.out"))
    unit, torque = record.channel("RotTorq")
    assert unit.lower().startswith("kn")
    rec_in = (record.time_s >= 35.0) & (record.time_s <= 59.0)
    ratio = np.std(data[inside, 1]) / (1e3 * np.std(np.asarray(torque)[rec_in]))
    print(f"\nopenfast-grid-loss: low-speed-shaft torque std over [35, 59] s = {ratio:.3g} x the record's RotTorq")
    assert 0.6 <= ratio <= 1.6
