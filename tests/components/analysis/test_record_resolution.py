"""The resolution and sampling of recorded values, and the zero-phase low-pass, against hand-made records."""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.record_resolution import (
    estimate_resolution,
    lowpass_zero_phase,
    sampling_of,
    significant_digits,
    step_ratio,
)
from components.errors import ParameterError


def _written(values, fmt: str) -> np.ndarray:
    """The values as a text record writes them (``"%.2E"``: 3 significant digits)."""
    return np.array([float(fmt % v) for v in values])


@pytest.mark.parametrize("value, digits", [(9.98, 3), (10.0, 1), (0.0493, 3), (12.1, 3), (1.0 / 3.0, 12), (0.0, 0)])
def test_significant_digits_by_hand(value, digits):
    assert significant_digits(np.array([value]))[0] == digits


def test_a_speed_written_with_3_significant_digits_has_0_01_rpm_steps_below_10_and_0_1_above():
    t = np.arange(0.0, 20.0, 0.05)
    rpm = _written(9.0 + 2.0 * t / 20.0 + 0.003 * np.sin(t), "%.2E")  # 9 to 11 rpm: FAST's ES10.3E2
    res = estimate_resolution(rpm)
    assert res.kind == "significant_digits" and res.digits == 3
    np.testing.assert_allclose(res.steps[rpm < 10.0], 0.01)
    np.testing.assert_allclose(res.steps[rpm >= 10.0], 0.1)
    assert "3 significant digits: steps 0.01 to 0.1 rpm" in res.describe("rpm")


def test_fixed_decimals_and_an_even_16_bit_lattice_and_full_precision():
    x = np.linspace(-3.0, 250.0, 400)
    dec = estimate_resolution(_written(x, "%.2f"))
    assert (dec.kind, dec.digits) == ("decimals", 2) and dec.step == pytest.approx(0.01)
    lo, hi = 11.0, 12.7  # an .outb channel: 16-bit integers times a scale plus an offset
    codes = np.concatenate(([0.0], np.arange(1000.0, 3000.0), [65535.0]))  # a slow signal hits every code
    lattice = estimate_resolution(lo + codes * (hi - lo) / 65535.0)
    assert lattice.kind == "uniform" and lattice.step == pytest.approx((hi - lo) / 65535.0, rel=1e-6)
    assert estimate_resolution(np.sin(x) * np.pi).kind == "none"
    assert estimate_resolution(np.full(5, 3.0)).kind == "constant"


def test_a_staircase_that_moves_one_step_every_n_samples_has_the_step_ratio_n():
    n, q = 4, 0.01
    x = np.repeat(np.arange(50) * q, n)
    # 199 intervals, each with the step q, against 49 moves of q: 199 / 49 = 4.06, n for a long staircase
    assert step_ratio(x, np.full(x.shape, q)) == pytest.approx((x.size - 1) / 49)
    assert step_ratio(x, np.full(x.shape, q)) == pytest.approx(n, rel=0.02)
    smooth = np.linspace(0.0, 1.0, 200)  # moves 1/199 per sample, far more than a 1e-6 step
    assert step_ratio(smooth, np.full(smooth.shape, 1e-6)) == pytest.approx(199e-6, rel=1e-9)


def test_sampling_of_an_even_and_an_uneven_grid():
    even = sampling_of(np.arange(0.0, 1.0, 0.05))
    assert even.uniform and even.interval_s == pytest.approx(0.05) and even.nyquist_hz == pytest.approx(10.0)
    assert not sampling_of([0.0, 0.05, 0.1, 0.2]).uniform
    with pytest.raises(ParameterError, match="strictly increasing"):
        sampling_of([0.0, 0.1, 0.1])


def test_the_low_pass_has_no_delay_keeps_slow_signals_and_removes_fast_ones():
    dt = 0.05
    t = np.arange(0.0, 60.0, dt)
    slow = np.sin(2 * np.pi * 0.1 * t)          # 0.1 Hz: a tenth of the cut-off
    fast = 0.5 * np.sin(2 * np.pi * 5.0 * t)    # 5 Hz: five times the cut-off
    y = lowpass_zero_phase(12.0 + slow + fast, dt, 1.0)
    inner = slice(200, -200)
    # zero phase: the slow part comes out in phase (Butterworth |H|^2 at f/fc = 0.1, order 2: 1 - 1e-4)
    np.testing.assert_allclose(y[inner] - 12.0, slow[inner], atol=2e-3)
    assert np.argmax(np.correlate(y[inner] - 12.0, slow[inner], "full")) == len(slow[inner]) - 1
    # the 5 Hz part is attenuated by |H|^2 = 1 / (1 + 5^4) = 1.6e-3
    residual = y[inner] - 12.0 - slow[inner]
    assert np.std(residual) < 2e-3 * np.std(fast)


@pytest.mark.parametrize("cutoff, match", [(10.0, r"\(0, 10\) Hz"), (25.0, "Nyquist")])
def test_a_cut_off_at_or_above_nyquist_is_refused(cutoff, match):
    with pytest.raises(ParameterError, match=match):
        lowpass_zero_phase(np.zeros(100), 0.05, cutoff)

