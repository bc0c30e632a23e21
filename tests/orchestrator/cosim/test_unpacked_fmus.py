"""FMUs unpacked once per content into the user cache (orchestrator.cosim.unpacked_fmus)."""

from __future__ import annotations

import importlib.util
import os
import sys
import time
from pathlib import Path

import pytest

from orchestrator.cosim import unpacked_fmus
from orchestrator.cosim.unpacked_fmus import folder_name, is_unpacked, store, unpacked
from tests.helpers.holders import held_elsewhere

SHA = "ab" * 32


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache of the test's own; the folders the test's unpacking holds are let go at its end."""
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(unpacked_fmus, "_held", {})
    yield tmp_path / "cache"
    _let_go()


def _extractor(calls: list):
    def extract(path: Path, folder: Path) -> Path:
        calls.append(folder)
        (folder / "resources").mkdir(parents=True, exist_ok=True)
        (folder / "resources" / "member.txt").write_text(path.name)
        return folder
    return extract


def test_an_fmu_is_unpacked_once_and_then_loaded_as_it_is(cache, tmp_path):
    calls: list = []
    first = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    again = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    assert first == again == store() / folder_name(SHA) and first.parent == cache / "unpacked"
    assert len(calls) == 1 and calls[0] != first  # extracted beside it, renamed when whole
    assert (first / "resources" / "member.txt").read_text() == "A.fmu" and is_unpacked(SHA)
    assert [p.name for p in store().iterdir()] == [folder_name(SHA)]  # no partial folder left


def test_the_folder_is_named_by_content_and_interpreter():
    assert folder_name(SHA) == f"abababababababab-{sys.implementation.cache_tag}"


def test_modules_without_bytecode_for_this_interpreter_get_it_before_the_rename(cache, tmp_path):
    def sources_only(path, folder):
        (folder / "resources" / "pkg").mkdir(parents=True)
        (folder / "resources" / "pkg" / "slave.py").write_text("X = 1\n")
        (folder / "resources" / "broken.py").write_text("def (:\n")  # its import will say so, as before
        return folder

    folder = unpacked(tmp_path / "A.fmu", SHA, sources_only)
    pyc = Path(importlib.util.cache_from_source(str(folder / "resources" / "pkg" / "slave.py")))
    assert pyc.is_file() and pyc.read_bytes()[4:8] == (0b01).to_bytes(4, "little")  # PEP 552: unchecked hash
    assert not Path(importlib.util.cache_from_source(str(folder / "resources" / "broken.py"))).exists()


def test_a_failed_extraction_leaves_nothing_and_is_raised(cache, tmp_path):
    def broken(path, folder):
        (folder / "half").write_text("x")
        raise OSError(27, "File too large", str(folder / "half"))

    with pytest.raises(OSError, match="File too large"):
        unpacked(tmp_path / "A.fmu", SHA, broken)
    assert not is_unpacked(SHA) and list(store().iterdir()) == []


def test_a_copy_renamed_first_by_another_process_is_used(cache, tmp_path):
    def racing(path, folder):  # another process finishes the same FMU meanwhile
        theirs = _extractor([])(path, store() / folder_name(SHA))
        unpacked_fmus._write_manifest(theirs)
        return _extractor([])(path, folder)

    folder = unpacked(tmp_path / "A.fmu", SHA, racing)
    assert folder == store() / folder_name(SHA) and [p.name for p in store().iterdir()] == [folder_name(SHA)]


def test_an_unwritable_cache_unpacks_into_a_folder_of_the_process(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the cache would be")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(blocker))
    calls: list = []
    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    assert (folder / "resources" / "member.txt").is_file() and not str(folder).startswith(str(blocker))
    assert unpacked(tmp_path / "A.fmu", SHA, _extractor(calls)) == folder and len(calls) == 1


def _let_go():
    """This process stops holding the folders it unpacked (as if other processes had unpacked them and ended)."""
    for fd in unpacked_fmus._held.values():
        if fd is not None:
            os.close(fd)
    unpacked_fmus._held.clear()


needs_flock = pytest.mark.skipif(unpacked_fmus.fcntl is None, reason="no flock (Windows): the hour rule")


@needs_flock
def test_beyond_the_most_recently_used_every_folder_no_process_holds_is_removed(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(unpacked_fmus, "KEPT", 2)
    folders = []
    for k in range(3):
        folders.append(unpacked(tmp_path / "A.fmu", f"{k:02d}" * 32, _extractor([])))
        os.utime(folders[-1], (time.time() - 10 + k,) * 2)  # 00 least recently used; all within the hour
    assert len(list(store().iterdir())) == 3  # this process holds all three
    _let_go()
    with held_elsewhere(folders[0]):  # a run of another process still loads 00
        unpacked(tmp_path / "A.fmu", "03" * 32, _extractor([]))  # a new one prunes: 2 kept, 00 held
        assert sorted(p.name for p in store().iterdir()) == [folder_name(k * 32) for k in ("00", "02", "03")]
    _let_go()
    unpacked(tmp_path / "A.fmu", "04" * 32, _extractor([]))  # 00 no longer held
    assert sorted(p.name for p in store().iterdir()) == [folder_name(k * 32) for k in ("03", "04")]


@needs_flock
def test_a_folder_held_by_this_process_is_never_removed_however_many_follow(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(unpacked_fmus, "KEPT", 1)
    first = unpacked(tmp_path / "A.fmu", "00" * 32, _extractor([]))
    os.utime(first, (time.time() - 7200,) * 2)  # used two hours ago: a long run
    for k in (1, 2):
        unpacked(tmp_path / "A.fmu", f"{k:02d}" * 32, _extractor([]))
    assert first.is_dir() and (first / "resources" / "member.txt").is_file()


@needs_flock
def test_a_folder_being_removed_is_not_taken_but_unpacked_anew(cache, tmp_path, monkeypatch):
    calls: list = []
    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    _let_go()
    fd = unpacked_fmus._lock(folder, exclusive=True)  # another process's pruning has locked it
    try:
        again = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    finally:
        os.close(fd)
    assert again == folder and len(calls) == 2 and folder in unpacked_fmus._held


@needs_flock
def test_beyond_max_held_folders_are_used_unlocked_and_spared_by_this_process_only(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(unpacked_fmus, "KEPT", 1)
    monkeypatch.setattr(unpacked_fmus, "MAX_HELD", 1)
    first = unpacked(tmp_path / "A.fmu", "00" * 32, _extractor([]))
    second = unpacked(tmp_path / "A.fmu", "01" * 32, _extractor([]))
    assert unpacked_fmus._held[first] is not None and unpacked_fmus._held[second] is None  # one descriptor only
    os.utime(second, (time.time() - 10,) * 2)
    unpacked(tmp_path / "A.fmu", "02" * 32, _extractor([]))  # this process's pruning spares both
    assert first.is_dir() and second.is_dir()


def test_where_nothing_can_be_locked_a_folder_used_within_the_hour_is_kept(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(unpacked_fmus, "fcntl", None)  # Windows
    monkeypatch.setattr(unpacked_fmus, "KEPT", 1)
    old, recent = (unpacked(tmp_path / "A.fmu", f"{k:02d}" * 32, _extractor([])) for k in range(2))
    assert unpacked_fmus._held == {old: None, recent: None}  # used, nothing locked
    os.utime(old, (time.time() - 2 * unpacked_fmus.IN_USE_S,) * 2)
    os.utime(recent, (time.time() - 60,) * 2)
    unpacked_fmus._held.clear()  # as seen by another process
    unpacked(tmp_path / "A.fmu", "02" * 32, _extractor([]))
    assert not old.exists() and recent.is_dir()


def test_a_partial_folder_is_removed_once_abandoned_for_an_hour(cache, tmp_path):
    old = time.time() - 2 * unpacked_fmus.IN_USE_S
    store().mkdir(parents=True)
    abandoned, fresh = store() / f"{unpacked_fmus.PARTIAL_PREFIX}x", store() / f"{unpacked_fmus.PARTIAL_PREFIX}y"
    abandoned.mkdir()
    fresh.mkdir()  # another process is unpacking into it
    os.utime(abandoned, (old, old))
    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor([]))
    assert sorted(store().iterdir()) == sorted([folder, fresh])


@needs_flock
def test_in_use_says_whether_any_process_holds_the_folder(cache, tmp_path, monkeypatch):
    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor([]))
    assert unpacked_fmus.in_use(folder)
    _let_go()
    assert not unpacked_fmus.in_use(folder)
    with held_elsewhere(folder):
        assert unpacked_fmus.in_use(folder)


def test_the_member_check_is_not_repeated_for_content_unpacked_whole(cache, toy_dir, monkeypatch):
    from fmus import archive_checks
    from orchestrator.cosim import fmu_interface
    from orchestrator.cosim.fmi_runtime import _extract

    fmu = next(Path(toy_dir).glob("*.fmu"))
    checked = []
    real = archive_checks.corrupt_member
    monkeypatch.setattr(archive_checks, "corrupt_member", lambda p: checked.append(p) or real(p))
    monkeypatch.setattr(fmu_interface, "_CACHE", {})
    iface = fmu_interface.read_fmu_interface(fmu)
    assert checked == [fmu.resolve()] and not is_unpacked(iface.sha256)
    folder = _extract(iface)
    assert folder == store() / folder_name(iface.sha256) and (folder / "modelDescription.xml").is_file()
    monkeypatch.setattr(fmu_interface, "_CACHE", {})
    assert fmu_interface.read_fmu_interface(fmu).sha256 == iface.sha256 and checked == [fmu.resolve()]


def _snapshot(folder: Path) -> dict:
    return {p: (p.stat().st_size, p.stat().st_mtime_ns) for p in folder.rglob("*")}


@pytest.mark.slow
def test_loading_and_stepping_an_unpacked_fmu_writes_nothing_into_its_folder(cache, toy_dir, monkeypatch):
    from orchestrator.cosim import fmu_interface
    from orchestrator.cosim.fmi_runtime import FmuInstance, _extract

    monkeypatch.setattr(fmu_interface, "_CACHE", {})
    iface = fmu_interface.read_fmu_interface(Path(toy_dir) / "ToySine.fmu")
    before = _snapshot(_extract(iface))
    instance = FmuInstance("sine", iface)
    try:
        instance.instantiate(0.0, 1.0)
        instance.enter_initialization(0.0)
        instance.exit_initialization(0.0)
        instance.get_reals([next(iter(iface.outputs))], 0.0)
    finally:
        instance.close()
    assert _snapshot(_extract(iface)) == before  # no bytecode, no log: concurrent runs load it as it is


@pytest.mark.parametrize("damage", ["deleted", "truncated", "no manifest"])
def test_a_folder_changed_since_it_was_unpacked_is_set_aside_and_unpacked_anew(cache, tmp_path, damage):
    calls: list = []
    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    member = folder / "resources" / "member.txt"
    if damage == "deleted":
        member.unlink()
    elif damage == "truncated":
        member.write_text("")
    else:
        (folder / unpacked_fmus.MANIFEST).unlink()
    again = unpacked(tmp_path / "A.fmu", SHA, _extractor(calls))
    assert again == folder and len(calls) == 2 and member.read_text() == "A.fmu"
    aside = [p.name for p in store().iterdir() if p.name.startswith(unpacked_fmus.PARTIAL_PREFIX)]
    assert len(aside) == 1 and "-damaged-" in aside[0]  # removed by a later unpacking once unused for an hour
    assert unpacked(tmp_path / "A.fmu", SHA, _extractor(calls)) == folder and len(calls) == 2  # whole again


def test_the_manifest_lists_every_file_with_its_size(cache, tmp_path):
    import json

    folder = unpacked(tmp_path / "A.fmu", SHA, _extractor([]))
    assert json.loads((folder / unpacked_fmus.MANIFEST).read_text()) == {"resources/member.txt": len("A.fmu")}
