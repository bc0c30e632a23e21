"""Analyses of a monolithic result read kinds and units from its declarations, never from a series' name (issue 31.4).

A result whose ``shaft1.torque`` is declared a contact force [N] and whose ``stage1.F_x`` is declared a shaft
torque [N m]: every analysis treats the first as a force and the second as a torque, as declared.
"""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.contact_loss import contact_loss_summary
from components.analysis.fatigue import fatigue_report
from components.model.presets import table3_parallel
from components.model.signals import CONTACT_FORCE, ROTOR_SPEED, SHAFT_TORQUE, Signal
from components.reference.cases import case_statistics
from components.reference.results import SimulationResult

T = np.linspace(0.0, 2.0, 2001)


def _misnamed() -> SimulationResult:
    force = 1000.0 * np.sin(2 * np.pi * T)  # through zero: contact losses
    torque = 2000.0 + 1000.0 * np.sin(2 * np.pi * T)
    return SimulationResult(
        time_s=T,
        series={"omega_rotor": np.full(T.size, 0.5), "shaft1.torque": force, "stage1.F_x": torque},
        signals={"omega_rotor": Signal("rad/s", "rotor speed", ROTOR_SPEED),
                 "shaft1.torque": Signal("N", "a contact force", CONTACT_FORCE,
                                         (("stage", "stage1"), ("mesh", "parallel"))),
                 "stage1.F_x": Signal("N.m", "a shaft torque", SHAFT_TORQUE, (("shaft", "shaft1"),))})


def test_the_declared_force_named_like_a_torque_is_the_one_contact_loss_counts():
    stats = contact_loss_summary(_misnamed())
    assert list(stats) == ["shaft1.torque"] and stats["shaft1.torque"].separations > 0


def test_fatigue_takes_the_torque_and_the_units_as_declared():
    report = fatigue_report(_misnamed())
    assert {n: fl.unit for n, fl in report.loads.items()} == {"shaft1.torque": "N", "stage1.F_x": "N.m"}
    assert list(report.ldd) == ["stage1.F_x"] and report.ldd["stage1.F_x"].unit == "N.m"


def test_a_reference_case_reports_the_declared_force_with_its_backlash_fraction():
    stats = case_statistics(_misnamed(), table3_parallel(), (0.0, 2.0))
    assert "backlash_fraction" in stats["shaft1.torque"] and "stage1.F_x" not in stats


@pytest.mark.parametrize("analysis", [contact_loss_summary, fatigue_report])
def test_a_plain_mapping_declares_no_kinds_so_the_loads_must_be_named(analysis):
    from components.errors import ParameterError

    with pytest.raises(ParameterError, match=r"names = None: expected the .* of a plain mapping of series, as "
                                             r"declared"):
        analysis(dict(_misnamed().series), time_s=T)


def test_the_reference_files_carry_the_declared_units(tmp_path):
    from components.reference.cases import CASES
    from orchestrator.reports.reference_cases import write_reference_outputs
    from orchestrator.result_files import read_timeseries

    write_reference_outputs(_misnamed(), CASES["table2"], {}, tmp_path, plot=True)
    header, _ = read_timeseries(tmp_path / "timeseries.csv")
    assert header == ["time [s]", "omega_rotor [rad/s]", "shaft1.torque [N]", "stage1.F_x [N.m]"]
    assert (tmp_path / "reference.png").stat().st_size > 10_000  # the declared force drawn as stage1's
