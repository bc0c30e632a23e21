"""Time-series playback: exact at record points, the interpolants between them, angles, out-of-record policy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import PchipInterpolator

from components.errors import ParameterError, SolverError
from components.model.time_series import ChannelSpec, Interpolant, TimeSeriesPlayer

T = np.array([0.0, 0.1, 0.25, 0.4, 0.5, 0.8, 1.0])
Y = np.array([1.0, 1.2, 1.1, 1.1, 0.7, 0.9, 1.5])


@pytest.mark.parametrize("method", ["linear", "pchip"])
def test_exact_at_every_record_point(method):
    f = Interpolant(T, Y, method)
    assert [f.value(t) for t in T] == pytest.approx(list(Y), abs=1e-15)


def test_pchip_between_points_is_scipys_pchip():
    f = Interpolant(T, Y, "pchip")
    ref = PchipInterpolator(T, Y)
    ts = np.linspace(0.0, 1.0, 137)
    assert [f.value(t) for t in ts] == pytest.approx(ref(ts), rel=1e-12, abs=1e-12)


def test_linear_between_points():
    f = Interpolant(T, Y, "linear")
    assert f.value(0.175) == pytest.approx((1.2 + 1.1) / 2)


def test_pchip_is_c1_and_does_not_overshoot_a_step():
    t = np.arange(6.0)
    y = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    f = Interpolant(t, y, "pchip")
    ts = np.linspace(0, 5, 501)
    values = np.array([f.value(x) for x in ts])
    assert values.min() >= 0.0 and values.max() <= 1.0
    eps = 1e-7
    for knot in (1.0, 2.0, 3.0, 4.0):  # one-sided slopes agree at the knots: C1
        left = (f.value(knot) - f.value(knot - eps)) / eps
        right = (f.value(knot + eps) - f.value(knot)) / eps
        assert left == pytest.approx(right, abs=1e-5)


@pytest.mark.parametrize("method", ["linear", "pchip"])
def test_integral_is_exact_for_the_interpolant(method):
    f = Interpolant(T, Y, method)
    for t in (0.0, 0.05, 0.25, 0.61, 1.0):
        assert f.integral(t) == pytest.approx(quad(f.value, 0.0, t, limit=200, points=list(T))[0], abs=1e-12)


def test_player_angle_offset_and_hold():
    player = TimeSeriesPlayer(T, np.column_stack([Y]), [ChannelSpec("w", 0), ChannelSpec("phi", 0, integral_of=True, initial=2.0)],
                              time_offset_s=0.25, out_of_record="hold")
    f = Interpolant(T, Y, "pchip")
    w, phi = player.values(0.15)  # record time 0.4
    assert w == pytest.approx(1.1, abs=1e-15)
    assert phi == pytest.approx(2.0 + f.integral(0.4))
    w_end, phi_end = player.values(1.0)  # record time 1.25: held speed, the angle goes on with it
    assert w_end == 1.5
    assert phi_end == pytest.approx(2.0 + f.integral(1.0) + 0.25 * 1.5)


def test_player_refuses_times_outside_the_record():
    player = TimeSeriesPlayer(T, np.column_stack([Y]), [ChannelSpec("w", 0)], out_of_record="error")
    assert player.values(1.0) == [1.5]
    with pytest.raises(SolverError, match=r"record time 1\.1 s .* outside the record \[0, 1\] s"):
        player.values(1.1)


@pytest.mark.parametrize("t, y, match", [
    ([0.0, 0.1, 0.1], [1.0, 2.0, 3.0], "strictly increasing"),
    ([0.0, 0.1, 0.2], [1.0, np.nan, 3.0], "finite"),
    ([0.0], [1.0], "two or more"),
])
def test_bad_samples(t, y, match):
    with pytest.raises(ParameterError, match=match):
        Interpolant(np.array(t), np.array(y))
