"""Contact-loss counting: synthetic forces with known episodes, and load events on the Table 6 drivetrain."""

import csv

import numpy as np
import pytest

from components.analysis.contact_loss import (
    contact_loss_events,
    contact_loss_summary,
    write_contact_loss_csv,
)
from components.analysis.equilibrium import static_equilibrium
from components.errors import ParameterError
from components.model.generator import LoadEvent
from components.model.presets import table6_gearbox
from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.cases import CONTACT_LOSS_THRESHOLD_N
from components.reference.solver import simulate_monolithic


def test_triangle_wave_crossings_are_counted_exactly():
    """Triangle between +100 and -100 N, period 1 s (slope 400 N/s): every zero crossing spends
    2 N / 400 N/s = 5 ms inside |F| < 1 N and changes flank."""
    t = np.arange(0.0, 4.0 + 1e-12, 0.25)  # vertices and zero crossings on samples
    f = np.tile([100.0, 0.0, -100.0, 0.0], 5)[: t.size]
    st = contact_loss_events(t, f, name="x")
    assert st.separations == 8
    assert st.flank_changes == 8
    assert st.time_in_backlash_s == pytest.approx(8 * 0.005, rel=1e-12)
    assert st.longest_episode_s == pytest.approx(0.005, rel=1e-12)
    assert st.backlash_fraction == pytest.approx(0.04 / 4.0)


def test_jump_through_the_band_between_two_samples_counts():
    st = contact_loss_events(np.array([0.0, 1.0]), np.array([100.0, -100.0]))
    assert (st.separations, st.flank_changes) == (1, 1)
    assert st.time_in_backlash_s == pytest.approx(2.0 / 200.0)


def test_separation_back_to_the_same_flank_and_initial_episode():
    t = np.arange(6.0)
    st = contact_loss_events(t, np.array([50.0, 0.0, 0.0, 50.0, 50.0, 50.0]))
    assert (st.separations, st.flank_changes) == (1, 0)
    # linear between samples: |F| < 1 N on the last 1/50 of 50 -> 0, the whole 0 -> 0, the first 1/50 of 0 -> 50
    assert st.time_in_backlash_s == pytest.approx(1.0 + 2 / 50)
    start = contact_loss_events(t, np.array([0.0, 0.0, 50.0, 50.0, 0.5, 50.0]))
    assert start.separations == 1  # the initial stay (teeth centred in the backlash) is not a separation
    assert start.longest_episode_s == pytest.approx(1.0 + 1 / 50)


def test_window_and_bad_input():
    t = np.linspace(0.0, 2.0, 201)
    f = np.where(t < 1.0, 0.0, 1e3)
    assert contact_loss_events(t, f, window=(1.0, 2.0)).time_in_backlash_s == 0.0
    with pytest.raises(ParameterError, match="threshold_n"):
        contact_loss_events(t, f, threshold_n=0.0)
    with pytest.raises(ParameterError, match="finite"):
        contact_loss_events(t, np.full(t.size, np.nan))
    with pytest.raises(ParameterError, match="increasing"):
        contact_loss_events(t[::-1], f)


@pytest.mark.parametrize("event, loses_contact", [
    (None, False),
    (LoadEvent("torque_step", 1.0, 0.5, 2.0), False),  # doubled torque: harder contact, no loss
    (LoadEvent("grid_fault", 1.0, 0.5), True),  # torque to zero for 0.5 s: the generator mode swings through
    (LoadEvent("emergency_stop", 1.0, 1.0), True),  # reversed torque
])
def test_load_events_on_the_table6_drivetrain(event, loses_contact, tmp_path):
    """Monolithic Table 6 run with the paper's wind from the static equilibrium, 3 s."""
    base = table6_gearbox()
    dt = base if event is None else base.with_generator(events=(event,))
    eq = static_equilibrium(base, base.generator.counter_torque_nm)
    result = simulate_monolithic(dt, RotorSpeedProcess(WindParameters()), 3.0, 1e-3, initial_state=eq.state)
    assert result.complete  # no solver failure through the backlash
    stats = contact_loss_summary(result)
    assert len(stats) == 13
    assert all(s.threshold_n == CONTACT_LOSS_THRESHOLD_N for s in stats.values())
    if loses_contact:
        for name in ("stage1.F_sp[1]", "stage2.F_rp[3]", "stage3.F_mesh"):
            s = stats[name]
            assert s.separations > 0 and s.flank_changes > 0, s
            assert 0.0 < s.time_in_backlash_s < 0.5
        assert result["stage3.F_mesh"].min() < -1e4  # loaded on the reverse flank
    else:
        assert all(s.separations == 0 and s.time_in_backlash_s == 0.0 for s in stats.values())
    rows = list(csv.DictReader(write_contact_loss_csv(tmp_path / "contact_loss.csv", stats).open()))
    assert [r["name"] for r in rows] == list(stats)
