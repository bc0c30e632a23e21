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


def _read_record(path):
    from orchestrator.inputs.series_file import read_load_record

    read_load_record(path)


def _import_ssp(path):
    from orchestrator.interop.ssp import import_ssp

    import_ssp(path)


def _tuning(path):
    from orchestrator.commands.export_ssp import _measured_step

    _measured_step(path, "paper-60s", "gauss-seidel")


def _validate(path):
    from fmus.validation import check_fmu

    problems = check_fmu(path)
    raise ValueError("; ".join(problems))


@pytest.mark.parametrize("read, name, match", [
    (_read_record, "record.csv", r"expected a regular record file \(this is a device, pipe or folder\)"),
    (_import_ssp, "system.ssp", r"system.ssp: not a regular file \(a device, pipe or folder\)"),
    (_import_ssp, "system.ssd", r"system.ssd: no SystemStructure.ssd"),
    (_tuning, "tuning.json", r"--tuning = .*tuning.json': expected a JSON file of .*not a regular file"),
    (_validate, "Gearbox.fmu", r"^not a regular file \(a device, pipe or folder\)$"),
], ids=["record", "ssp", "ssd", "export-ssp-tuning", "validate"])
def test_every_file_a_user_names_is_read_only_when_regular(tmp_path, read, name, match):
    """A pipe named as any input would block the command until a writer came (issue 35.7)."""
    path = tmp_path / name
    os.mkfifo(path)
    with pytest.raises(Exception, match=match):
        read(path)


@pytest.mark.parametrize("command, kind", [("sweep", "study"), ("loads", "load-case set"),
                                           ("drivetrain show", "drivetrain"), ("run", "scenario")])
@pytest.mark.parametrize("make", ["pipe", "device", "folder"])
def test_a_device_pipe_or_folder_named_as_an_input_is_called_so(tmp_path, capsys, command, kind, make):
    """sweep, loads and drivetrain said "expected an existing study file" for /dev/zero, a pipe or a folder."""
    from orchestrator.commands import cli

    path = {"device": "/dev/zero", "pipe": str(tmp_path / "p.toml"), "folder": str(tmp_path / "d.toml")}[make]
    if make == "pipe":
        os.mkfifo(path)
    elif make == "folder":
        os.mkdir(path)
    extra = ["--check"] if command in ("sweep", "loads") else []
    assert cli.main([*command.split(), path, *extra]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"(file) = '{path}': expected a regular {kind} file (this is a device, pipe or " \
                             "folder)" in err[0], err
