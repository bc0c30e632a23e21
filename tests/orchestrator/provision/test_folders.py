"""The FMU folder: created where it is chosen, or refused naming the setting that chose it."""

from __future__ import annotations

import pytest

from orchestrator.provision.folders import FmuFolderError, usable_fmu_dir


@pytest.fixture
def blocked(tmp_path, monkeypatch):
    """A file where a folder would have to be created; neither variable set."""
    monkeypatch.delenv("DTCOSIM_FMU_DIR", raising=False)
    monkeypatch.delenv("DTCOSIM_CACHE_DIR", raising=False)
    path = tmp_path / "a-file"
    path.write_text("not a folder")
    return path


def test_the_folder_is_created_where_it_is_chosen(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_FMU_DIR", str(tmp_path / "x" / "fmus"))
    assert usable_fmu_dir() == tmp_path / "x" / "fmus" and (tmp_path / "x" / "fmus").is_dir()
    assert usable_fmu_dir(tmp_path / "given") == tmp_path / "given" and (tmp_path / "given").is_dir()


@pytest.mark.parametrize("chosen_by", ["--fmu-dir", "DTCOSIM_FMU_DIR", "DTCOSIM_CACHE_DIR", "default"])
def test_a_folder_that_cannot_be_created_is_refused_naming_the_setting(blocked, monkeypatch, chosen_by):
    given = None
    if chosen_by == "--fmu-dir":
        given, value, folder = blocked, blocked, blocked
    elif chosen_by == "DTCOSIM_FMU_DIR":
        monkeypatch.setenv("DTCOSIM_FMU_DIR", str(blocked / "fmus"))
        value = folder = blocked / "fmus"
    elif chosen_by == "DTCOSIM_CACHE_DIR":
        monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(blocked))
        value, folder = blocked, blocked / "fmus"
    else:
        monkeypatch.setenv("XDG_CACHE_HOME", str(blocked))  # ~/.cache's place
        value = folder = blocked / "dtcosim" / "fmus"
    key = "the FMU folder" if chosen_by == "default" else chosen_by
    with pytest.raises(FmuFolderError, match=rf"invalid setting entry {key} = '{value}': expected a place for the "
                                             rf"FMU folder {folder}, which cannot be created \(.+\); --fmu-dir or "
                                             "DTCOSIM_FMU_DIR chooses another"):
        usable_fmu_dir(given)


def test_a_command_names_its_own_option(blocked):
    with pytest.raises(FmuFolderError, match=rf"invalid setting entry --out = '{blocked}': .+; --out or DTCOSIM_FMU_DIR"):
        usable_fmu_dir(blocked, "--out")


def test_a_file_in_its_place_is_named_as_such(blocked):
    with pytest.raises(FmuFolderError, match=r"cannot be created \(a file is there\)"):
        usable_fmu_dir(blocked)


def test_a_run_says_it_before_anything_is_built(blocked, tmp_path):
    from tests.helpers.scenarios import dtcosim

    proc = dtcosim("run", "--stop", "1", "--out", str(tmp_path / "out"), "--fmu-dir", str(blocked), cwd=tmp_path,
                   env={"DTCOSIM_CACHE_DIR": str(tmp_path / "cache")})
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert f"error: invalid setting entry --fmu-dir = '{blocked}'" in proc.stderr
    assert not (tmp_path / "cache").exists()  # no kernel compile started, nothing unpacked
