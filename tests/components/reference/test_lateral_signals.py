"""The bearing outputs of a lateral-torsional gearbox are declared once, for the Gearbox FMU and the reference alike.

:func:`components.model.signals.gearbox_signals` names every output :class:`GearboxModel` writes, in its
order, and declares each bearing's force magnitude and speed with the bearing it belongs to (the rating
plan of ``dtcosim loads`` pairs them by that detail); the monolithic reference declares its series the same.
"""

from __future__ import annotations

import numpy as np
import pytest

from components.model.assembly import Assembly
from components.model.gearbox_model import GearboxModel
from components.model.signals import BEARING_FORCE, BEARING_SPEED, BODY_DISPLACEMENT, gearbox_signals
from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.solver import simulate_monolithic
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

#: paper-table6-lateral: 3 + 2 bearings in each planetary stage (planets, sun, carrier), 2 in the parallel one
BEARINGS = ([f"stage{s}.planet_bearing[{i}]" for s in (1, 2) for i in (1, 2, 3)]
            + [f"stage{s}.{m}_bearing" for s in (1, 2) for m in ("sun", "carrier")]
            + ["stage3.drive_bearing", "stage3.driven_bearing"])


@pytest.fixture(scope="module")
def lateral():
    return load_drivetrain_file(find_drivetrain("paper-table6-lateral")).drivetrain


def test_the_declared_outputs_are_the_gearbox_models_in_its_order(lateral):
    signals = gearbox_signals(Assembly(lateral, cut_at_generator=True))
    names = GearboxModel(lateral).output_names
    first = names.index("torque_rotor") + 1
    assert names[first:names.index("alpha_out")] == list(signals)


def test_each_bearing_force_and_speed_names_its_own_bearing(lateral):
    signals = gearbox_signals(Assembly(lateral, cut_at_generator=True))
    forces = {n: s for n, s in signals.items() if s.kind == BEARING_FORCE}
    speeds = {n: s for n, s in signals.items() if s.kind == BEARING_SPEED}
    assert sorted(s.detail("bearing") for s in forces.values()) == sorted(BEARINGS)
    assert all(s.detail("bearing") == n.removesuffix(".F") and s.unit == "N" for n, s in forces.items())
    assert all(s.detail("bearing") == n.removesuffix(".omega") and s.unit == "rad/s" for n, s in speeds.items())
    assert signals["stage1.planet_bearing[2].F"].detail("body") == "stage1.planet[2]"
    moving = [n for n, s in signals.items() if s.kind == BODY_DISPLACEMENT]
    assert "stage1.sun.x" in moving and all(signals[n].unit == "m" for n in moving)


def test_the_reference_declares_its_bearing_series_as_the_gearbox(lateral):
    result = simulate_monolithic(lateral, RotorSpeedProcess(WindParameters()), 0.01, output_interval_s=1e-3)
    assert sorted(result.names_of(BEARING_FORCE)) == sorted(f"{b}.F" for b in BEARINGS)
    f = result.series
    np.testing.assert_allclose(f["stage3.drive_bearing.F"], np.hypot(f["stage3.drive_bearing.F_x"],
                                                                     f["stage3.drive_bearing.F_y"]), rtol=1e-12)
