"""Lifetime fatigue: wind-bin probabilities, S-N curves, lifetime DEL and damage against hand values and pCrunch."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.analysis.fatigue import RainflowCycles, damage_equivalent_load, rainflow
from components.analysis.lifetime import SECONDS_PER_YEAR, DesignLife, lifetime_damage, lifetime_del, run_weights
from components.analysis.operating_law import OperatingLaw
from components.analysis.sn_curve import SNCurve
from components.analysis.wind_distribution import WindDistribution, bin_probabilities
from components.errors import ParameterError


# --------------------------------------------------------------- wind
@pytest.mark.parametrize("cls, v_ave", [("I", 10.0), ("II", 8.5), ("III", 7.5)])
def test_iec_rayleigh_bin_probabilities_are_the_cdf_differences_of_iec_61400_1_eq_8(cls, v_ave):
    wind = WindDistribution.iec(cls)
    edges = np.array([3.0, 5.0, 25.0])
    hand = [math.exp(-math.pi * (lo / (2 * v_ave)) ** 2) - math.exp(-math.pi * (hi / (2 * v_ave)) ** 2)
            for lo, hi in zip(edges[:-1], edges[1:])]
    assert np.allclose(bin_probabilities(wind, edges), hand, rtol=1e-13)
    assert wind.mean_speed_m_s == pytest.approx(v_ave, rel=1e-13)


def test_weibull_mean_and_probabilities_of_all_speeds_sum_to_one():
    wind = WindDistribution.weibull(2.2, 9.0)
    assert wind.mean_speed_m_s == pytest.approx(9.0 * math.gamma(1 + 1 / 2.2), rel=1e-14)
    assert bin_probabilities(wind, np.array([0.0, 10.0, 1e3])).sum() == pytest.approx(1.0, abs=1e-15)
    with pytest.raises(ParameterError, match="increasing"):
        bin_probabilities(wind, np.array([5.0, 3.0]))


# ---------------------------------------------------------------- S-N
def test_sn_curve_with_knee_second_slope_and_endurance_limit():
    curve = SNCurve(5.0, 100.0, 2e6, knee_cycles=1e7, slope_after_knee=9.0)
    knee = 100.0 * (2e6 / 1e7) ** (1 / 5)
    assert curve.knee_range == pytest.approx(knee, rel=1e-14)
    n = curve.cycles_to_failure(np.array([200.0, knee, 0.5 * knee]))
    assert n == pytest.approx([2e6 * 0.5**5, 1e7, 1e7 * 2.0**9], rel=1e-13)
    flat = SNCurve(5.0, 100.0, 2e6, knee_cycles=1e7)  # endurance limit: no damage below the knee
    assert flat.damage(np.array([0.5 * knee, 200.0]), np.zeros(2), np.array([1e9, 1.0])) == pytest.approx(1 / (2e6 / 32))


def test_goodman_uses_the_magnitude_of_the_mean_and_refuses_a_mean_beyond_the_ultimate():
    curve = SNCurve.from_ultimate(4.0, 1000.0, goodman=True)
    eq = curve.equivalent_ranges(np.array([10.0, 10.0]), np.array([500.0, -500.0]))
    assert eq == pytest.approx([20.0, 20.0])
    assert curve.damage(np.array([10.0]), np.array([500.0]), np.array([0.5])) == pytest.approx(0.5 * (20.0 / 1000.0) ** 4)
    with pytest.raises(ParameterError, match="largest cycle mean"):
        curve.equivalent_ranges(np.array([1.0]), np.array([1000.0]))
    with pytest.raises(ParameterError, match="ultimate load"):
        SNCurve(4.0, 1.0, goodman=True)


# ------------------------------------------------------------ weights
def test_run_weights_pool_the_seeds_of_a_bin():
    life = DesignLife(20.0, 0.9)
    w = run_weights([0, 0, 1], [600.0, 300.0, 600.0], [0.25, 0.5], life)
    t_life = 20 * SECONDS_PER_YEAR
    assert w == pytest.approx([0.9 * 0.25 * t_life / 900, 0.9 * 0.25 * t_life / 900, 0.9 * 0.5 * t_life / 600])
    with pytest.raises(ParameterError, match="availability"):
        DesignLife(20.0, 0.0)


# ---------------------------------------------- two bins of pure cosines
#: (amplitude, frequency [Hz], mean) of the two bins; the cosines start and end at a crest
COSINES = [(1500.0, 1.0, 20e3), (4000.0, 2.0, 35e3)]
LENGTH_S = 60.0
DT_S = 1e-3
WIND = WindDistribution.weibull(2.0, 8.0)
EDGES = np.array([4.0, 10.0, 16.0])
LIFE = DesignLife(20.0, 0.95)


def _cosine(amplitude, frequency, mean):
    t = np.arange(0.0, LENGTH_S + DT_S / 2, DT_S)
    return t, mean + amplitude * np.cos(2 * np.pi * frequency * t)


def _hand_lifetime_del(m, n_eq):
    probs = np.diff(1 - np.exp(-((EDGES / 8.0) ** 2)))
    total = sum(LIFE.availability * LIFE.seconds * p * f * (2 * a) ** m for p, (a, f, _) in zip(probs, COSINES))
    return (total / n_eq) ** (1 / m)


@pytest.mark.parametrize("residue", ["half", "repeat"])
def test_a_cosine_has_one_cycle_of_twice_its_amplitude_per_period(residue):
    a, f, mean = COSINES[1]
    cycles = rainflow(_cosine(a, f, mean)[1], residue=residue)
    assert cycles.total_cycles == f * LENGTH_S
    assert np.allclose(cycles.ranges, 2 * a, rtol=1e-12)
    assert damage_equivalent_load(cycles, 4.0, LENGTH_S) == pytest.approx(2 * a * f ** 0.25, rel=1e-12)


@pytest.mark.parametrize("m", [3.0, 5.0, 8.0, 10.0])
def test_lifetime_del_of_two_cosine_bins_equals_the_hand_value(m):
    cycles = [rainflow(_cosine(*c)[1]) for c in COSINES]
    weights = run_weights([0, 1], [LENGTH_S, LENGTH_S], bin_probabilities(WIND, EDGES), LIFE)
    assert lifetime_del(cycles, weights, m, 1e7) == pytest.approx(_hand_lifetime_del(m, 1e7), rel=1e-9)


def test_lifetime_damage_of_two_cosine_bins_and_the_share_of_each_bin():
    cycles = [rainflow(_cosine(*c)[1]) for c in COSINES]
    probs = bin_probabilities(WIND, EDGES)
    weights = run_weights([0, 1], [LENGTH_S, LENGTH_S], probs, LIFE)
    curve = SNCurve(5.0, 2e4, 1e6, knee_cycles=5e6, slope_after_knee=9.0, ultimate_load=2e5, goodman=True)
    dmg = lifetime_damage(cycles, weights, [0, 1], 2, curve)
    hand = []
    for p, (a, f, mean) in zip(probs, COSINES):
        s_eq = 2 * a / (1 - mean / 2e5)
        n_fail = curve.cycles_to_failure(np.array([s_eq]))[0]
        hand.append(LIFE.availability * LIFE.seconds * p * f / n_fail)
    assert dmg.by_bin == pytest.approx(hand, rel=1e-9)
    assert dmg.total == pytest.approx(sum(hand), rel=1e-9)
    assert dmg.share_by_bin.sum() == pytest.approx(1.0, rel=1e-12)


# ------------------------------------------------------------ pCrunch
def _pcrunch_lifetime(series, time_s, probs, m, life, bins=100):
    """pCrunch's lifetime Miner sum of a unit S-N curve (N = S^-m) and its weighted DEL, for a channel ``x``."""
    from pCrunch import AeroelasticOutput, Crunch, FatigueParams

    outputs = [AeroelasticOutput({"Time": t, "x": y}, name=f"run{i}") for i, (t, y) in enumerate(zip(time_s, series))]
    crunch = Crunch(outputs, probability=np.asarray(probs, dtype=float),
                    fatigue_channels={"x": FatigueParams(slope=m, S_intercept=1.0, bins=bins)})
    crunch.process_outputs()
    # pCrunch's year is 365 days and it renormalises the probabilities over the runs (see docs/lifetime.md)
    dels, damage = crunch.compute_total_fatigue(lifetime=life.years * 365.25 / 365.0, availability=life.availability)
    return float(damage["x"]["Weighted"]) * float(np.sum(probs)), float(dels["x"]["Weighted"]), crunch.dels["x"].to_numpy()


@pytest.mark.parametrize("m", [3.0, 5.0, 10.0])
def test_pcrunch_lifetime_del_of_the_cosine_bins_agrees_within_half_a_percent(m):
    runs = [_cosine(*c) for c in COSINES]
    probs = bin_probabilities(WIND, EDGES)
    miner, weighted_mean_del, short = _pcrunch_lifetime([y for _, y in runs], [t for t, _ in runs], probs, m, LIFE)
    hand = _hand_lifetime_del(m, 1e7)
    assert (miner / 1e7) ** (1 / m) == pytest.approx(hand, rel=5e-3)
    ours = [damage_equivalent_load(rainflow(y), m, LENGTH_S) for _, y in runs]
    assert short == pytest.approx(ours, rel=5e-3)
    # pCrunch's own "Weighted" DEL is the probability-weighted mean of the short-term DELs: not damage-equivalent
    assert weighted_mean_del == pytest.approx(np.dot(probs / probs.sum(), short), rel=1e-12)


# --------------------------------------------------------- operating law
def test_operating_law_region_2_and_region_3():
    law = OperatingLaw(12.0, rated_rotor_speed_rad_s=1.6, rated_torque_nm=25e3, rated_sigma_rad_s=0.01,
                       rated_spectrum_level=2e-4, minimum_rotor_speed_rad_s=0.6)
    p = law.at(6.0)
    assert (p.region, p.rotor_speed_rad_s, p.generator_torque_nm) == ("2", pytest.approx(0.8), pytest.approx(6250.0))
    assert p.sigma_rad_s == pytest.approx(0.005) and p.spectrum_level == pytest.approx(5e-5)
    assert law.at(3.0).rotor_speed_rad_s == 0.6  # held at the minimum speed
    top = law.at(20.0)
    assert (top.region, top.rotor_speed_rad_s, top.generator_torque_nm, top.sigma_rad_s) == ("3", 1.6, 25e3, 0.01)


def test_cycles_of_rainflow_counts_are_what_the_lifetime_combines():
    c = RainflowCycles(np.array([2.0, 4.0]), np.zeros(2), np.array([1.0, 0.5]))
    assert lifetime_del([c, c], [1.0, 3.0], 2.0, 8.0) == pytest.approx(math.sqrt((4 * (4 + 8)) / 8))


def test_the_largest_cycle_and_its_share_of_the_lifetime_damage_by_hand():
    # run 0: 10 cycles of 100 and a residue half cycle of 300; run 1: 4 cycles of 200; m = 5, no knee
    runs = [RainflowCycles(np.array([100.0, 300.0]), np.zeros(2), np.array([10.0, 0.5])),
            RainflowCycles(np.array([200.0]), np.zeros(1), np.array([4.0]))]
    weights = [3.0, 2.0]
    curve = SNCurve(5.0, 1000.0, 1e6)
    dmg = lifetime_damage(runs, weights, [0, 1], 2, curve)
    d = {s: (s / 1000.0) ** 5 / 1e6 for s in (100.0, 200.0, 300.0)}  # 1 / N(S)
    total = 3.0 * (10 * d[100.0] + 0.5 * d[300.0]) + 2.0 * 4 * d[200.0]
    assert dmg.total == pytest.approx(total, rel=1e-12)
    big = dmg.largest_cycle
    assert (big.run, big.range, big.count) == (0, 300.0, 0.5)
    assert big.share == pytest.approx(3.0 * 0.5 * d[300.0] / total, rel=1e-12)
    assert 0.5 < big.share < 1.0  # 0.688: the figure rests on one event


def test_no_largest_cycle_without_damage():
    runs = [RainflowCycles(np.zeros(0), np.zeros(0), np.zeros(0))]
    assert lifetime_damage(runs, [1.0], [0], 1, SNCurve(5.0, 1000.0, 1e6)).largest_cycle is None
