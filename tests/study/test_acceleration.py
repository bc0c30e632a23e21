"""Eq. 11 resolved: the peak output acceleration at every solver step against dense sampling."""

from __future__ import annotations

import numpy as np
import pytest

from components import presets, units
from components.acceleration import peak_output_acceleration
from components.errors import ParameterError
from components.reference import simulate_monolithic
from components.wind import ConstantSpeed


@pytest.mark.parametrize("lambda_per_mm", [10.0, 600.0])
def test_peak_matches_dense_sampling_and_coarse_sampling_misses_it(lambda_per_mm):
    drivetrain = presets.sensitivity_variant(8.0, lambda_per_mm)
    driver = ConstantSpeed(units.rpm(5.0))
    peak = peak_output_acceleration(drivetrain, driver, 2e-3)
    dense = simulate_monolithic(drivetrain, driver, 2e-3, output_interval_s=1e-7)
    alpha = dense.series["alpha_out"]
    k = int(np.argmax(np.abs(alpha)))
    assert peak.value_rad_s2 == pytest.approx(abs(alpha[k]), rel=1e-4)
    assert peak.value_rad_s2 >= abs(alpha[k]) * (1 - 1e-6)  # the search never under-reads the sampled maximum
    assert peak.time_s == pytest.approx(dense.time_s[k], abs=2e-7)
    # the first stage-3 impact, about 0.4 ms after the load step (the free output gear crosses half the backlash)
    assert 3.5e-4 < peak.time_s < 5e-4
    coarse = simulate_monolithic(drivetrain, driver, 2e-3, output_interval_s=1e-4)
    assert np.max(np.abs(coarse.series["alpha_out"])) < 0.95 * peak.value_rad_s2


def test_reference_reports_cpu_time_and_steps():
    result = simulate_monolithic(presets.sensitivity_variant(10.0, 600.0), ConstantSpeed(units.rpm(5.0)), 0.05)
    assert result.info["steps"] > 100 and result.info["rhs_calls"] > result.info["steps"]
    assert 0.0 < result.info["cpu_time_s"] < 60.0


def test_peak_rejects_an_empty_interval():
    with pytest.raises(ParameterError, match=r"t_end_s = 0.0: expected > t_start_s = 0"):
        peak_output_acceleration(presets.sensitivity_variant(10.0, 600.0), ConstantSpeed(1.0), 0.0)
