"""ISO 281 bearing life against hand values: constant load and speed, a two-level spectrum, a_ISO, a1."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.analysis.bearing_life import (
    LifeModification,
    a_iso,
    basic_rating_life_mrev,
    bearing_life,
    constant_speed_life_hours,
    equivalent_load,
    reliability_factor,
    sample_revolutions,
)
from components.errors import ParameterError


@pytest.mark.parametrize("kind, p", [("ball", 3.0), ("roller", 10.0 / 3.0)])
def test_constant_load_at_constant_speed(kind, p):
    # C = 1 MN, P = 200 kN at 100 rpm for 10 s sampled at 1 ms: L10 = (C/P)^p 1e6 / (60 n) hours
    c, load, rpm = 1.0e6, 2.0e5, 100.0
    t = np.linspace(0.0, 10.0, 10001)
    revs = sample_revolutions(t, np.full(t.size, rpm * math.pi / 30.0))
    assert revs.sum() == pytest.approx(rpm / 60.0 * 10.0, rel=1e-12)  # 16.67 revolutions
    life = bearing_life("b", kind, c, np.full(t.size, load), revs, duty_hours=10.0 / 3600.0)
    expected_h = 5.0**p * 1e6 / (60.0 * rpm)  # ball: 125 x 166.7 h = 20 833 h; roller: 214.0 x 166.7 h = 35 624 h
    assert life.equivalent_load_n == pytest.approx(load, rel=1e-12)
    assert life.l10_mrev == pytest.approx(5.0**p, rel=1e-12)
    assert life.l10_h == pytest.approx(expected_h, rel=1e-9)
    assert constant_speed_life_hours(c, load, p, rpm) == pytest.approx(expected_h, rel=1e-12)
    assert life.lnm_h is None and life.met


def test_a_two_level_spectrum():
    # roller bearing, C = 500 kN: 3e6 revolutions at 100 kN, 1e6 at 200 kN
    # P = ((100^(10/3) 3 + 200^(10/3) 1) / 4)^(3/10) kN = ((3 x 4.6416e6 + 4.6783e7) / 4)^0.3 = (1.5177e7)^0.3 = 142.68 kN
    p = 10.0 / 3.0
    loads, revs = np.array([1e5, 2e5]), np.array([3e6, 1e6])
    p_eq = ((1e5**p * 3e6 + 2e5**p * 1e6) / 4e6) ** (1 / p)
    assert p_eq == pytest.approx(1.4268e5, rel=1e-4)
    assert equivalent_load(loads, revs, p) == pytest.approx(p_eq, rel=1e-12)
    # Miner over the levels gives the same life: 1 / L = 0.75 / L(100 kN) + 0.25 / L(200 kN)
    miner = 1.0 / (0.75 / basic_rating_life_mrev(5e5, 1e5, p) + 0.25 / basic_rating_life_mrev(5e5, 2e5, p))
    life = bearing_life("b", "roller", 5e5, loads, revs, duty_hours=1000.0)
    assert life.l10_mrev == pytest.approx(miner, rel=1e-12) == pytest.approx((5e5 / p_eq) ** p, rel=1e-12)
    assert life.l10_h == pytest.approx(life.l10_mrev * 1e6 / 4e3, rel=1e-12)  # 4e6 rev in 1000 h
    # with a constant a_ISO and 99 % reliability: L_nm = 0.25 x 2 x L10
    mod = LifeModification(reliability_percent=99.0, a_iso=2.0)
    assert bearing_life("b", "roller", 5e5, loads, revs, 1000.0, mod).lnm_mrev == pytest.approx(0.5 * life.l10_mrev)


def test_a_iso_by_iso_281():
    # roller, kappa = 1: 0.1 [1 - (1.5859 - 1.2348 / 1^0.071739) 0.1^0.4]^-9.185 = 0.1 x 0.86023^-9.185 = 0.3986
    assert a_iso("roller", 1.0, 0.1) == pytest.approx(0.1 * (1 - 0.3511 * 0.1**0.4) ** -9.185, rel=1e-12)
    assert a_iso("roller", 1.0, 0.1) == pytest.approx(0.3986, abs=1e-4)
    # ball, kappa = 0.5: 0.1 [1 - (2.5671 - 1.9987 / 0.5^0.19087)^0.83 0.2^(1/3)]^-9.3
    b = 2.5671 - 1.9987 / 0.5**0.19087
    assert a_iso("ball", 0.5, 0.2) == pytest.approx(0.1 * (1 - b**0.83 * 0.2 ** (1 / 3)) ** -9.3, rel=1e-12)
    assert a_iso("roller", 0.1, 0.5) == pytest.approx(0.1, abs=2e-4)  # poor lubrication: the floor 0.1
    assert a_iso("ball", 9.0, 0.3) == a_iso("ball", 4.0, 0.3)  # kappa above 4 counts as 4
    assert a_iso("roller", 4.0, 10.0) == 50.0  # the limit
    with pytest.raises(ParameterError, match="kappa"):
        a_iso("ball", 0.05, 0.1)


def test_a_iso_per_level_under_a_spectrum():
    mod = LifeModification(viscosity_ratio=1.0, contamination_factor=0.5, fatigue_load_limit_n=4e4)
    loads, revs = np.array([1e5, 2e5]), np.array([1e6, 1e6])
    a = [a_iso("roller", 1.0, 0.5 * 4e4 / p) for p in loads]
    expected = 1.0 / sum(0.5 * (p / 5e5) ** (10 / 3) / ai for p, ai in zip(loads, a))
    life = bearing_life("b", "roller", 5e5, loads, revs, 100.0, mod)
    assert life.lnm_mrev == pytest.approx(expected, rel=1e-12)
    assert life.lnm_mrev < life.l10_mrev  # e_C C_u / P = 0.1-0.2 with kappa 1: a_ISO 0.3-0.4


@pytest.mark.parametrize("reliability, a1", [(90, 1.0), (95, 0.64), (99, 0.25), (99.95, 0.077)])
def test_reliability_factors_of_iso_281_table_12(reliability, a1):
    assert reliability_factor(reliability) == a1


@pytest.mark.parametrize("kwargs, match", [
    (dict(reliability_percent=93.0), "reliability"),
    (dict(a_iso=2.0, viscosity_ratio=1.0, contamination_factor=0.5, fatigue_load_limit_n=1e4), "either a_iso"),
    (dict(viscosity_ratio=1.0), "all three"),
    (dict(a_iso=60.0), "a_iso"),
])
def test_inconsistent_life_modifications_are_refused(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        LifeModification(**kwargs)


def test_a_bearing_that_never_turns_is_refused():
    with pytest.raises(ParameterError, match="turned"):
        equivalent_load(np.array([1e5]), np.array([0.0]), 3.0)
    with pytest.raises(ParameterError, match="ball"):
        bearing_life("b", "needle", 1e5, np.array([1e5]), np.array([1.0]), 1.0)


@pytest.mark.parametrize("load_n, unloaded", [(1e-9, True), (1e-3, True), (1.1e-3, False), (100.0, False)])
def test_a_load_at_round_off_is_no_load_and_the_lives_are_infinite(load_n, unloaded):
    # C = 1 MN: a floating sun's bearing carries ~1e-9 N of round-off, which (C/P)^3 made ~1e45 x 1e6 rev;
    # at most 1e-9 C (here 1e-3 N) is no load; just above it the life is (C/P)^p as ever
    revs = np.full(3, 10.0)
    life = bearing_life("sun", "ball", 1e6, np.full(3, load_n), revs, duty_hours=1.0,
                        modification=LifeModification(reliability_percent=99.0, a_iso=1.0))
    assert life.unloaded is unloaded and life.met
    if unloaded:
        assert math.isinf(life.l10_mrev) and math.isinf(life.l10_h) and math.isinf(life.lnm_h)
        assert life.as_dict()["L10_h"] is None and life.as_dict()["unloaded"] is True
    else:
        assert life.l10_mrev == pytest.approx((1e6 / load_n) ** 3, rel=1e-12) and math.isfinite(life.lnm_h)
