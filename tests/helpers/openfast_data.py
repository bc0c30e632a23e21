"""The OpenFAST outputs in ``<repo>/../shared/openfast-data/`` (or under ``$DTCOSIM_DATA``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.inputs.series_spec import data_roots


def openfast_file(name: str) -> Path:
    """Path of a file of the shared OpenFAST data; skips the test when the folder is absent."""
    for root in data_roots():
        path = root / "openfast-data" / name
        if path.is_file():
            return path
    pytest.skip(f"openfast-data/{name} is in no data root ({', '.join(map(str, data_roots()))}; CI has ../shared)")
