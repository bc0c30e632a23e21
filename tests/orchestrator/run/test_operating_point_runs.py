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
