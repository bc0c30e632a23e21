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

_PACKAGES = ("dtcosim", "numpy", "scipy", "fmpy", "pythonfmu", "matplotlib")


def versions() -> dict[str, str]:
    """Versions of Python and of the packages a result depends on."""
    out = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def write_series_csv(path: str | Path, header: list[str], time_s: np.ndarray, values: np.ndarray,
                     types: list[str] | None = None, text: Mapping[int, np.ndarray] | None = None) -> Path:
    """CSV of ``time_s`` (N,) and ``values`` (N, M) under ``header`` (M + 1 fields), 17 significant digits.

    ``types`` (M FMI type names) formats the non-Real columns: Integer and Enumeration
    as integers, Boolean as 0/1, String (from ``text``: column index -> N strings)
    quoted with doubled inner quotes. Without it every column is Real.
    """
    path = Path(path)
    if types is not None and any(t != "Real" for t in types):
        return _write_typed_csv(path, header, time_s, values, types, dict(text or {}))
    table = np.column_stack([time_s, values]) if values.size else np.asarray(time_s)[:, None]
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(",".join(_csv_field(h) for h in header) + "\n")
        np.savetxt(fh, table, delimiter=",", fmt="%.17g")
    return path


def _write_typed_csv(path: Path, header: list[str], time_s: np.ndarray, values: np.ndarray, types: list[str],
                     text: dict[int, np.ndarray]) -> Path:
    def fmt(typ: str, j: int):
        if typ == "String":
            column = text[j]
            return lambda i: '"' + str(column[i]).replace('"', '""') + '"'
        column = values[:, j]
        if typ in ("Integer", "Enumeration", "Boolean"):
            return lambda i: "%d" % column[i]
        return lambda i: "%.17g" % column[i]

    formats = [fmt(t, j) for j, t in enumerate(types)]
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(",".join(_csv_field(h) for h in header) + "\n")
        for i, t in enumerate(time_s):
            fh.write(",".join(["%.17g" % t] + [f(i) for f in formats]) + "\n")
    return path


def _csv_field(text: str) -> str:
    return f'"{text}"' if "," in text or '"' in text else text


def read_timeseries(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Read a ``timeseries.csv``: (header fields, array of shape (n_samples, n_columns))."""
    import csv

    with open(path, encoding="utf-8") as fh:
        header = next(csv.reader(fh))
        data = np.loadtxt(fh, delimiter=",", ndmin=2)
    return header, data


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
    """Write ``summary.json`` (indented, NaN/inf as null)."""
    path = Path(path)
    path.write_text(json.dumps(jsonable(summary), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    return path
