"""Level histograms on the power-of-two lattice: exact times, revolutions and merging."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.analysis.load_spectrum import LATTICE_LEVELS, LevelHistogram, lattice_exponent, level_histogram, merge_histograms
from components.errors import ParameterError


def _run(seed: int, mean: float, n: int = 20001):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 50.0, n))
    load = mean + 300.0 * np.sin(0.7 * t) + 20.0 * rng.standard_normal(n)
    speed = 1.5 + 0.1 * np.cos(0.3 * t)
    return t, load, speed


def test_times_sum_to_the_run_and_revolutions_are_the_trapezoid_integral_of_the_speed():
    t, load, speed = _run(1, 2e4)
    h = level_histogram(t, load, {"gear": speed})
    assert h.total_time_s == pytest.approx(t[-1] - t[0], rel=1e-13)
    assert h.total_revolutions("gear") == pytest.approx(np.trapezoid(speed, t) / (2 * math.pi), rel=1e-13)
    span = load.max() - load.min()
    assert LATTICE_LEVELS <= span / h.width < 2 * LATTICE_LEVELS
    assert np.all(h.lower <= load.max()) and h.lower[0] <= load.min() < h.upper[0]


def test_coarsening_and_merging_are_exact_regroupings_of_cells():
    runs = [_run(s, m) for s, m in ((1, 2e4), (2, 5e4), (3, -1e3))]
    hs = [level_histogram(t, y, {"gear": w}) for t, y, w in runs]
    assert len({h.exponent for h in hs}) >= 1
    weights = [2.0, 0.5, 3.0]
    merged = merge_histograms(hs, weights)
    assert merged.exponent == max(h.exponent for h in hs)
    assert merged.total_time_s == pytest.approx(sum(w * h.total_time_s for h, w in zip(hs, weights)), rel=1e-13)
    # the same samples binned directly on the merged lattice give the same cells
    direct = merge_histograms([level_histogram(t, y, {"gear": w}, exponent=merged.exponent) for t, y, w in runs], weights)
    assert np.array_equal(direct.indices, merged.indices)
    assert direct.time_s == pytest.approx(merged.time_s, rel=1e-12, abs=1e-12)
    assert direct.revolutions["gear"] == pytest.approx(merged.revolutions["gear"], rel=1e-12, abs=1e-12)
    small = merged.with_at_most(64)
    assert small.indices[-1] - small.indices[0] + 1 <= 64
    assert small.total_revolutions("gear") == pytest.approx(merged.total_revolutions("gear"), rel=1e-13)


def test_negative_loads_fall_in_floor_cells_and_round_trip_through_arrays():
    t = np.linspace(0.0, 1.0, 5)
    h = level_histogram(t, np.array([-3.0, -1.0, 0.0, 1.0, 3.0]), exponent=1)
    assert h.indices.tolist() == [-2, -1, 0, 1] and h.time_s.tolist() == [0.125, 0.25, 0.5, 0.125]  # 1 / 2 floors to cell 0
    assert h.coarsened(2).indices.tolist() == [-1, 0]
    gappy = level_histogram(t, np.array([-3.0, -3.0, 5.0, 5.0, 5.0]), exponent=1)
    edges, time, _ = gappy.dense()
    assert edges.tolist() == [-4.0, -2.0, 0.0, 2.0, 4.0, 6.0] and time.tolist() == [0.375, 0.0, 0.0, 0.0, 0.625]
    again = LevelHistogram.from_arrays(h.as_arrays())
    assert again.exponent == 1 and np.array_equal(again.time_s, h.time_s)
    assert lattice_exponent(np.full(3, 5.0)) == math.floor(math.log2(5.0 / LATTICE_LEVELS))


def test_bad_inputs_name_what_is_wrong():
    with pytest.raises(ParameterError, match="increasing"):
        level_histogram(np.array([0.0, 0.0, 1.0]), np.ones(3))
    t, y, w = _run(1, 1.0)
    with pytest.raises(ParameterError, match="same gears"):
        merge_histograms([level_histogram(t, y, {"a": w}), level_histogram(t, y)])
