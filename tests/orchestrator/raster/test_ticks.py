"""Tick positions and labels of the run figures: hand-computed cases and matplotlib's own rules on many ranges."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.raster import ticks

M = ticks.MINUS


@pytest.mark.parametrize("length_pt, fontsize, horizontal, bins", [
    (644.4, 10.0, True, 9),    # a 10 in wide run figure: 21 labels fit, at most 9 intervals
    (100.0, 10.0, False, 5),   # 100 pt high: one label per 20 pt
    (25.0, 10.0, True, 1),     # too short for one label: still one interval
])
def test_the_intervals_that_fit_an_axis(length_pt, fontsize, horizontal, bins):
    assert ticks.tick_bins(length_pt, fontsize, horizontal) == bins


@pytest.mark.parametrize("vmin, vmax, bins, expected", [
    # the raw step (range / bins) rounded up to 1, 2, 2.5, 5 x a power of ten; ticks from below vmin to above vmax
    (0.0, 60.0, 9, [0, 10, 20, 30, 40, 50, 60]),               # 6.67 -> 10
    (876.0, 925.0, 9, [870, 880, 890, 900, 910, 920, 930]),    # 5.44 -> 10 (5 is below the raw step)
    (876.0, 925.0, 4, [860, 880, 900, 920, 940]),              # 12.25 -> 20
    (15.7, 16.23, 5, [15.6, 15.8, 16.0, 16.2, 16.4]),           # 0.106 -> 0.2
    (-0.23, 0.22, 4, [-0.4, -0.2, 0.0, 0.2, 0.4]),              # 0.1125 -> 0.2
    (0.0, 1.0, 1, [0.0, 1.0]),                                 # 1 -> 1: two ticks inside
])
def test_linear_ticks_take_the_smallest_nice_step_with_at_most_bins_intervals(vmin, vmax, bins, expected):
    np.testing.assert_allclose(ticks.linear_ticks(vmin, vmax, bins), expected, rtol=0, atol=1e-9)


def test_forces_in_kn_and_in_n_keep_their_digits():
    """Stage 1's ~9.0e5 N: in kN the labels are 3 digits, in N 6 digits; an offset would save fewer than 4: none."""
    kn = ticks.linear_labels(np.array([870.0, 880.0, 890.0, 900.0, 910.0, 920.0, 930.0]), 879.0, 922.0)
    assert kn.labels == ("870", "880", "890", "900", "910", "920", "930") and kn.offset_text == ""
    values = ticks.linear_ticks(879e3, 922e3, 7)
    np.testing.assert_allclose(values, np.arange(870e3, 930001.0, 10e3))  # raw step 6143 -> 10000
    n = ticks.linear_labels(values, 879e3, 922e3)
    assert n.labels[1] == "880000" and n.offset_text == "" and (n.offset, n.power) == (0.0, 0)


def test_a_common_offset_leaves_labels_that_would_be_long():
    """Ticks 100000.0 ... 100002.0 share '10000' in front (5 digits): '+1e5' beside the axis, labels 0.0-2.0."""
    labels = ticks.linear_labels(np.array([100000.0, 100000.5, 100001.0, 100001.5, 100002.0]), 100000.0, 100002.0)
    assert labels.labels == ("0.0", "0.5", "1.0", "1.5", "2.0")
    assert (labels.offset_text, labels.offset, labels.power) == ("+1e5", 100000.0, 0)


def test_a_power_of_ten_leaves_labels_of_small_values():
    labels = ticks.linear_labels(np.array([0.0, 1e-6, 2e-6, 3e-6]), 0.0, 3e-6)
    assert labels.labels == ("0", "1", "2", "3")
    assert (labels.offset_text, labels.power) == (f"1e{M}6", -6)


def test_negative_labels_carry_a_true_minus_sign():
    labels = ticks.linear_labels(np.array([-0.2, -0.1, 0.0, 0.1, 0.2]), -0.23, 0.22)
    assert labels.labels == (f"{M}0.2", f"{M}0.1", "0.0", "0.1", "0.2")


def test_log_axes_tick_every_decade_with_minor_ticks_at_2_and_5():
    major, minor = ticks.log_ticks(0.01, 3.5, 9)
    np.testing.assert_allclose(major, [0.01, 0.1, 1.0, 10.0])
    np.testing.assert_allclose(minor, [0.02, 0.05, 0.2, 0.5, 2.0, 5.0, 20.0, 50.0])
    assert ticks.log_labels(major).labels == ("0.01", "0.1", "1", "10")
    major, minor = ticks.log_ticks(1e-3, 1e9, 4)  # 13 decades, room for 4: every third, the others minor
    np.testing.assert_allclose(major, 10.0 ** np.arange(-3, 12, 3))
    assert 1e-2 in minor and 1e0 not in minor
    assert ticks.log_labels(np.array([1e5, 1e6])).labels == ("100000", "1e+06")
    with pytest.raises(ValueError, match="positive limits"):
        ticks.log_ticks(0.0, 1.0, 5)


def _ranges(n: int):
    rng = np.random.default_rng(1)
    for _ in range(n):
        centre = 10 ** rng.uniform(-8, 9) * rng.choice([-1, 1]) * rng.choice([0, 1, 1, 1])
        span = 10 ** rng.uniform(-9, 9)
        low = centre - span * rng.uniform(0, 1)
        yield low, low + span, int(rng.integers(1, 10))


def test_ticks_and_labels_are_those_of_matplotlib_on_600_ranges():
    """The published rules (matplotlib's MaxNLocator with AutoLocator's steps, ScalarFormatter) on random ranges."""
    from matplotlib.ticker import MaxNLocator, ScalarFormatter

    class Axis:  # what the formatter asks of its axis
        def __init__(self, low, high):
            self.view = (low, high)

        def get_view_interval(self):
            return self.view

    for low, high, bins in _ranges(600):
        expected = MaxNLocator(nbins=bins, steps=[1, 2, 2.5, 5, 10]).tick_values(low, high)
        got = ticks.linear_ticks(low, high, bins)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0, err_msg=f"{low!r}..{high!r} in {bins}")
        formatter = ScalarFormatter()
        formatter.axis = Axis(low, high)
        formatter.set_locs(expected)
        labels = ticks.linear_labels(got, low, high)
        assert labels.labels == tuple(formatter(v) for v in expected), (low, high, bins)
        assert labels.offset_text == formatter.get_offset(), (low, high, bins)
