"""Fixtures of the study tests: study files, the project's FMUs."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture
def write_study(tmp_path):
    """``write_study(text, name="study.toml")`` -> path of a study file in a fresh directory."""

    def make(text: str, name: str = "study.toml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return make


@pytest.fixture(scope="session")
def study_fmu_dir(tmp_path_factory) -> Path:
    """The project's three FMUs built once into a session directory."""
    from fmus.build import build_all

    out = tmp_path_factory.mktemp("study-fmus")
    build_all(out)
    return out
