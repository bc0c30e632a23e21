"""A study's result files, regenerated from its journal: ``results.csv``, ``study.json``, plots.

``results.csv``
    One row per point of the study, in point order: ``index``, ``status``
    (``ok``, ``failed``, ``error`` or ``pending`` = not run yet), one column per
    varied parameter (``component.parameter``, in its declared unit, full precision), for axes
    written in another unit also ``label [unit]`` as written (e.g. ``lambda [1/mm]``), one column
    per measure (``name [unit]``), ``error`` (the message of a failed point),
    ``worker``, ``task_wall_time [s]`` and ``key``.
``study.json``
    The study (name, engine, base, axes, measures), the point counts by status,
    the code version and the last sweep's numbers (points run and skipped,
    workers, times).

Written atomically (temporary file + rename), so a reader never sees half a table.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any, Mapping

from ..atomic_files import write_text_atomic
from ..output_folders import STUDY_SUMMARY
from .journal import JOURNAL_FILE, latest_by_key, read_journal

TABLE_FILE = "results.csv"
SUMMARY_FILE = STUDY_SUMMARY
PENDING = "pending"


def point_records(prepared, records: list[dict] | None = None, out_dir: str | Path | None = None) -> list[dict | None]:
    """The latest journal record of every point of the study (None: not run yet).

    Parameters
    ----------
    prepared : PreparedStudy
    records : list of dict, optional
        Journal records; default: read from ``out_dir``.
    out_dir : path, optional
    """
    if records is None:
        records = read_journal(Path(out_dir) / JOURNAL_FILE)
    latest = latest_by_key(records)
    return [latest.get(k) for k in prepared.keys]


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""
    return str(value)


def table_text(prepared, recs: list[dict | None]) -> str:
    """The CSV table (see the module docstring) as text."""
    study = prepared.study
    params = study.varied_parameters
    display = [(a, a.parameters[0]) for a in study.axes if a.shown is not None]
    header = ["index", "status", *params, *(a.axis_label for a, _ in display), *(m.column for m in study.measures),
              "error", "worker", "task_wall_time [s]", "key"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for point, key, rec in zip(prepared.points, prepared.keys, recs):
        pv = point.parameters
        measures = (rec or {}).get("measures") or {}
        row = [point.index, rec["status"] if rec else PENDING]
        row += [_cell(pv.get(p)) for p in params]
        row += [_cell(a.display(pv[p])) if p in pv else "" for a, p in display]
        row += [_cell(measures.get(m.name)) for m in study.measures]
        row += [_cell((rec or {}).get("error")), _cell((rec or {}).get("worker")),
                _cell((rec or {}).get("task_wall_time_s")), key]
        w.writerow(row)
    return buf.getvalue()


def read_table(path: str | Path) -> list[dict[str, str]]:
    """Rows of a ``results.csv`` as dicts of text by column header."""
    with open(path, encoding="utf-8", newline="") as fh:
        return list(csv.DictReader(fh))


def status_counts(recs: list[dict | None]) -> dict[str, int]:
    """Number of points by status (``ok``, ``failed``, ``error``, ``pending``)."""
    out = {"ok": 0, "failed": 0, "error": 0, PENDING: 0}
    for rec in recs:
        status = rec["status"] if rec else PENDING
        out[status] = out.get(status, 0) + 1
    return out


def summary(prepared, recs: list[dict | None], report=None, files: Mapping[str, Path] | None = None) -> dict[str, Any]:
    """The ``study.json`` content."""
    study = prepared.study
    doc: dict[str, Any] = {
        "study": study.name,
        "description": study.description,
        "study_file": study.source,
        "engine": study.engine,
        "base": {"kind": study.base.kind, "name": study.base.name,
                 "path": str(study.base.path) if study.base.path else None,
                 "parameters": dict(study.base.parameters)},
        "points": len(prepared.points),
        "status": status_counts(recs),
        "axes": [{"label": a.label, "unit": a.unit, "parameters": list(a.parameters), "values": list(a.values),
                  "shown": list(a.shown) if a.shown is not None else None} for a in study.axes],
        "seeds": list(study.seeds),
        "measures": [{"name": m.name, "unit": m.unit, "description": m.description} for m in study.measures],
        "code_version": prepared.identity["code"],
        "fmus": {c: str(p) for c, p in prepared.fmu_paths.items()},
    }
    if report is not None:
        doc["last_sweep"] = {
            "submitted": report.submitted, "skipped": report.skipped, "ok": report.ok, "failed": report.failed,
            "errors": report.errors, "interrupted": report.interrupted, "workers": report.workers,
            "in_process": report.in_process, "compute_time_s": report.compute_time_s,
        }
    if files:
        doc["files"] = {k: Path(p).name for k, p in files.items()}
    return doc


def write_outputs(prepared, out_dir: str | Path, report=None, plots: bool = True) -> dict[str, Path]:
    """Regenerate ``results.csv``, the plots and ``study.json`` from the journal.

    Returns
    -------
    dict of str -> pathlib.Path
        Files by role: ``journal``, ``table``, ``plot:<stem>``, ``summary``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    recs = point_records(prepared, out_dir=out)
    files: dict[str, Path] = {"journal": out / JOURNAL_FILE}
    files["table"] = write_text_atomic(out / TABLE_FILE, table_text(prepared, recs))
    if plots:
        from .plots import plot_study

        for p in plot_study(prepared, recs, out):
            files[f"plot:{p.stem}"] = p
    files["summary"] = out / SUMMARY_FILE
    write_text_atomic(files["summary"], json.dumps(summary(prepared, recs, report, files), indent=2) + "\n")
    return files
