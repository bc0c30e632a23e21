"""An FMU unpacked for its run by the process that built it (orchestrator.provision.unpack_ahead)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from orchestrator.cosim import fmu_interface
from orchestrator.cosim.fmi_runtime import _extract
from orchestrator.cosim.unpacked_fmus import folder_name, is_unpacked, store
from orchestrator.provision.unpack_ahead import unpack_ahead


def test_the_run_loads_the_folder_unpacked_ahead(tmp_path, toy_dir, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    fmu = next(Path(toy_dir).glob("*.fmu"))
    sha = fmu_interface.file_sha256(fmu)
    folder = unpack_ahead(fmu)
    assert folder == store() / folder_name(sha) and is_unpacked(sha) and (folder / "modelDescription.xml").is_file()
    monkeypatch.setattr(fmu_interface, "_CACHE", {})
    assert _extract(fmu_interface.read_fmu_interface(fmu)) == folder


def test_where_the_cache_cannot_take_it_nothing_is_unpacked_and_no_folder_is_left(tmp_path, toy_dir, monkeypatch):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the cache would be")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(blocker))
    before = set(Path(tempfile.gettempdir()).glob("dtcosim-fmus-*"))
    assert unpack_ahead(next(Path(toy_dir).glob("*.fmu"))) is None
    assert set(Path(tempfile.gettempdir()).glob("dtcosim-fmus-*")) == before  # no folder of this process's own


def test_a_damaged_archive_is_left_to_the_run_to_report(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    broken = tmp_path / "Broken.fmu"
    broken.write_bytes(b"PK\x03\x04 not a zip archive")
    assert unpack_ahead(broken) is None
    assert not list((tmp_path / "cache" / "unpacked").glob("*"))  # nothing under a folder's name, nothing partial
