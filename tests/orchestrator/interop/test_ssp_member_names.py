"""A file inside an ``.ssp`` is named ``<file>.ssp!<member>`` in messages, never by its temporary extracted copy.

An FMU of an archive refused by the archive checks, the host checks or its slave module was named
``/tmp/dtcosim-ssp-.../resources/Feedthrough.fmu``: a file the user cannot find, gone when dtcosim exits.
"""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import pytest

from fmus.model_description import rewrite_archive
from orchestrator.commands import cli
from tests.helpers.ssp_documents import feedthrough, real, ssd, write_ssp, zip_folder

SYSTEM = f"""
  <ssd:System name="root">
    <ssd:Elements>{feedthrough("ft", real("Float64_continuous_input", "input"))}</ssd:Elements>
  </ssd:System>"""


def _outside(fmu: Path) -> None:
    rewrite_archive(fmu, {"/tmp/dtcosim-escaped.txt": b"x"})


def _windows_only(fmu: Path) -> None:
    with zipfile.ZipFile(fmu) as z:
        members = {n: z.read(n) for n in z.namelist() if not n.endswith("/")}
    fmu.unlink()
    with zipfile.ZipFile(fmu, "w") as z:
        for name, data in members.items():
            z.writestr(name.replace("linux64/Feedthrough.so", "win64/Feedthrough.dll"), data)


def _bad_slave_module(fmu: Path) -> None:
    """A PythonFMU archive (its generationTool says so) whose slavemodule.txt names no module."""
    with zipfile.ZipFile(fmu) as z:
        description = z.read("modelDescription.xml")
    rewrite_archive(fmu, {"modelDescription.xml": re.sub(rb'generationTool="[^"]*"', b'generationTool="PythonFMU 0.7"',
                                                         description),
                          "resources/slavemodule.txt": b""})


BROKEN = {
    "archive checks": (_outside, "would be extracted outside the FMU's folder"),
    "host checks": (_windows_only, "an FMU this host can load (no co-simulation binary for this platform"),
    "slave module": (_bad_slave_module, "names no slave module (its first line is empty): the FMU cannot create its "
                                        "slave"),
}


def _archive(tmp_path: Path, system: str = SYSTEM, change=None) -> Path:
    folder = write_ssp(tmp_path / "folder", ssd(system))
    if change is not None:
        change(folder / "resources" / "Feedthrough.fmu")
    return zip_folder(folder, tmp_path / "system.ssp")


@pytest.mark.parametrize("case", list(BROKEN))
def test_a_refused_fmu_of_an_ssp_is_named_as_a_member_of_the_archive(tmp_path, capsys, case):
    change, message = BROKEN[case]
    archive = _archive(tmp_path, change=change)
    for command in (["run", str(archive), "--check"], ["run", str(archive), "--out", str(tmp_path / "out"), "-q"]):
        assert cli.main(command) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0], err
        assert f"components.ft.fmu = '{archive}!resources/Feedthrough.fmu': expected " in err[0], err
        assert "dtcosim-ssp-" not in err[0]


def test_an_ssd_element_of_an_archive_is_named_as_a_member_with_its_line(tmp_path, capsys):
    archive = _archive(tmp_path, SYSTEM.replace("</ssd:Elements>", "</ssd:Elements><ssd:SignalDictionaries/>"))
    assert cli.main(["run", str(archive), "--check"]) == 1
    err = capsys.readouterr().err
    assert re.search(rf"^dtcosim run: error: {re.escape(str(archive))}!SystemStructure\.ssd, line \d+: "
                     r"<ssd:SignalDictionaries> is not supported", err), err


def test_the_summary_names_the_fmu_of_an_archive_as_its_member(tmp_path, capsys):
    archive = _archive(tmp_path)
    assert cli.main(["run", str(archive), "--out", str(tmp_path / "out"), "-q", "--no-plots"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["fmus"]["ft"]["file"] == f"{archive}!resources/Feedthrough.fmu"
