"""Several records in one TimeSeriesSource (``records = [...]``): the table, the packed samples, the FMU's
``record`` parameter with declared bounds, and the errors before any run."""

from __future__ import annotations

import io
from pathlib import Path

import fmpy
import numpy as np
import pytest

from orchestrator.provision.series_fmus import ensure_series_fmu
from orchestrator.errors import ScenarioError
from orchestrator.inputs.scenario_file import load_scenario
from orchestrator.inputs.series_file import LoadRecordError

SCENARIO = """
name = "records"
[simulation]
start = 0.0
stop = {stop}
step = 0.01
[components.loads]
fmu = "TimeSeriesSource.fmu"
[components.loads.series]
{selection}
[[components.loads.series.channels]]
channel = "GenTq"
output = "torque"
interpolation = "linear"
"""

RECORDS = {"a.csv": "Time [s], GenTq [kN-m]\n0, 40\n0.5, 41\n1.0, 42\n",
           "b.csv": "Time [s], GenTq [kN-m]\n0, 30\n0.25, 35\n0.5, 31\n1.0, 33\n",
           "c.csv": "Time [s], GenTq [kN-m]\n0, 20\n0.5, 25\n1.0, 21\n"}


def write(tmp_path: Path, selection: str, stop: float = 1.0) -> Path:
    for name, text in RECORDS.items():
        (tmp_path / name).write_text(text)
    path = tmp_path / "records.toml"
    path.write_text(SCENARIO.format(selection=selection, stop=stop))
    return path


def test_records_are_packed_each_with_its_own_time_and_the_model_lists_them(tmp_path):
    spec = load_scenario(write(tmp_path, 'records = ["a.csv", "b.csv", "c.csv"]')).component("loads").series
    assert spec.selectable and [r.record.name for r in spec.records] == ["a.csv", "b.csv", "c.csv"]
    series = spec.model()["series"]
    assert [r["source"] for r in series["records"]] == ["a.csv", "b.csv", "c.csv"]
    assert [r["samples"] for r in series["records"]] == [3, 4, 3]
    with np.load(io.BytesIO(spec.npz_bytes())) as data:
        assert sorted(data.files) == ["samples_1", "samples_2", "samples_3", "time_s_1", "time_s_2", "time_s_3"]
        np.testing.assert_array_equal(data["time_s_2"], [0.0, 0.25, 0.5, 1.0])
        np.testing.assert_array_equal(data["samples_2"][:, 0], [30e3, 35e3, 31e3, 33e3])  # kN m -> N m


def test_a_single_record_keeps_its_model_and_key(tmp_path):
    one = load_scenario(write(tmp_path, 'record = "a.csv"')).component("loads").series
    listed = load_scenario(write(tmp_path, 'records = ["a.csv"]')).component("loads").series
    assert "records" not in one.model()["series"] and not one.selectable
    assert "records" in listed.model()["series"] and listed.key != one.key


@pytest.mark.parametrize("selection, match", [
    ('record = "a.csv"\nrecords = ["b.csv"]', "exactly one"),
    ("", "exactly one"),
    ("records = []", "records"),
    ('records = ["a.csv", "missing.csv"]', r"records\[1\].*a record file"),
])
def test_record_and_records_one_clear_error(tmp_path, selection, match):
    with pytest.raises(ScenarioError, match=match):
        load_scenario(write(tmp_path, selection))


def test_records_in_other_units_are_converted_and_another_quantity_is_refused(tmp_path):
    path = write(tmp_path, 'records = ["a.csv", "n.csv"]')
    (tmp_path / "n.csv").write_text("Time [s], GenTq [N-m]\n0, 40\n1.0, 42\n")
    np.testing.assert_array_equal(load_scenario(path).component("loads").series.records[1].samples[:, 0], [40, 42])
    (tmp_path / "n.csv").write_text("Time [s], GenTq [kN]\n0, 40\n1.0, 42\n")
    with pytest.raises(ScenarioError, match=r"records\[1\] = 'n\.csv'.*GenTq in kN = N \(first record: kN-m\)"):
        load_scenario(path)


def test_every_record_must_cover_the_run(tmp_path):
    (tmp_path / "short.csv").write_text("Time [s], GenTq [kN-m]\n0, 40\n0.5, 41\n")
    with pytest.raises(ScenarioError, match=r"series\.records = 'short\.csv \[0, 0\.5\] s.*covering the run"):
        load_scenario(write(tmp_path, 'records = ["a.csv", "short.csv"]'))


def test_a_missing_channel_in_a_later_record_names_that_record(tmp_path):
    path = write(tmp_path, 'records = ["a.csv", "x.csv"]')
    (tmp_path / "x.csv").write_text("Time [s], RotSpeed [rpm]\n0, 12\n1.0, 12\n")
    with pytest.raises(LoadRecordError, match="x.csv.*GenTq"):
        load_scenario(path)


@pytest.mark.slow
def test_the_fmu_plays_the_selected_record_and_declares_its_bounds(tmp_path, capfd):
    spec = load_scenario(write(tmp_path, 'records = ["a.csv", "b.csv", "c.csv"]')).component("loads").series
    fmu = ensure_series_fmu(spec, tmp_path / "fmus")
    record = next(v for v in fmpy.read_model_description(str(fmu)).modelVariables if v.name == "record")
    assert (record.type, record.start, record.min, record.max) == ("Integer", "1", "1", "3")
    for number, name in enumerate(RECORDS, start=1):
        rows = np.loadtxt(io.StringIO(RECORDS[name]), delimiter=",", skiprows=1)
        res = fmpy.simulate_fmu(str(fmu), stop_time=1.0, output_interval=0.25, start_values={"record": number},
                                output=["torque"])
        played = np.interp(res["time"], rows[:, 0], rows[:, 1] * 1e3)
        np.testing.assert_allclose(res["torque"], played, rtol=1e-12)
    with pytest.raises(Exception, match="ExitInitializationMode"):
        fmpy.simulate_fmu(str(fmu), stop_time=1.0, start_values={"record": 4}, output=["torque"])
    assert "invalid parameter record = 4: expected one of the 3 packed records" in capfd.readouterr().err
