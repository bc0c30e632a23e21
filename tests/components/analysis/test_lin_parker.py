"""The lateral-torsional planetary model against the published natural frequencies of Lin and Parker (1999).

Published values: J. Lin and R. G. Parker, "Analytical characterization of the unique properties of
planetary gear free vibration", J. Vib. Acoust. 121(3), 316-321, 1999, Table 1 (also J. Lin's thesis,
Ohio State University, 2000, Table C.1), as quoted with their sources in the public repository
gfsReboucas/Drivetrain-python, tests/test_lin_parker_1999.py. Frequencies in Hz by mode family:
rotational (simple; the 0 Hz rigid-body rotation of sun and carrier is removed here), translational
(multiplicity 2) and planet (multiplicity N - 3). The system is the packaged drivetrain file
``lin-parker-1999`` (its comments convert the published data), analysed with the stage-1 input free.
"""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.equilibrium import OperatingPoint
from components.analysis.modes import drivetrain_modes
from orchestrator.commands.cli import main as dtcosim
from orchestrator.inputs.drivetrain_entries import with_entries
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

#: Lin and Parker (1999) Table 1 [Hz]: family -> frequencies (each listed once), by number of planets
PUBLISHED = {
    3: {"rotational": [1475.7, 1930.3, 2658.3, 7462.8, 11775.3],
        "translational": [743.2, 1102.4, 1896.0, 2276.4, 6986.3, 9647.9],
        "planet": []},
    4: {"rotational": [1536.6, 1970.6, 2625.7, 7773.6, 13071.1],
        "translational": [727.0, 1091.0, 1892.8, 2342.5, 7189.9, 10437.6],
        "planet": [1808.2, 5963.8, 6981.7]},
    5: {"rotational": [1567.4, 2006.1, 2614.8, 8065.4, 14253.1],
        "translational": [710.0, 1072.0, 1888.1, 2425.3, 7382.4, 11172.3],
        "planet": [1808.2, 5963.8, 6981.7]},
}
MULTIPLICITY = {"rotational": lambda n: 1, "translational": lambda n: 2, "planet": lambda n: n - 3}


def _modes(n_planets: int):
    spec = load_drivetrain_file(find_drivetrain("lin-parker-1999"))
    spec = with_entries(spec, {"stages[0].planets": n_planets})
    op = OperatingPoint.of_drivetrain(spec.drivetrain, spec.rotor_speed_rad_s)
    return drivetrain_modes(spec.drivetrain, op, free_input=True)


@pytest.mark.parametrize("n_planets", [3, 4, 5])
def test_natural_frequencies_and_mode_families_are_those_of_table_1(n_planets):
    analysis = _modes(n_planets)
    expected = sorted((f, family) for family, fs in PUBLISHED[n_planets].items()
                      for f in fs for _ in range(MULTIPLICITY[family](n_planets)))
    got = [(m.mode.undamped_frequency_hz, m.kind, m.multiplicity) for m in analysis.modes]
    assert len(got) == len(expected) == 3 * (3 + n_planets) - 1  # every degree of freedom but the rigid rotation
    for (f, kind, multiplicity), (f_pub, family) in zip(got, expected):
        assert f == pytest.approx(f_pub, rel=5e-3), (f, f_pub, family)
        assert kind == family and multiplicity == MULTIPLICITY[family](n_planets)
    worst = max(abs(f / f_pub - 1.0) for (f, _, _), (f_pub, _) in zip(got, expected))
    assert worst < 5e-4  # measured: 0.04 % (727.3 Hz against the published 727.0 Hz, 4 planets)


def test_a_held_carrier_removes_no_mode_and_stiffens_the_rotational_ones():
    """With the carrier held (a prescribed rotor speed) the rotational family loses its rigid rotation and changes;
    the translational and planet modes, which do not turn the carrier, stay."""
    spec = load_drivetrain_file(find_drivetrain("lin-parker-1999"))
    spec = with_entries(spec, {"stages[0].planets": 4})
    held = drivetrain_modes(spec.drivetrain, OperatingPoint.of_drivetrain(spec.drivetrain, spec.rotor_speed_rad_s))
    free = _modes(4)
    pick = lambda an, kind: sorted(m.mode.undamped_frequency_hz for m in an.modes if m.kind == kind)  # noqa: E731
    np.testing.assert_allclose(pick(held, "planet"), pick(free, "planet"), rtol=1e-9)
    assert len(held.modes) == len(free.modes)
    assert not np.allclose(pick(held, "rotational"), pick(free, "rotational"), rtol=1e-3)


def test_dtcosim_modes_prints_the_families(tmp_path, capsys):
    assert dtcosim(["modes", "--drivetrain", "lin-parker-1999", "--free-input", "--out", str(tmp_path),
                    "--speed-points", "2", "--shapes", "2"]) == 0, capsys.readouterr().err
    text = capsys.readouterr().out
    assert "input member free, no rotor" in text
    assert text.count("translational x2") == 12 and text.count("rotational ") == 5
    assert "743.16" in text and "11775" in text
