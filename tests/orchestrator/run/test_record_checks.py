"""A load record must fit its drivetrain (issue 29): the speed-ratio check and channel suggestions by meaning.

A record of another turbine (generator/rotor speed ratio 28.25, as HSShftV / RotSpeed) driven through
the 5-MW drivetrain (ratio 96) is refused before any run, naming both ratios, the file and the
channels; ``check_speed_ratio = false`` runs it anyway. A missing GenSpeed in a record that has
HSShftV is answered with HSShftV (the same quantity), not a look-alike name.
"""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.inputs.series_file import LoadRecordError
from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow


def _record(folder, ratio: float, generator_channel: str = "HSShftV"):
    """A 12 s CSV record: rotor speed 12 rpm (+ a slow wave), generator speed ``ratio`` x it, torques."""
    t = np.arange(0.0, 12.0001, 0.05)
    rotor = 12.0 + 0.2 * np.sin(0.5 * t)
    rows = [f"{a:g}, {b:.9g}, {ratio * b:.9g}, 40, 3800" for a, b in zip(t, rotor)]
    path = folder / "other-turbine.csv"
    path.write_text(f"Time [s], RotSpeed [rpm], {generator_channel} [rpm], GenTq [kN-m], RotTorq [kN-m]\n"
                    + "\n".join(rows) + "\n")
    return path


def _scenario(folder, extra: str = "", generator_channel: str = "GenSpeed"):
    text = find_scenario("openfast-dlc11").read_text()
    text = text.replace('record = "openfast-data/DLC1.1_0_NREL5MW_OC3_spar_0.outb"',
                        f'record = "other-turbine.csv"\n{extra}')
    text = text.replace('channel = "GenSpeed"          # for the comparison only',
                        f'channel = "{generator_channel}"')
    text = text.replace('name = "openfast-dlc11"', 'name = "other-turbine"')
    path = folder / "other-turbine.toml"
    path.write_text(text)
    return path


def test_a_record_of_another_drivetrain_is_refused_before_the_run(tmp_path, fmu_dir):
    _record(tmp_path, 28.25)
    scenario = _scenario(tmp_path, generator_channel="HSShftV")
    proc = dtcosim("run", str(scenario), "--check", "--fmu-dir", str(tmp_path / "fmus"), cwd=tmp_path, timeout=1200)
    assert proc.returncode != 0
    message = proc.stderr
    assert "components.loads.series" in message and "other-turbine.csv" in message
    assert "HSShftV / RotSpeed = 28.25" in message and "96" in message and "check_speed_ratio = false" in message
    assert "Traceback" not in message
    scenario = _scenario(tmp_path, "check_speed_ratio = false", generator_channel="HSShftV")
    proc = dtcosim("run", str(scenario), "--check", "--fmu-dir", str(tmp_path / "fmus"), cwd=tmp_path, timeout=1200)
    assert proc.returncode == 0, proc.stderr


def test_a_record_of_this_drivetrain_passes(tmp_path):
    _record(tmp_path, 96.0, "GenSpeed")
    spec = load_scenario(_scenario(tmp_path)).component("loads").series
    ratio = spec.model()["series"]["speed_ratio"]
    assert ratio["ratio"] == pytest.approx(96.0) and (ratio["generator"], ratio["rotor"]) == ("GenSpeed", "RotSpeed")


def test_a_missing_channel_is_answered_with_the_channel_of_the_same_quantity(tmp_path):
    _record(tmp_path, 96.0, "HSShftV")
    with pytest.raises(LoadRecordError, match=r"GenSpeed.*generator speed as HSShftV \(did you mean HSShftV\?\)"):
        load_scenario(_scenario(tmp_path))
