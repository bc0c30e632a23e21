"""The binary columnar results format: round trip, units as metadata, streamed, cut back, chosen by size."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.columnar_files import ARROW_END_OF_STREAM, read_columnar
from orchestrator.errors import ScenarioError
from orchestrator.inputs.results_format import AUTO_PARQUET_VALUES, concrete_format
from orchestrator.inputs.scenario_file import find_scenario, load_scenario, scenario_from_dict
from orchestrator.result_files import find_timeseries, read_timeseries
from orchestrator.run.parquet_writer import ParquetWriter
from orchestrator.run.results import results_writer
from orchestrator.run.writers import Column, CsvWriter
from tests.helpers.failing_files import FillingDisk

#: one column of every FMI 2.0 type, with and without units
COLUMNS = [Column("gearbox.F_sp[1]", "N"), Column("gearbox.omega_out", "rad/s"), Column("fail.mode", "", "Integer"),
           Column("gen.state", "", "Enumeration"), Column("gen.tripped", "", "Boolean"),
           Column("gen.message", "", "String")]


def chunk(k: int, n: int = 4):
    """Rows of chunk ``k``: reals that need 17 digits, integers, booleans and strings."""
    t = (k * n + np.arange(n)) * 1e-3
    values = np.column_stack([t / 3.0 * 1e5, np.pi * (1 + t), k * n + np.arange(n) - 7.0, np.full(n, 2.0),
                              (np.arange(n) % 2).astype(float), np.full(n, np.nan)])
    return t, values, {5: np.array([f'row {k * n + i}, "quoted"' for i in range(n)], dtype=object)}


def write_chunks(writer, count: int):
    writer.open(COLUMNS)
    for k in range(count):
        writer.append(*chunk(k))


def test_every_fmi_type_and_unit_round_trips_through_the_parquet_file(tmp_path):
    writer = ParquetWriter(tmp_path / "timeseries.parquet")
    write_chunks(writer, 3)
    assert writer.partial_path.name == "timeseries.parquet.partial" and not writer.path.exists()
    assert writer.close() == tmp_path / "timeseries.parquet" and not writer.partial_path.exists()
    table = read_columnar(tmp_path / "timeseries.parquet")
    assert table.names == ["time", *(c.name for c in COLUMNS)]
    assert table.units == ["s", "N", "rad/s", "", "", "", ""]
    assert table.fmi_types == ["Real", "Real", "Real", "Integer", "Enumeration", "Boolean", "String"]
    expected = np.vstack([np.column_stack([chunk(k)[0], chunk(k)[1]]) for k in range(3)])
    np.testing.assert_array_equal(table.data[:, :6], expected[:, :6])  # float64, integers, booleans exactly
    assert np.isnan(table.data[:, 6]).all() and table.text[6][5] == 'row 5, "quoted"'
    header, data = read_timeseries(tmp_path / "timeseries.parquet")  # the same header as timeseries.csv
    assert header == ["time [s]", "gearbox.F_sp[1] [N]", "gearbox.omega_out [rad/s]", "fail.mode [-]",
                      "gen.state [-]", "gen.tripped [Boolean 0/1]", "gen.message [String]"]
    assert header == [Column("time", "s").header] + [c.header for c in COLUMNS] and data.shape == (12, 7)


def test_pandas_reads_the_file_with_its_units_and_pyarrow_sees_them_per_field(tmp_path):
    pd = pytest.importorskip("pandas")
    import pyarrow.parquet as pq

    writer = ParquetWriter(tmp_path / "timeseries.parquet")
    write_chunks(writer, 2)
    path = writer.close()
    frame = pd.read_parquet(path)
    assert list(frame.columns) == ["time", *(c.name for c in COLUMNS)]
    assert frame.attrs["units"]["gearbox.F_sp[1]"] == "N" and frame.attrs["units"]["time"] == "s"
    assert frame.attrs["fmi_types"]["gen.tripped"] == "Boolean"
    assert str(frame["fail.mode"].dtype) == "int32" and frame["gen.tripped"].dtype == bool
    assert frame["gearbox.omega_out"].iloc[3] == np.pi * (1 + 3e-3)
    field = pq.read_schema(path).field("gearbox.omega_out")
    assert field.metadata == {b"unit": b"rad/s", b"fmi_type": b"Real"}


def test_the_partial_stream_reads_to_its_last_whole_batch_after_a_kill(tmp_path):
    writer = ParquetWriter(tmp_path / "timeseries.parquet")
    write_chunks(writer, 3)
    assert read_columnar(writer.partial_path).data.shape == (12, 7)  # readable while the run goes on
    writer.abandon()
    data = writer.partial_path.read_bytes()
    writer.partial_path.write_bytes(data[:-100])  # a kill in the middle of writing the third batch
    table = read_columnar(writer.partial_path)
    assert table.whole is False and table.data.shape == (8, 7)
    np.testing.assert_array_equal(table.data[:, 0], np.arange(8) * 1e-3)
    header, rows = read_timeseries(writer.partial_path)
    assert rows.shape == (8, 7) and header[1] == "gearbox.F_sp[1] [N]"


def test_a_write_error_cuts_the_stream_back_to_the_last_whole_batch(tmp_path):
    writer = ParquetWriter(tmp_path / "timeseries.parquet")
    write_chunks(writer, 2)
    size = writer.partial_path.stat().st_size
    writer._fh = FillingDisk(writer._fh, room=40)  # the next batch fits only partly
    with pytest.raises(OSError, match="No space left on device") as info:
        writer.append(*chunk(2))
    assert info.value.filename == str(writer.partial_path)
    writer.abandon()
    assert writer.partial_path.stat().st_size == size and writer.rows_written == 8
    table = read_columnar(writer.partial_path)
    assert table.data.shape == (8, 7) and table.whole is False  # two whole batches, no end-of-stream marker
    assert not writer.partial_path.read_bytes().endswith(ARROW_END_OF_STREAM)


@pytest.mark.parametrize("requested, samples, variables, expected", [
    ("csv", 10**7, 22, "csv"), ("parquet", 2, 1, "parquet"),
    ("auto", 12_001, 22, "csv"),  # the 60 s paper run at 5 ms
    ("auto", 60_001, 22, "csv"),  # ... at 1 ms
    ("auto", 120_001, 22, "parquet"),  # the 600 s run at 5 ms
    ("auto", AUTO_PARQUET_VALUES, 1, "csv"), ("auto", AUTO_PARQUET_VALUES + 1, 1, "parquet"),
])
def test_auto_writes_parquet_for_long_runs_only(requested, samples, variables, expected):
    assert concrete_format(requested, samples, variables) == expected


def test_the_scenario_and_the_size_choose_the_writer(tmp_path):
    scenario = load_scenario(find_scenario("paper-60s"))
    assert scenario.results_format == "auto"
    sim = scenario.simulation
    assert isinstance(results_writer("auto", tmp_path, sim, 22), CsvWriter)
    long = scenario.with_simulation(stop_s=3600.0).simulation  # 180 001 samples x 22: above the 2 million values
    writer = results_writer("auto", tmp_path, long, 22)
    assert isinstance(writer, ParquetWriter) and writer.format == "parquet"
    assert writer.path == tmp_path / "timeseries.parquet"
    assert results_writer("csv", tmp_path, long, 22).path == tmp_path / "timeseries.csv"


def _doc(fmt):
    return {"simulation": {"stop": 1.0, "step": 0.1}, "components": {"a": {"fmu": "A.fmu"}},
            "record": {"variables": ["a.y"], "format": fmt}}


def test_record_format_is_read_from_the_scenario_and_a_bad_one_is_named():
    assert scenario_from_dict(_doc("parquet"), name="s").results_format == "parquet"
    with pytest.raises(ScenarioError, match=r"record\.format.*'hdf5'.*'auto'.*'csv'.*'parquet'"):
        scenario_from_dict(_doc("hdf5"), name="s")


def test_find_timeseries_takes_the_file_the_summary_lists(tmp_path):
    (tmp_path / "timeseries.parquet").write_bytes(b"PAR1")
    assert find_timeseries(tmp_path) == tmp_path / "timeseries.parquet"
    (tmp_path / "timeseries.csv").write_text("time [s]\n")
    (tmp_path / "summary.json").write_text('{"files": {"timeseries": "timeseries.parquet"}}')
    assert find_timeseries(tmp_path) == tmp_path / "timeseries.parquet"
    with pytest.raises(FileNotFoundError, match="no results file"):
        find_timeseries(tmp_path / "nothing")
