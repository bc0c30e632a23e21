"""Runs that write the binary results file: whole when complete, readable to the last block when killed or cut."""

from __future__ import annotations

import json
import subprocess
import time

import numpy as np
import pytest

from orchestrator.columnar_files import read_columnar
from orchestrator.result_files import find_timeseries, read_timeseries
from tests.helpers.scenarios import dtcosim
from tests.orchestrator.run import test_stops as stops

pytestmark = pytest.mark.slow


def wait_for_batches(proc: subprocess.Popen, partial, size: int = 60_000, timeout: float = 300.0) -> None:
    """Wait until the streamed Arrow file holds ``size`` bytes (a few blocks of 250 rows)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise AssertionError(f"the run ended early ({proc.returncode}): {proc.stderr.read()}")
        if partial.exists() and partial.stat().st_size > size:
            return
        time.sleep(0.05)
    raise AssertionError("the run did not reach its stepping loop")


def test_a_complete_parquet_run_holds_the_same_samples_as_the_csv_run(fmu_dir, tmp_path):
    runs = {}
    for fmt in ("csv", "parquet"):
        out = tmp_path / fmt
        proc = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--stop", "1", "--results", fmt, "-q",
                       cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        summary = json.loads((out / "summary.json").read_text())
        assert summary["results_format"] == fmt and summary["files"]["timeseries"] == f"timeseries.{fmt}"
        assert find_timeseries(out) == out / f"timeseries.{fmt}"
        runs[fmt] = read_timeseries(out / f"timeseries.{fmt}")
        assert "contact_forces.png" in summary["files"].values()  # plots and analyses from the same run
    assert runs["csv"][0] == runs["parquet"][0]  # the same header fields, units included
    np.testing.assert_array_equal(runs["csv"][1], runs["parquet"][1])  # and every sample, to the last bit
    assert sorted(p.name for p in (tmp_path / "parquet").iterdir() if "timeseries" in p.name) == ["timeseries.parquet"]


def test_after_sigkill_the_parquet_stream_reads_to_its_last_block(fmu_dir, tmp_path):
    out = tmp_path / "killed"
    proc = stops.start(fmu_dir, out, "--results", "parquet")
    partial = out / "timeseries.parquet.partial"
    wait_for_batches(proc, partial)
    proc.kill()
    proc.communicate(timeout=60)
    summary = stops.summary_of(out)
    assert summary["status"] == "running" and summary["files"] == {} and summary["results_format"] == "parquet"
    assert summary["files_incomplete"]["timeseries"]["file"] == "timeseries.parquet.partial"
    table = read_columnar(partial)
    n = table.data.shape[0]
    assert n > 250 and (n - 1) % 250 == 0  # row 0, then whole blocks of 250 steps
    np.testing.assert_allclose(table.data[:, 0], np.arange(n) * 1e-3, rtol=0, atol=1e-12)
    assert table.units[table.names.index("gearbox.stage1.F_sp[1]")] == "N" and np.isfinite(table.data).all()


def test_a_file_size_limit_keeps_the_parquet_stream_to_its_last_block_and_says_so(fmu_dir, tmp_path):
    out = tmp_path / "limited"
    out.mkdir()
    proc = stops.start(fmu_dir, out, "--stop", "10", "--results", "parquet",
                       preexec_fn=stops._file_size_limit(1_500_000))  # above the FMUs' largest file (1.1 MB)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 1, stderr
    summary = stops.summary_of(out)
    assert summary["status"] == "failed" and summary["stage"] == "writing", stderr[-2000:]
    kept = summary["files_incomplete"]["timeseries"]
    assert kept["file"] == "timeseries.parquet.partial" and "File too large" in kept["reason"]
    assert "timeseries.parquet.partial" in kept["reason"] and "Traceback" not in stderr
    table = read_columnar(out / "timeseries.parquet.partial")
    assert table.data.shape[0] == kept["rows"] > 250 and (kept["rows"] - 1) % 250 == 0
    assert summary["stopped_at"] == pytest.approx((kept["rows"] - 1) * 1e-3 + 0.25, abs=1e-9)
    assert not (out / "timeseries.parquet").exists() and "timeseries" not in summary["files"]
