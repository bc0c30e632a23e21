"""Result writers and atomic files: whole or not there, cut back to the last chunk on a write error."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.atomic_files import atomic_path, write_text_atomic
from orchestrator.result_files import read_timeseries
from orchestrator.run.writers import Column, CsvWriter
from tests.helpers.failing_files import FillingDisk


def test_rows_stream_into_a_partial_file_that_becomes_whole_on_close(tmp_path):
    writer = CsvWriter(tmp_path / "timeseries.csv")
    writer.open([Column("a.x", "m"), Column("b.n", "", "Integer")])
    writer.append(np.array([0.0, 0.1]), np.array([[1.0 / 3.0, 2], [np.pi, 3]]))
    assert writer.partial_path.name == "timeseries.csv.partial" and not writer.path.exists()
    header, data = read_timeseries(writer.partial_path)  # readable while the run goes on
    assert header == ["time [s]", "a.x [m]", "b.n [-]"] and data.shape == (2, 3)
    writer.append(np.array([0.2]), np.array([[-1e300, 4]]))
    assert writer.close() == tmp_path / "timeseries.csv" and not writer.partial_path.exists()
    text = (tmp_path / "timeseries.csv").read_text()
    assert text.splitlines()[1:] == ["0,0.33333333333333331,2", "0.10000000000000001,3.1415926535897931,3",
                                     "0.20000000000000001,-1.0000000000000001e+300,4"]
    header, data = read_timeseries(tmp_path / "timeseries.csv")
    assert data[0, 1] == 1.0 / 3.0 and data[1, 1] == np.pi  # 17 significant digits: exact


def test_a_write_error_cuts_the_file_back_to_the_last_whole_chunk(tmp_path):
    writer = CsvWriter(tmp_path / "timeseries.csv")
    writer.open([Column("a.x", "m")])
    writer.append(np.arange(3) * 0.1, np.ones((3, 1)))
    writer._fh = FillingDisk(writer._fh, room=10)  # the next chunk fits only partly
    with pytest.raises(OSError, match="No space left on device") as info:
        writer.append(np.arange(3, 6) * 0.1, np.ones((3, 1)))
    assert info.value.filename == str(writer.partial_path)  # the error names the file
    writer.abandon()
    header, data = read_timeseries(writer.partial_path)
    assert data.shape == (3, 2) and writer.rows_written == 3  # the first chunk, whole; nothing of the second
    assert writer.partial_path.read_text().endswith("\n")


def test_a_line_cut_by_a_kill_is_not_read_as_a_sample(tmp_path):
    path = tmp_path / "timeseries.csv.partial"
    path.write_text("time [s],a.x [m]\n0,1\n0.1,2\n0.2,3.00")
    header, data = read_timeseries(path)
    assert data.tolist() == [[0.0, 1.0], [0.1, 2.0]]
    path.write_text("time [s],a.x [m]\n")
    assert read_timeseries(path)[1].shape == (0, 2)


def test_an_atomic_write_that_fails_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "summary.json"
    write_text_atomic(target, "old\n")
    with pytest.raises(RuntimeError, match="disk gone"):
        with atomic_path(target) as tmp:
            tmp.write_text("new, half written")
            raise RuntimeError("disk gone")
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]
    with atomic_path(tmp_path / "plot.png") as tmp:
        assert tmp.suffix == ".png" and tmp.parent == tmp_path  # same folder, same suffix (savefig picks PNG)
        tmp.write_bytes(b"png")
    assert (tmp_path / "plot.png").read_bytes() == b"png"
