"""Rainflow counting, damage-equivalent loads and load duration distributions against hand-computed signals."""

import csv
import json

import numpy as np
import pytest

from components.analysis.equilibrium import static_equilibrium
from components.analysis.fatigue import (
    FatigueSettings,
    damage_equivalent_load,
    fatigue_loads,
    fatigue_report,
    rainflow,
    reversals,
    write_del_csv,
    write_ldd_csv,
)
from components.analysis.load_duration import load_duration_distribution, sample_durations
from components.errors import ParameterError
from components.model.presets import table6_gearbox
from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.solver import simulate_monolithic

M = (3.0, 5.0, 8.0, 10.0)


def _histogram(cycles):
    """{range: count} rounded to 1e-9."""
    out = {}
    for r, c in zip(np.round(cycles.ranges, 9), cycles.counts):
        out[float(r)] = out.get(float(r), 0.0) + float(c)
    return out


def test_astm_e1049_example_half_cycle_residue():
    """ASTM E1049-85 rainflow example: load sequence -2 1 -3 5 -1 3 -4 4 -2.

    Expected (the standard's table): one full cycle of range 4 and half cycles of
    ranges 3, 4, 6, 8, 8, 9.
    """
    c = rainflow(np.array([-2, 1, -3, 5, -1, 3, -4, 4, -2.0]), gate=0.0, residue="half")
    assert sorted(zip(c.ranges, c.counts)) == [(3, 0.5), (4, 0.5), (4, 1.0), (6, 0.5), (8, 0.5), (8, 0.5), (9, 0.5)]
    assert c.total_cycles == 4.0


def test_astm_example_repeated_block():
    """The same sequence taken as a repeating block (by hand, starting at the peak 5):
    5 -1 3 -4 4 -2 1 -3 5 closes (-1, 3) = 4, (-2, 1) = 3, (4, -3) = 7 and (5, -4) = 9."""
    c = rainflow(np.array([-2, 1, -3, 5, -1, 3, -4, 4, -2.0]), gate=0.0, residue="repeat")
    assert sorted(c.ranges) == [3, 4, 7, 9]
    assert np.all(c.counts == 1.0)


def _two_sines(a=3.0, b=1.0, f1=1.0, f2=7.0, t1=5.0, t2=5.0):
    """A sine of amplitude a for t1 seconds, then one of amplitude b for t2 seconds (whole periods,
    samples on every crest and trough)."""
    h = 1.0 / (4 * f2 * 8)
    ta = np.arange(0.0, t1, h)
    tb = np.arange(0.0, t2 + 0.5 * h, h)
    y = np.concatenate([a * np.sin(2 * np.pi * f1 * ta), b * np.sin(2 * np.pi * f2 * tb)])
    t = np.arange(y.size) * h
    return t, y


def test_two_sines_counts_and_dels_are_the_hand_computed_values():
    """5 cycles of range 2a = 6 and 35 cycles of range 2b = 2 in T = 10 s (repeat residue);
    DEL_m = ((5 * 6^m + 35 * 2^m) / N_ref)^(1/m) with N_ref = 1 Hz * T."""
    t, y = _two_sines()
    settings = FatigueSettings(residue="repeat")
    assert _histogram(rainflow(y, residue="repeat")) == {2.0: 35.0, 6.0: 5.0}
    fl = fatigue_loads(t, y, settings, name="shaft1.torque", unit="N.m")
    assert fl.analysed_time_s == pytest.approx(10.0)
    assert fl.reference_cycles == pytest.approx(10.0)
    assert fl.cycles == 40.0
    assert fl.max_range == pytest.approx(6.0)
    assert fl.unit == "N.m"
    for m in M:
        expected = ((5 * 6.0**m + 35 * 2.0**m) / 10.0) ** (1.0 / m)
        assert fl.del_by_exponent[m] == pytest.approx(expected, rel=1e-9)
    # an explicit reference count scales the DEL by (N_ref,1 / N_ref,2)^(1/m)
    fl2 = fatigue_loads(t, y, FatigueSettings(residue="repeat", reference_cycles=1e7))
    for m in M:
        assert fl2.del_by_exponent[m] == pytest.approx(fl.del_by_exponent[m] * (10.0 / 1e7) ** (1 / m), rel=1e-9)


def test_sum_of_two_sines_without_extra_reversals():
    """y = A sin(wt) + B sin(5wt) with B < A / 6.25 has no extra turning points
    (dy/dt = w cos(wt) (A + 25 B - 100 B c^2 + 80 B c^4), c = cos(wt), and the quartic is
    positive for B < A / 6.25): one cycle per period of range 2 (A + B)."""
    a, b = 3.0, 0.3
    t = np.arange(0.0, 10.0 + 1e-9, 1.0 / 400)
    y = a * np.sin(2 * np.pi * t) + b * np.sin(2 * np.pi * 5 * t)
    c = rainflow(y, residue="repeat")
    assert c.total_cycles == 10.0
    assert c.ranges == pytest.approx(np.full(10, 2 * (a + b)), rel=1e-12)
    fl = fatigue_loads(t, y, FatigueSettings(residue="repeat"))
    for m in M:  # N_ref = 10 cycles = the counted cycles: DEL is the range itself
        assert fl.del_by_exponent[m] == pytest.approx(2 * (a + b), rel=1e-9)


def test_half_cycle_residue_of_a_sine():
    """10 whole periods of a sine starting at 0: 9 full cycles of 2A in the first pass, the residue
    0, A, -A, 0 gives half cycles A, 2A, A (ASTM)."""
    t = np.arange(0.0, 10.0 + 1e-9, 1.0 / 400)
    y = 2.0 * np.sin(2 * np.pi * t)
    assert _histogram(rainflow(y, residue="half")) == {2.0: 1.0, 4.0: 9.5}
    assert _histogram(rainflow(y, residue="repeat")) == {4.0: 10.0}


def test_gate_removes_noise_cycles_but_not_the_load_cycles():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 10.0, 1.0 / 4000)
    y = 2.0 * np.sin(2 * np.pi * t) + 2e-4 * rng.standard_normal(t.size)  # wiggles well below 0.1 % of the range
    assert rainflow(y, gate=0.0).total_cycles > 100  # every noise wiggle near the crests is a cycle
    gated = rainflow(y)  # default gate: 0.1 % of the range = 4e-3
    assert gated.total_cycles == pytest.approx(10.0, abs=0.5)
    assert gated.ranges.max() == pytest.approx(4.0, abs=2e-3)
    assert list(reversals(np.array([0, 1, 0.999, 1.5, 0.2, 0.25, -1, 0.0]), gate=0.1)) == [0, 1.5, -1, 0]


def test_del_of_no_cycles_is_zero():
    assert damage_equivalent_load(rainflow(np.full(10, 3.0)), 3.0, 10.0) == 0.0


@pytest.mark.parametrize("kwargs, match", [
    (dict(wohler_exponents=(0.0,)), "wohler_exponents"),
    (dict(wohler_exponents=()), "at least one exponent"),
    (dict(residue="ignore"), "residue"),
    (dict(reference_frequency_hz=-1.0), "reference_frequency_hz"),
    (dict(ldd_bins=(1.0, 0.5)), "ldd_bins"),
    (dict(ldd_bins=0), "ldd_bins"),
])
def test_bad_fatigue_settings_are_rejected(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        FatigueSettings(**kwargs)


# ------------------------------------------------------------------ LDD
@pytest.mark.parametrize("uniform", [True, False])
def test_ldd_sums_to_the_analysed_time(uniform):
    rng = np.random.default_rng(1)
    t = np.linspace(0.0, 7.0, 3001) if uniform else np.sort(np.concatenate([[0.0, 7.0], rng.uniform(0, 7, 2999)]))
    y = np.sin(t) + 0.1 * rng.standard_normal(t.size)
    ld = load_duration_distribution(t, y, bins=32, name="shaft2.torque")
    assert ld.time_s.sum() == pytest.approx(7.0, rel=1e-12)
    assert ld.analysed_time_s == pytest.approx(7.0)
    assert sample_durations(t).sum() == pytest.approx(7.0, rel=1e-12)
    lw = load_duration_distribution(t, y, bins=32, window=(2.0, 5.0))
    assert lw.time_s.sum() == pytest.approx(lw.analysed_time_s, rel=1e-12)
    assert lw.analysed_time_s == pytest.approx(3.0, abs=0.01)


def test_ldd_of_a_sine_is_the_arcsine_law():
    """Time with A sin in [a, b] over whole periods: T (asin(b/A) - asin(a/A)) / pi."""
    amp, period_s, n_periods = 2.0, 1.0, 20
    t = np.linspace(0.0, n_periods * period_s, 400_001)
    y = amp * np.sin(2 * np.pi * t / period_s)
    edges = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    ld = load_duration_distribution(t, y, bins=edges, speed_rad_s=np.full(t.size, 2 * np.pi * 3.0))
    expected = 20.0 * (np.arcsin(edges[1:] / amp) - np.arcsin(edges[:-1] / amp)) / np.pi
    assert ld.time_s == pytest.approx(expected, abs=1e-3)  # sample-and-hold weights: O(dt) per crossing
    assert ld.revolutions == pytest.approx(3.0 * ld.time_s, rel=1e-12)  # 3 rev/s
    narrow = load_duration_distribution(t, y, bins=[-1.0, 1.0])
    assert narrow.time_outside_s == pytest.approx(20.0 - expected[1:3].sum(), abs=1e-3)


# ------------------------------------------------------------------ a run
@pytest.fixture(scope="module")
def wind_run():
    dt = table6_gearbox()
    eq = static_equilibrium(dt, dt.generator.counter_torque_nm)
    return simulate_monolithic(dt, RotorSpeedProcess(WindParameters()), 6.0, 1e-3, initial_state=eq.state)


def test_fatigue_report_of_a_run_is_json_and_csv_ready(wind_run, tmp_path):
    report = fatigue_report(wind_run, window=(1.0, 6.0), speeds={"shaft3.torque": "omega_gen"})
    names = list(report.loads)
    assert "stage1.F_sp[1]" in names and "stage3.F_mesh" in names and "shaft3.torque" in names
    assert len(names) == 13 + 3
    assert sorted(report.ldd) == ["shaft1.torque", "shaft2.torque", "shaft3.torque"]
    for ld in report.ldd.values():
        assert ld.time_s.sum() == pytest.approx(5.0, rel=1e-9)
    gen = report.ldd["shaft3.torque"]
    assert gen.revolutions.sum() == pytest.approx(5.0 * 100 * 16 / 60, rel=0.01)  # ~1600 rpm for 5 s
    dels = report.loads["stage1.F_sp[1]"].del_by_exponent
    assert dels[3.0] < dels[5.0] < dels[8.0] < dels[10.0]  # higher m weighs the largest ranges more
    assert dels[10.0] <= report.loads["stage1.F_sp[1]"].max_range
    d = json.loads(json.dumps(report.as_dict()))
    assert d["del"]["shaft1.torque"]["reference_cycles"] == pytest.approx(5.0)
    assert set(d["del"]["shaft1.torque"]["del"]) == {"m=3", "m=5", "m=8", "m=10"}
    rows = list(csv.DictReader(write_del_csv(tmp_path / "del.csv", report).open()))
    assert len(rows) == 16 * 4
    ldd_rows = list(csv.DictReader(write_ldd_csv(tmp_path / "ldd.csv", report).open()))
    assert len(ldd_rows) == 3 * 64
    assert sum(float(r["time_s"]) for r in ldd_rows if r["variable"] == "shaft1.torque") == pytest.approx(5.0)


def test_fatigue_report_of_fmu_style_columns(wind_run):
    """Result columns of a co-simulation carry the component prefix (``gearbox.shaft1.torque``); a plain mapping
    declares no kinds, so the caller names the loads, the torques and their units as the FMU declares them."""
    loads = wind_run.names_of("contact_force", "shaft_torque")
    series = {f"gearbox.{k}": wind_run[k] for k in loads}
    series["wind.omega"] = wind_run["omega_rotor"]
    report = fatigue_report(series, time_s=wind_run.time_s, window=(1.0, 6.0), names=[f"gearbox.{k}" for k in loads],
                            torques=[f"gearbox.{k}" for k in wind_run.names_of("shaft_torque")],
                            units={f"gearbox.{k}": wind_run.signals[k].unit for k in loads})
    assert len(report.loads) == 16 and "wind.omega" not in report.loads
    assert sorted(report.ldd) == ["gearbox.shaft1.torque", "gearbox.shaft2.torque", "gearbox.shaft3.torque"]
    assert report.loads["gearbox.shaft1.torque"].unit == "N.m"
    direct = fatigue_report(wind_run, window=(1.0, 6.0))
    assert report.loads["gearbox.stage3.F_mesh"].del_by_exponent == direct.loads["stage3.F_mesh"].del_by_exponent
    with pytest.raises(ParameterError, match="time_s"):
        fatigue_report(series)
    with pytest.raises(ParameterError, match="names = None: expected the load signals of a plain mapping"):
        fatigue_report(series, time_s=wind_run.time_s)


def test_declared_kinds_and_units_not_names_choose_the_ldd_and_the_units():
    # a foreign gearbox: its shaft torque is called F_x, its contact force shaft1.torque
    t = np.linspace(0.0, 2.0, 2001)
    series = {"g.F_x": 2000.0 + 1000.0 * np.sin(2 * np.pi * t), "g.shaft1.torque": 500.0 * np.cos(2 * np.pi * t)}
    report = fatigue_report(series, time_s=t, names=["g.F_x", "g.shaft1.torque"], torques=["g.F_x"],
                            units={"g.F_x": "N.m", "g.shaft1.torque": "N"})
    assert list(report.ldd) == ["g.F_x"] and report.ldd["g.F_x"].unit == "N.m"
    assert report.ldd["g.F_x"].time_s.sum() == pytest.approx(2.0, rel=1e-12)
    assert {n: fl.unit for n, fl in report.loads.items()} == {"g.F_x": "N.m", "g.shaft1.torque": "N"}
    # reversals 2000 3000 1000 3000 1000 2000: one cycle of range 2000 (1000-3000), residue 2000 3000 1000 2000 as
    # half cycles of 1000, 2000, 1000: DEL_3 = ((2000^3 + (1000^3 + 2000^3 + 1000^3) / 2) / (1 Hz * 2 s))^(1/3)
    assert report.loads["g.F_x"].del_by_exponent[3.0] == pytest.approx(6.5e9 ** (1 / 3), rel=1e-9)
    # given names without declared units, none is made up from a name
    plain = fatigue_report(series, time_s=t, names=["g.F_x"])
    assert plain.loads["g.F_x"].unit == "" and plain.ldd == {}
    with pytest.raises(ParameterError, match="torques"):
        fatigue_report(series, time_s=t, names=["g.F_x"], torques=["g.shaft1.torque"])
