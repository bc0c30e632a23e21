"""Records in: OpenFAST binary and text (FAST v6, Latin-1), CSV; channel selection, SI units, every bad input.

Each bad input is an error when the scenario is loaded: before any FMU is built or instantiated
(the FMU directory stays empty).
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from orchestrator.errors import ScenarioError
from orchestrator.inputs.scenario_file import load_scenario
from orchestrator.inputs.series_file import LoadRecordError, read_load_record, si_conversion
from tests.helpers.openfast_data import openfast_file

SCENARIO = """
name = "series"
[simulation]
stop = {stop}
step = 0.01
[components.loads]
fmu = "TimeSeriesSource.fmu"
[components.loads.series]
record = "{record}"
{options}
[[components.loads.series.channels]]
channel = "{channel}"
output = "w"
"""


def scenario(tmp_path: Path, record: str, channel: str = "RotSpeed", stop: float = 1.0, options: str = "") -> Path:
    path = tmp_path / "series.toml"
    path.write_text(SCENARIO.format(record=record, channel=channel, stop=stop, options=options))
    return path


def csv_record(tmp_path: Path, text: str, name: str = "rec.csv") -> str:
    (tmp_path / name).write_text(text)
    return name


GOOD_CSV = "Time [s], RotSpeed [rpm], GenTq [kN-m]\n0, 12, 40\n0.5, 12.1, 41\n1.0, 12.2, 42\n"


def test_outb_read_with_openfast_io():
    rec = read_load_record(openfast_file("DLC1.1_0_NREL5MW_OC3_spar_0.outb"))
    assert rec.time_s[0] == 0.0 and rec.time_s[-1] == pytest.approx(10.0) and rec.time_s.size == 801
    assert rec.channel("RotSpeed")[0] == "rpm"
    assert len(rec.channels) == 276


def test_fast_v6_text_file_that_is_not_utf8():
    path = openfast_file("DLC2.3_1.out")
    with pytest.raises(UnicodeDecodeError):
        path.read_text(encoding="utf-8")
    rec = read_load_record(path)
    assert rec.time_s[0] == 30.0 and rec.time_s[-1] == 90.0
    unit, gen_tq = rec.channel("GenTq")
    assert unit == "kN-m"  # the Latin-1 'kN·m'
    assert si_conversion(unit, "GenTq", "x") == ("N.m", 1e3)
    assert gen_tq[0] == 24.2


@pytest.mark.parametrize("unit, si, factor", [
    ("rpm", "rad/s", math.pi / 30), ("(kN-m)", "N.m", 1e3), ("kN\u00b7m", "N.m", 1e3), ("N-m", "N.m", 1.0),
    ("deg", "rad", math.pi / 180), ("kW", "W", 1e3), ("m/s", "m/s", 1.0), ("[sec]", "s", 1.0),
])
def test_unit_conversion_by_unit(unit, si, factor):
    assert si_conversion(unit, "c", "f") == (si, pytest.approx(factor))


def test_csv_channels_are_converted_to_si(tmp_path):
    sc = load_scenario(scenario(tmp_path, csv_record(tmp_path, GOOD_CSV)))
    spec = sc.component("loads").series
    assert spec.samples[:, 0] == pytest.approx(np.array([12, 12.1, 12.2]) * math.pi / 30)
    assert spec.outputs[0]["unit"] == "rad/s" and spec.outputs[0]["quantity"] == "rotor_speed"


@pytest.mark.parametrize("text, channel, error, match", [
    (GOOD_CSV, "RotSped", LoadRecordError, r"channel = 'RotSped'.*did you mean RotSpeed"),
    ("Time [s], RotSpeed [furlongs]\n0, 1\n1, 2\n", "RotSpeed", LoadRecordError, r"RotSpeed\.unit = 'furlongs'.*known conversion"),
    ("Time [s], RotSpeed [rpm]\n0, 1\n0.5, nan\n1, 2\n", "RotSpeed", LoadRecordError, r"RotSpeed = 'NaN at t = 0\.5 s"),
    ("Time [s], RotSpeed [rpm]\n0, 1\n0.6, 2\n0.5, 3\n1, 4\n", "RotSpeed", LoadRecordError, r"strictly increasing \(monotonic\) time"),
    ("", "RotSpeed", LoadRecordError, r"the file is empty"),
    ("Time, RotSpeed\n0, 1\n", "RotSpeed", LoadRecordError, r"'name \[unit\]'"),
])
def test_bad_csv_records(tmp_path, text, channel, error, match):
    fmus = tmp_path / "fmus"
    with pytest.raises(error, match=match):
        load_scenario(scenario(tmp_path, csv_record(tmp_path, text), channel))
    assert not fmus.exists()


def test_record_shorter_than_the_run(tmp_path):
    path = scenario(tmp_path, csv_record(tmp_path, GOOD_CSV), stop=2.0)
    with pytest.raises(ScenarioError, match=r"record covering the run \[0, 2\] s .* shorter than the run"):
        load_scenario(path)
    held = load_scenario(scenario(tmp_path, csv_record(tmp_path, GOOD_CSV), stop=2.0, options='out_of_record = "hold"'))
    assert held.simulation.stop_s == 2.0
    with pytest.raises(ScenarioError, match="shorter than the run"):  # an override of the stop is checked too
        load_scenario(scenario(tmp_path, csv_record(tmp_path, GOOD_CSV))).with_simulation(stop_s=3.0)


def test_time_offset_moves_the_run_into_the_record(tmp_path):
    rec = csv_record(tmp_path, "Time [s], RotSpeed [rpm]\n30, 1\n31, 2\n32, 3\n")
    with pytest.raises(ScenarioError, match="shorter than the run"):
        load_scenario(scenario(tmp_path, rec))
    assert load_scenario(scenario(tmp_path, rec, options="time_offset = 30.0")).component("loads").series.time_offset_s == 30


def test_binary_files_of_the_wrong_kind(tmp_path):
    rng = np.random.default_rng(1)
    (tmp_path / "noise.outb").write_bytes(b"\x89PNG\r\n\x1a\n" + rng.bytes(4000))
    with pytest.raises(LoadRecordError, match=r"not a FAST binary file"):
        load_scenario(scenario(tmp_path, "noise.outb"))
    shutil.copy(openfast_file("DLC1.1_0_NREL5MW_OC3_spar_0.outb"), tmp_path / "renamed.out")
    with pytest.raises(LoadRecordError, match=r"OpenFAST text output \(\.out\); the file is binary"):
        load_scenario(scenario(tmp_path, "renamed.out"))
    data = openfast_file("DLC1.1_0_NREL5MW_OC3_spar_0.outb").read_bytes()
    (tmp_path / "cut.outb").write_bytes(data[:20000])
    with pytest.raises(LoadRecordError, match=r"truncated or another kind"):
        load_scenario(scenario(tmp_path, "cut.outb"))


def test_record_found_in_a_data_root(tmp_path, monkeypatch):
    root = tmp_path / "root"
    (root / "sub").mkdir(parents=True)
    (root / "sub" / "r.csv").write_text(GOOD_CSV)
    with pytest.raises(ScenarioError, match=r"record = 'sub/r\.csv'.*tried"):
        load_scenario(scenario(tmp_path, "sub/r.csv"))
    monkeypatch.setenv("DTCOSIM_DATA", os.pathsep.join(["/nonexistent", str(root)]))
    assert load_scenario(scenario(tmp_path, "sub/r.csv")).component("loads").series.record == (root / "sub" / "r.csv")


def test_a_record_above_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from orchestrator.inputs import series_file

    path = tmp_path / "big.csv"
    path.write_text("Time [s],GenSpeed [rpm]\n" + "".join(f"{i * 0.1:g},{1000 + i}\n" for i in range(100)))
    monkeypatch.setattr(series_file, "MAX_RECORD_BYTES", 512)
    with pytest.raises(LoadRecordError, match=r"a record of at most 512 bytes \(0\.000488 MiB\); the file has 904 bytes"):
        read_load_record(path)
