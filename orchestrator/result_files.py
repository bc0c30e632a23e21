"""Result files of every kind of output: CSV series, JSON summaries, the versions a result depends on.

Used by runs (:mod:`orchestrator.run.results`), the reference cases and modal
reports (:mod:`orchestrator.reports`) and studies.
"""

from __future__ import annotations

import json
import math
import platform
from importlib import metadata
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .atomic_files import atomic_path, write_text_atomic

_PACKAGES = ("dtcosim", "numpy", "scipy", "fmpy", "pythonfmu", "matplotlib", "pillow")


def versions() -> dict[str, str]:
    """Versions of Python and of the packages a result depends on."""
    out = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def write_series_csv(path: str | Path, header: list[str], time_s: np.ndarray, values: np.ndarray) -> Path:
    """CSV of ``time_s`` (N,) and ``values`` (N, M) under ``header`` (M + 1 fields), 17 significant digits.

    Written by temporary file and rename: ``path`` is whole or not there.
    """
    path = Path(path)
    table = np.column_stack([time_s, values]) if values.size else np.asarray(time_s)[:, None]
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(",".join(_csv_field(h) for h in header) + "\n")
        np.savetxt(fh, table, delimiter=",", fmt="%.17g")
    return path


def _csv_field(text: str) -> str:
    return f'"{text}"' if "," in text or '"' in text else text


def read_timeseries(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a run's results file, CSV or binary: (header fields, array of shape (n_samples, n_columns)).

    The header fields are ``time [s]``, ``component.variable [unit]``, ... for either
    format. Reads ``timeseries.csv`` and ``timeseries.parquet``, and the files a
    killed run left: ``timeseries.csv.partial`` (a last line without its line end, a
    chunk cut by the kill, is not a sample and is left out) and
    ``timeseries.parquet.partial`` (an Arrow IPC stream, read up to its last whole
    batch). For the units and FMI types of a binary file column by column, and its
    String columns, use :func:`orchestrator.columnar_files.read_columnar`.
    """
    from .columnar_files import is_columnar, read_columnar

    if is_columnar(path):
        table = read_columnar(path)
        return table.header, table.data
    import csv
    import io

    text = Path(path).read_text(encoding="utf-8")
    if text and not text.endswith("\n"):
        text = text[:text.rfind("\n") + 1]
    fh = io.StringIO(text)
    header = next(csv.reader(fh))
    rest = fh.read()
    data = np.loadtxt(io.StringIO(rest), delimiter=",", ndmin=2) if rest.strip() else np.empty((0, len(header)))
    return header, data


def find_timeseries(folder: str | Path) -> Path:
    """The results file of a run in ``folder``: the one its ``summary.json`` lists, else
    ``timeseries.csv`` or ``timeseries.parquet`` (whole, then ``.partial``), whichever is there."""
    folder = Path(folder)
    try:
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        listed = (summary.get("files") or {}).get("timeseries") or \
            ((summary.get("files_incomplete") or {}).get("timeseries") or {}).get("file")
    except (OSError, ValueError, AttributeError):
        listed = None
    names = ([listed] if isinstance(listed, str) else []) + ["timeseries.csv", "timeseries.parquet",
                                                             "timeseries.csv.partial", "timeseries.parquet.partial"]
    for name in names:
        if (folder / name).is_file():
            return folder / name
    raise FileNotFoundError(f"{folder}: no results file (timeseries.csv or timeseries.parquet)")


def jsonable(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, (np.floating, np.integer)):
        return jsonable(value.item())
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def write_summary(path: str | Path, summary: Mapping[str, Any]) -> Path:
    """Write ``summary.json`` (indented, NaN/inf as null) by temporary file and rename."""
    return write_text_atomic(path, json.dumps(jsonable(summary), indent=2, allow_nan=False) + "\n")
