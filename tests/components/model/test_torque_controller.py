"""The NREL 5-MW baseline torque law: each region against hand-computed values, filter and rate limit."""

from __future__ import annotations

import math

import pytest

from components.errors import ParameterError
from components.model.torque_controller import TorqueController, TorqueLawParameters, law_torque_nm, region_of

P = TorqueLawParameters()
# hand-computed from the DISCON constants (Jonkman et al. 2009, Sec. 7)
SYNC = 121.6805 / 1.1                                       # 110.61864 rad/s
SLOPE25 = (5296610.0 / 121.6805) / (121.6805 - SYNC)        # 3935.036 N m s/rad
SLOPE15 = 2.332287 * 91.21091 ** 2 / (91.21091 - 70.16224)  # 921.830 N m s/rad


def test_derived_constants():
    assert P.sync_speed_rad_s == pytest.approx(110.618636, rel=1e-8)
    assert P.slope25_nm_s == pytest.approx(SLOPE25, rel=1e-12)
    assert P.slope15_nm_s == pytest.approx(SLOPE15, rel=1e-12)
    w = P.transition_speed_rad_s  # k w^2 = slope25 (w - sync) there
    assert 2.332287 * w * w == pytest.approx(SLOPE25 * (w - SYNC), rel=1e-10)
    assert w == pytest.approx(119.0138, abs=1e-3)  # VS_TrGnSp of the baseline


@pytest.mark.parametrize("speed, region, torque", [
    (50.0, "1", 0.0),
    (70.16224, "1", 0.0),
    (80.0, "1.5", SLOPE15 * (80.0 - 70.16224)),
    (100.0, "2", 2.332287 * 100.0 ** 2),
    (115.0, "2", 2.332287 * 115.0 ** 2),
    (120.0, "2.5", SLOPE25 * (120.0 - SYNC)),
    (121.6805, "3", 5296610.0 / 121.6805),
    (125.0, "3", 5296610.0 / 125.0),
    (130.0, "3", 5296610.0 / 130.0),
])
def test_each_region(speed, region, torque):
    assert region_of(P, speed) == region
    assert law_torque_nm(P, speed) == pytest.approx(torque, rel=1e-12)


def test_region3_by_pitch_and_constant_torque_mode():
    q = TorqueLawParameters(region3_mode="constant_torque", rated_torque_nm=43664.0)
    assert region_of(q, 110.0, pitch_rad=math.radians(2.0)) == "3"
    assert law_torque_nm(q, 110.0, math.radians(2.0)) == 43664.0
    assert law_torque_nm(q, 110.0, 0.0) == pytest.approx(2.332287 * 110.0 ** 2)


def test_max_torque_limits_constant_power_at_low_speed():
    assert law_torque_nm(P, 100.0, pitch_rad=0.1) == 47402.91  # 5296610 / 100 = 52966 > VS_MaxTq


def test_filter_is_exact_first_order_and_rate_is_limited():
    c = TorqueController(P, 100.0)
    assert c.torque_nm == pytest.approx(2.332287 * 1e4)
    c.step(0.01, 110.0)
    assert c.filtered_speed_rad_s == pytest.approx(100.0 + 10.0 * (1.0 - math.exp(-1.570796 * 0.01)), rel=1e-14)
    c = TorqueController(P, 100.0)
    c.step(0.01, 100.0, pitch_rad=0.1)  # target jumps to 47402.91: at most 15000 N m/s x 0.01 s
    assert c.torque_nm == pytest.approx(2.332287 * 1e4 + 150.0)


def test_inconsistent_constants_are_refused():
    with pytest.raises(ParameterError, match="region2_start"):
        TorqueLawParameters(region2_start_rad_s=130.0)
