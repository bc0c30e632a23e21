"""The settling time: five time constants of the slowest-decaying eigenvalue, checked by hand."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from components.analysis.eigen import state_space_modes
from components.analysis.equilibrium import OperatingPoint
from components.analysis.modes import drivetrain_modes
from components.analysis.settling import N_TIME_CONSTANTS, settling_time
from components.model.presets import table6_gearbox


def _analysis(mass, damping, stiffness, held=True):
    ss = state_space_modes(np.atleast_2d(mass), np.atleast_2d(damping), np.atleast_2d(stiffness))
    return SimpleNamespace(state_space=ss, rotor_held=held)


@pytest.mark.parametrize("f_hz, zeta", [(2.0, 0.044), (6.88, 0.042), (0.953, 0.30)])
def test_one_oscillator_settles_in_five_over_zeta_omega(f_hz, zeta):
    w = 2 * math.pi * f_hz
    s = settling_time(_analysis(1.0, 2 * zeta * w, w * w))
    assert s.time_s == pytest.approx(N_TIME_CONSTANTS / (zeta * w), rel=1e-9)
    assert s.frequency_hz == pytest.approx(f_hz, rel=1e-9) and s.damping_ratio == pytest.approx(zeta, rel=1e-9)
    assert s.oscillatory and s.rotor == "held"
    assert f"{s.time_s:.3g} s = 5 time constants of the {f_hz:.3g} Hz mode" in s.describe()


def test_the_slowest_decay_wins_not_the_lowest_frequency():
    # two uncoupled oscillators: 1 Hz at 30 % (sigma 1.88 1/s) and 5 Hz at 2 % (sigma 0.63 1/s)
    w1, w2 = 2 * math.pi, 10 * math.pi
    s = settling_time(_analysis(np.eye(2), np.diag([2 * 0.3 * w1, 2 * 0.02 * w2]), np.diag([w1 * w1, w2 * w2])))
    assert s.frequency_hz == pytest.approx(5.0) and s.time_s == pytest.approx(5.0 / (0.02 * w2))


def test_an_overdamped_root_sets_the_time_when_it_is_the_slowest():
    # x'' + 10 x' + x = 0: roots -0.101 and -9.899; the slow one sets the time
    s = settling_time(_analysis(1.0, 10.0, 1.0, held=False))
    slow = (10.0 - math.sqrt(96.0)) / 2.0
    assert not s.oscillatory and math.isnan(s.frequency_hz) and s.time_s == pytest.approx(5.0 / slow)
    assert s.rotor == "free" and s.as_dict()["frequency_hz"] is None


def test_an_undamped_drivetrain_has_no_settling_time():
    with pytest.raises(ValueError, match="every mode decays"):
        settling_time(_analysis(1.0, 0.0, 4.0))


def test_the_paper_drivetrain_settles_with_its_0_95_hz_mode():
    an = drivetrain_modes(table6_gearbox(), OperatingPoint.from_rpm(16.0, 25.4e3))
    s = settling_time(an)
    first = min(an.underdamped, key=lambda m: m.mode.damping_ratio * m.mode.undamped_frequency_hz)
    assert s.frequency_hz == pytest.approx(first.mode.undamped_frequency_hz, rel=1e-6)
    assert s.damping_ratio == pytest.approx(first.mode.damping_ratio, rel=1e-6)
    assert s.frequency_hz == pytest.approx(0.953, abs=5e-4) and s.time_s == pytest.approx(2.82, abs=0.01)


@pytest.mark.parametrize("rotor", [None, "rigid shaft", "main shaft"])
def test_the_settling_from_the_eigenvalues_alone_is_the_modal_analysis_one(rotor):
    from components.analysis.settling import drivetrain_settling
    from components.model.rotor import RotorParameters

    drivetrain, op = table6_gearbox(), OperatingPoint.from_rpm(16.0, 25.4e3)
    parameters = {None: None, "rigid shaft": RotorParameters(inertia_kgm2=3.8e7),
                  "main shaft": RotorParameters(inertia_kgm2=3.8e7, shaft_stiffness_nm_rad=8.7e8,
                                                shaft_damping_nms_rad=6.2e6, carrier_inertia_kgm2=2.0e3)}[rotor]
    full = settling_time(drivetrain_modes(drivetrain, op, rotor=parameters))
    alone = drivetrain_settling(drivetrain, op, rotor=parameters)
    assert alone.rotor == full.rotor == ("held" if rotor is None else "free")
    assert alone.time_s == pytest.approx(full.time_s, rel=1e-9)
    assert alone.frequency_hz == pytest.approx(full.frequency_hz, rel=1e-9, nan_ok=True)
    assert alone.damping_ratio == pytest.approx(full.damping_ratio, rel=1e-9)


def test_a_runs_settling_time_imports_no_scipy():
    import subprocess
    import sys

    code = ("import sys\nfrom components.analysis.settling import drivetrain_settling\n"
            "from components.analysis.equilibrium import OperatingPoint\n"
            "from components.model.presets import table6_gearbox\n"
            "drivetrain_settling(table6_gearbox(), OperatingPoint.from_rpm(16.0, 25.4e3))\n"
            "print(sorted(m for m in sys.modules if m.startswith('scipy')))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
