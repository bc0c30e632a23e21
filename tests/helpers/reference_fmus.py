"""The Modelica Reference-FMUs in ``<repo>/../shared/reference-fmus/`` and readers of typed result files."""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
#: ``<repo>/../shared/reference-fmus`` (as CI lays it out); a worktree elsewhere may point
#: ``DTCOSIM_REFERENCE_FMUS`` at the folder
REFERENCE_FMUS = Path(os.environ.get("DTCOSIM_REFERENCE_FMUS", REPO.parent / "shared" / "reference-fmus"))
NAMES = ("BouncingBall", "Dahlquist", "Feedthrough", "Stair", "VanDerPol", "Resource")


def reference_fmu(name: str) -> Path:
    """Path of ``<name>.fmu``; skips the test when the shared folder is absent."""
    path = REFERENCE_FMUS / f"{name}.fmu"
    if not path.is_file():
        pytest.skip(f"the Modelica Reference-FMUs are not in {REFERENCE_FMUS} (CI has ../shared beside the clone)")
    return path


def published_result(name: str) -> dict[str, list[str]]:
    """The published ``<name>_out.csv``: column name -> the fields as written."""
    with open(REFERENCE_FMUS / f"{name}_out.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    return {h: [r[i] for r in rows[1:]] for i, h in enumerate(rows[0])}


def read_typed_timeseries(path: Path) -> tuple[dict[str, str], dict[str, list[str]]]:
    """A dtcosim ``timeseries.csv``: (column name -> header tag in brackets, column name -> fields as written)."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    tags, columns = {}, {}
    for i, header in enumerate(rows[0]):
        name, _, tag = header.partition(" [")
        tags[name] = tag.rstrip("]")
        columns[name] = [r[i] for r in rows[1:]]
    return tags, columns


def as_numbers(fields: list[str]) -> np.ndarray:
    return np.array([float(x) for x in fields])
