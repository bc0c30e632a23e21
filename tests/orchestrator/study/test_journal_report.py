"""The journal survives a torn write and a second writer; the table and plots are rebuilt from it."""

from __future__ import annotations

import json

import pytest

from orchestrator.inputs.study_file import load_study
from orchestrator.study.engine import PointTask, run_point
from orchestrator.study.journal import (
    Journal,
    JournalError,
    latest_by_key,
    read_journal,
)
from orchestrator.study.prepare import prepare_study
from orchestrator.study.report import read_table, write_outputs
from orchestrator.study.sweep import pending_points
from tests.helpers.studies import (
    SMALL_FAILURE,
    SMALL_HEAD,
    SMALL_STUDY,
    SMALL_TABLES,
    STAGE3_FORCE_N,
)


def test_torn_last_line_is_skipped_and_the_next_record_starts_a_new_line(tmp_path):
    path = tmp_path / "journal.jsonl"
    with Journal(path) as j:
        j.append({"key": "a", "status": "ok"})
    with open(path, "ab") as fh:  # a crash in the middle of a write
        fh.write(b'{"key": "b", "sta')
    assert [r["key"] for r in read_journal(path)] == ["a"]
    with Journal(path) as j:
        j.append({"key": "a", "status": "failed"})
    records = read_journal(path)
    assert [r["key"] for r in records] == ["a", "a"]
    assert latest_by_key(records)["a"]["status"] == "failed"


def test_a_second_writer_is_refused(tmp_path):
    path = tmp_path / "journal.jsonl"
    with Journal(path):
        with pytest.raises(JournalError, match=r"in use by another sweep"):
            Journal(path).__enter__()


def test_points_run_in_process_fill_the_table_and_the_rest_is_pending(write_study, tmp_path):
    prepared = prepare_study(load_study(write_study(SMALL_STUDY)))
    out = tmp_path / "out"
    with Journal(out / "journal.jsonl") as j:
        for i in (0, 3):  # one valid point, the invalid one
            p = prepared.points[i]
            record = run_point(prepared.payload, PointTask(prepared.keys[i], p.index, dict(p.parameters)))
            j.append({**record, "parameters": dict(p.parameters)})
    assert pending_points(prepared, read_journal(out / "journal.jsonl")) == [1, 2]
    assert pending_points(prepared, read_journal(out / "journal.jsonl"), retry_failed=True) == [1, 2, 3]
    files = write_outputs(prepared, out)
    rows = read_table(files["table"])
    assert [r["status"] for r in rows] == ["ok", "pending", "pending", "failed"]
    assert rows[3]["error"] == SMALL_FAILURE and rows[3]["gearbox.stage3.lambda"] == "-600000.0"
    assert float(rows[0]["gearbox.stage3.F_mesh:mean [N]"]) == pytest.approx(STAGE3_FORCE_N, rel=0.01)
    assert float(rows[0]["I_max_acc [rad/s2]"]) > 1e5
    summary = json.loads(files["summary"].read_text())
    assert summary["status"] == {"ok": 1, "failed": 1, "error": 0, "pending": 2}
    assert not any(k.startswith("plot:") for k in files)  # explicit points only: nothing to plot over


def test_heat_map_with_ok_failed_and_pending_cells(write_study, tmp_path):
    import matplotlib.image

    text = SMALL_HEAD + SMALL_TABLES + (
        '[[axes]]\nparameter = "gearbox.R1"\nvalues = [8.0, 9.0]\nlabel = "R1"\n'
        '[[axes]]\nparameter = "gearbox.stage3.lambda"\nvalues = [100.0, -600.0]\nlabel = "lambda_3"\n'
        'unit = "1/mm"\n'  # converted to 1/m, shown as written
        '[[plots]]\nmeasure = "I_max_acc"\nfile = "imax.png"\n')
    prepared = prepare_study(load_study(write_study(text)))
    assert prepared.study.shape == (1, 2, 2, 1)
    out = tmp_path / "out"
    with Journal(out / "journal.jsonl") as j:
        for i in (0, 1):
            p = prepared.points[i]
            j.append({**run_point(prepared.payload, PointTask(prepared.keys[i], p.index, dict(p.parameters))),
                      "parameters": dict(p.parameters)})
    files = write_outputs(prepared, out)
    rows = read_table(files["table"])
    assert [r["status"] for r in rows] == ["ok", "failed", "pending", "pending"]
    assert rows[1]["lambda_3 [1/mm]"] == "-600.0"
    image = matplotlib.image.imread(files["plot:imax"])
    assert image.shape[0] > 300 and image.shape[1] > 500


def test_keys_depend_on_values_engine_and_measures(write_study):
    a = prepare_study(load_study(write_study(SMALL_STUDY, "a.toml")))
    b = prepare_study(load_study(write_study(SMALL_STUDY.replace('"steps", ', ""), "b.toml")))
    assert len(set(a.keys)) == 4
    assert a.keys == prepare_study(load_study(write_study(SMALL_STUDY, "c.toml"))).keys  # deterministic
    assert not set(a.keys) & set(b.keys)  # other measures: other points
