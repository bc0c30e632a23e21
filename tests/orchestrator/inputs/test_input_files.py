"""Input files are bounded before they are parsed (issue 35.7/35.9): regular files only, a size limit,
nesting and integer size refused as invalid TOML, each a named error and never a hang or a traceback."""

from __future__ import annotations

import os

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.inputs.files import MAX_INPUT_BYTES
from orchestrator.inputs.scenario_file import load_scenario
from tests.helpers.scenarios import dtcosim


def _deep(path):
    path.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")


def _long_integer(path):
    path.write_text('name = "x"\n[simulation]\nstop = ' + "9" * 5000 + "\n")


def _fifo(path):
    os.mkfifo(path)  # reading it would block until a writer comes


def _huge(path):
    with open(path, "wb") as fh:  # sparse: the size without the bytes
        fh.truncate(MAX_INPUT_BYTES + 1)


@pytest.mark.parametrize("make, match", [
    (_deep, r"\(syntax\).*valid TOML nested less deeply"),
    (_long_integer, r"\(syntax\).*valid TOML with integers of at most \d+ digits"),
    (_fifo, r"\(file\).*a regular scenario file \(this is a device, pipe or folder\)"),
    (_huge, r"\(file\).*a scenario file of at most 16 MiB"),
])
def test_a_pathological_file_is_a_named_error(tmp_path, make, match):
    path = tmp_path / "bad.toml"
    make(path)
    with pytest.raises(ScenarioError, match=match):
        load_scenario(path)


def test_a_device_is_refused_by_the_command_without_a_traceback(tmp_path):
    res = dtcosim("run", "/dev/zero", "--check", cwd=tmp_path, timeout=60)
    assert res.returncode != 0 and "Traceback" not in res.stderr
    assert "a regular scenario file" in res.stderr
