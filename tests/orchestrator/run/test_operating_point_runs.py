"""Co-simulations start at their operating point (issue 29): constant inputs give constant forces from t = 0.

The paper's scenario (the Gearbox's inertia interface) and the GRC-like rated point (the motion
interface, a Gearbox built from a drivetrain file) with the rotor-speed fluctuation switched off:
every contact force stays within 1e-6 of its mean over the whole run, start included; with the
Gearbox's ``start_at_rest`` the load arrives as a step, as before.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from orchestrator.result_files import find_timeseries, read_timeseries
from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fmu_home(tmp_path_factory, fmu_dir):
    """An FMU directory with the suite's preset FMUs; the drivetrain file's FMUs get built into it."""
    home = tmp_path_factory.mktemp("operating-point-fmus")
    for name in ("WindSource", "Gearbox", "GeneratorRotor"):
        shutil.copy(fmu_dir / f"{name}.fmu", home / f"{name}.fmu")
    return home


def _forces(fmu_home, tmp_path, scenario, *extra):
    out = tmp_path / scenario
    proc = dtcosim("run", scenario, "--stop", "2", "--set", "wind.sigma=1e-9", *extra, "--out", str(out),
                   "--no-plots", "-q", cwd=tmp_path, env={"DTCOSIM_FMU_DIR": str(fmu_home)}, timeout=1200)
    assert proc.returncode == 0, proc.stderr
    names, data = read_timeseries(find_timeseries(out))
    columns = [i for i, name in enumerate(names) if ".F_" in name]
    assert columns
    return data[:, columns]


@pytest.mark.parametrize("scenario", ["paper-60s", "grc-rated"])
def test_constant_inputs_give_constant_forces_from_the_start(fmu_home, tmp_path, scenario):
    forces = _forces(fmu_home, tmp_path, scenario)
    mean = forces.mean(axis=0)
    assert np.all(np.abs(mean) > 1e3)
    assert np.abs(forces - mean).max() <= 1e-6 * np.abs(mean).max(), np.abs(forces - mean).max(axis=0)


def test_start_at_rest_brings_back_the_load_step(fmu_home, tmp_path):
    forces = _forces(fmu_home, tmp_path, "paper-60s", "--set", "gearbox.start_at_rest=true")
    assert np.all(forces[0] == 0.0) and np.ptp(forces[:, 0]) > 0.5 * abs(forces[-1, 0])


TORQUE_DRIVEN = """
name = "torque-driven-constant"
[simulation]
stop = 2.0
step = 1.0e-3
order = ["gearbox", "generator", "rotor"]  # the Gearbox takes the rotor's motion at t_k, as the packaged scenario
[components.rotor]
fmu = "{fmus}/Rotor.fmu"
[components.rotor.parameters]
inertia = 4.0e6
initial_speed = 1.6755160819145563      # 16 rpm
aero_torque = 2.54e6                    # ratio 100 x the generator's 25.4 kN m: in balance
{shaft}
[components.gearbox]
fmu = "{fmus}/Gearbox.fmu"
[components.generator]
fmu = "{fmus}/GeneratorRotor.fmu"
[[connections]]
from = "rotor.omega"
to = "gearbox.omega_rotor"
[[connections]]
from = "rotor.phi"
to = "gearbox.phi_rotor"
[[connections]]
from = "gearbox.torque_rotor"
to = "rotor.gearbox_torque"
[[connections]]
from = "generator.omega"
to = "gearbox.omega_gen"
[[connections]]
from = "generator.phi"
to = "gearbox.phi_gen"
[[connections]]
from = "generator.generator_torque"
to = "gearbox.counter_torque"
[[connections]]
from = "gearbox.shaft_torque"
to = "generator.shaft_torque"
[[initial]]
from = "gearbox.omega_out"
to = "generator.initial_speed"
[[bindings]]
from = "generator.inertia"
to = "gearbox.generator_inertia"
[record]
variables = ["gearbox.*.F_*", "rotor.omega", "rotor.shaft_torque"]
"""


@pytest.mark.parametrize("shaft", ["", "shaft_stiffness = 5.0e8\nshaft_damping = 1.0e6\ncarrier_inertia = 1.0e4"],
                         ids=["rigid rotor", "main shaft"])
def test_a_torque_driven_rotor_in_balance_gives_constant_forces_from_the_start(fmu_dir, tmp_path, capsys, shaft):
    """The third interface (issue 29.1): a Rotor FMU driven by a constant aerodynamic torque in balance with the
    generator's, the drivetrain free at both ends. The Gearbox starts at its static deflection and the main shaft
    at its static twist: nothing moves from t = 0."""
    from orchestrator.commands import cli

    scenario = tmp_path / "torque.toml"
    scenario.write_text(TORQUE_DRIVEN.format(fmus=fmu_dir, shaft=shaft))
    out = tmp_path / "out"
    assert cli.main(["run", str(scenario), "--no-build", "--no-plots", "-q", "--out", str(out)]) == 0
    assert "warning: FMU" not in capsys.readouterr().err
    names, data = read_timeseries(find_timeseries(out))
    forces = data[:, [i for i, name in enumerate(names) if ".F_" in name]]
    mean = forces.mean(axis=0)
    assert forces.shape[1] == 13 and np.all(np.abs(mean) > 1e3)
    assert np.abs(forces - mean).max() <= 1e-6 * np.abs(mean).max()
    speed = data[:, names.index(next(n for n in names if n.startswith("rotor.omega")))]
    assert np.ptp(speed) <= 1e-9 * speed[0]
    if shaft:
        twist = data[:, names.index(next(n for n in names if n.startswith("rotor.shaft_torque")))]
        assert twist == pytest.approx(2.54e6, rel=1e-6)
