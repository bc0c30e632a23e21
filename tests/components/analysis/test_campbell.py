"""Campbell diagram, `dtcosim modes`, analysis plots, and the monolithic solver's initial state."""

import csv
import json
import math

import numpy as np
import pytest

from components import units
from components.analysis.campbell import (
    LoadLaw,
    campbell_diagram,
    excitation_frequencies,
)
from components.analysis.equilibrium import OperatingPoint, static_equilibrium
from components.analysis.load_duration import load_duration_distribution
from components.analysis.modes import drivetrain_modes
from components.errors import ParameterError
from components.model.presets import table6_gearbox
from components.model.wind import ConstantSpeed
from components.reference.solver import simulate_monolithic
from orchestrator.commands.cli import main
from orchestrator.run.analysis_plots import plot_force_spectra, plot_load_duration


@pytest.fixture(scope="module")
def campbell():
    return campbell_diagram(table6_gearbox(), units.rpm(np.linspace(4.0, 20.0, 17)))


def test_excitation_lines_at_16_rpm():
    lines = excitation_frequencies(table6_gearbox(), units.rpm(16.0), rotor_orders=(1, 3), mesh_harmonics=(1, 2))
    assert float(lines["1P"][0]) == pytest.approx(16 / 60)
    assert float(lines["3P"][0]) == pytest.approx(0.8)
    assert float(lines["stage1 mesh"][0]) == pytest.approx(48.0)  # Z_ring 180 x carrier 16 rpm
    assert float(lines["stage2 mesh"][0]) == pytest.approx(140 * 160 / 60)  # Z_ring 140 x carrier 160 rpm
    assert float(lines["stage3 mesh"][0]) == pytest.approx(20 * 1280 / 60)  # Z_drive 20 x drive 1280 rpm
    assert float(lines["stage3 mesh x2"][0]) == pytest.approx(2 * 20 * 1280 / 60)


def test_quadratic_load_law():
    law = LoadLaw()
    w = units.rpm(np.array([4.0, 8.0, 16.0, 20.0]))
    assert law.torque_nm(w) == pytest.approx([25.4e3 / 16, 25.4e3 / 4, 25.4e3, 25.4e3])
    assert LoadLaw("constant").torque_nm(w) == pytest.approx(np.full(4, 25.4e3))
    with pytest.raises(ParameterError, match="load_law"):
        LoadLaw("cubic")


def test_campbell_modes_stiffen_with_load_and_3p_meets_the_generator_mode(campbell):
    f = campbell.undamped_frequency_hz
    assert f.shape == (17, 12)
    # gear modes stiffen with the load (k ~ F^(1/3)): from 4 to 16 rpm the torque x16, f x ~16^(1/6)
    assert f[12, 3] / f[0, 3] == pytest.approx(16 ** (1 / 6), rel=0.02)
    assert np.all(np.diff(f[12:, :], axis=0) == 0.0)  # rated torque above 16 rpm: frozen
    assert campbell.overdamped[:, 1:].all() and not campbell.overdamped[:, 0].any()
    under = [c for c in campbell.crossings() if not c["overdamped"]]
    assert len(under) == 1
    c = under[0]
    assert (c["mode"], c["excitation"]) == (1, "3P")
    assert c["rotor_speed_rpm"] == pytest.approx(60 * f[-1, 0] / 3, rel=1e-9)  # 3 x rotor frequency = f_1
    # the generator mode's |lambda| (its undamped frequency; the undamped system's mode gives 19.05 rpm)
    assert c["rotor_speed_rpm"] == pytest.approx(19.06, abs=0.01)


def test_campbell_rows_and_json(campbell):
    rows = campbell.rows()
    assert len(rows) == 17
    assert rows[0]["rotor_speed_rpm"] == pytest.approx(4.0)
    assert rows[-1]["stage3_mesh_hz"] == pytest.approx(20 * 80 * 20 / 60)
    d = json.loads(json.dumps(campbell.as_dict(), allow_nan=False))  # strict JSON: NaN -> null
    assert d["load_law"]["kind"] == "quadratic"
    with pytest.raises(ParameterError, match="increasing positive"):
        campbell_diagram(table6_gearbox(), [1.0, 0.5])


def test_dtcosim_modes_writes_table_and_files(tmp_path, capsys):
    out = tmp_path / "modes"
    code = main(["modes", "--out", str(out), "--speed-points", "9"])
    assert code == 0
    text = capsys.readouterr().out
    assert "generator 100%" in text and "planet stage1" in text and "mode 1 x 3P" in text
    for name in ("modes.csv", "modes.json", "modes.png", "campbell.csv", "campbell_crossings.csv", "campbell.png"):
        assert (out / name).stat().st_size > 100, name
    rows = list(csv.DictReader((out / "modes.csv").open()))
    assert len(rows) == 12
    assert rows[0]["overdamped"] == "False" and float(rows[0]["damped_frequency_hz"]) == pytest.approx(0.9102, abs=1e-3)
    assert len(list(csv.DictReader((out / "campbell.csv").open()))) == 9
    summary = json.loads((out / "modes.json").read_text())
    assert summary["operating_point"]["rotor_speed_rpm"] == pytest.approx(16.0)
    assert (out / "modes.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_dtcosim_modes_other_torque_and_bad_range(tmp_path, capsys):
    assert main(["modes", "--torque-nm", "10000", "--out", str(tmp_path), "--speed-points", "3", "--load-law", "constant",
                 "--shapes", "2"]) == 0
    assert "output torque 10000 N m" in capsys.readouterr().out
    assert main(["modes", "--speed-range", "10", "5", "--out", str(tmp_path)]) == 1
    assert "speed_range" in capsys.readouterr().err


def test_force_spectrum_and_ldd_plots(tmp_path):
    t = np.arange(0.0, 1.0, 1e-3)
    x = 3e5 + 1e3 * np.sin(2 * math.pi * 48.0 * t)
    p = plot_force_spectra(t, {"stage1.F_sp[1]": x}, tmp_path / "spectrum.png", {"stage1 mesh": 48.0})
    assert p.stat().st_size > 1000
    q = plot_load_duration([load_duration_distribution(t, x, 16, name="shaft1.torque")], tmp_path / "ldd.png")
    assert q.stat().st_size > 1000


# ------------------------------------------------------------------ monolithic solver: initial state
def test_start_from_static_equilibrium_stays_there():
    dt = table6_gearbox()
    eq = static_equilibrium(dt, dt.generator.counter_torque_nm)
    r = simulate_monolithic(dt, ConstantSpeed(units.rpm(16.0)), 0.5, 1e-2, initial_state=eq.state)
    f = r["stage1.F_sp[1]"]
    assert np.abs(f - eq.contact_force_n[0]).max() < 1e-6 * eq.contact_force_n[0]
    assert r["omega_gen"] == pytest.approx(np.full(f.size, 100 * units.rpm(16.0)), rel=1e-12)
    with pytest.raises(ParameterError, match="initial_state"):
        simulate_monolithic(dt, ConstantSpeed(1.0), 0.1, initial_state=np.zeros(3))


def test_end_time_not_a_multiple_of_the_output_interval():
    """The last sample is t_end itself, never a NaN sample beyond it."""
    r = simulate_monolithic(table6_gearbox(), ConstantSpeed(1.0), 0.1, output_interval_s=0.035)
    assert r.time_s == pytest.approx([0.0, 0.035, 0.07, 0.1])
    assert np.all(np.isfinite(r["stage3.F_mesh"]))


def test_modes_of_a_scenario_style_drivetrain():
    """A scenario supplies a drivetrain (its generator torque) and a rotor speed."""
    dt = table6_gearbox().with_generator(counter_torque_nm=12.7e3)
    op = OperatingPoint.of_drivetrain(dt, units.rpm(12.0))
    assert op.output_torque_nm == 12.7e3
    an = drivetrain_modes(dt, op)
    assert an.model.equilibrium.shaft_torque_nm[-1] == pytest.approx(12.7e3)
