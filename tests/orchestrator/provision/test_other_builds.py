"""Two dtcosim versions sharing the per-user FMU folder set each other's FMUs aside instead of rebuilding them.

Seen on one machine with several checkouts: each run of one rebuilt the FMUs the other had just built (1-2 s,
and the files other hosts were pointed at changed every time).
"""

from __future__ import annotations

import shutil
import zipfile

import pytest

from orchestrator.provision import other_builds, staleness
from tests.orchestrator.provision.test_staleness import _fmu

OTHER = "0123456789ab"  # the build id another version's code gives


@pytest.fixture
def fresh_checks(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(staleness, "_checks", None)


def _build_of(path) -> str:
    with zipfile.ZipFile(path) as zf:
        return zf.read("resources/slavemodule.txt").decode().split("_")[-2]


def _as_the_other_version(monkeypatch, tmp_path):
    """From here on the installed code hashes to ``OTHER`` (its own remembered verdicts)."""
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "other-cache"))
    monkeypatch.setattr(staleness, "_checks", None)
    monkeypatch.setattr(staleness, "code_hash", lambda *a, **k: OTHER)


def test_going_back_and_forth_between_two_versions_builds_each_fmu_once(fresh_checks, tmp_path, monkeypatch):
    path = _fmu(tmp_path / "Gearbox.fmu")  # this version's build
    mine = _build_of(path)
    with monkeypatch.context() as other:
        _as_the_other_version(other, tmp_path)
        assert other_builds.swap_in(path) is False  # the other version has none kept: it builds its own
        assert not path.exists() and (tmp_path / ".other-builds" / "Gearbox" / f"{mine}.fmu").is_file()
        _fmu(path, OTHER)  # what its build writes
        assert other_builds.swap_in(path) is True  # current for it: nothing to do
    assert other_builds.swap_in(path) is True  # back: this version's build taken back, the other's set aside
    assert _build_of(path) == mine
    assert sorted(p.name for p in (tmp_path / ".other-builds" / "Gearbox").iterdir()) == [f"{OTHER}.fmu"]
    with monkeypatch.context() as other:
        _as_the_other_version(other, tmp_path)
        assert other_builds.swap_in(path) is True and _build_of(path) == OTHER


def test_only_the_last_builds_set_aside_are_kept(fresh_checks, tmp_path):
    path = tmp_path / "Gearbox.fmu"
    builds = [f"{i:012x}" for i in range(1, 6)]
    for build in builds:
        other_builds.set_aside(_fmu(path, build), build)
    kept = sorted(p.stem for p in (tmp_path / ".other-builds" / "Gearbox").glob("*.fmu"))
    assert len(kept) == other_builds.KEEP and kept == builds[-other_builds.KEEP:]


def test_a_broken_fmu_is_left_to_be_built_over_and_a_broken_one_set_aside_is_dropped(fresh_checks, tmp_path):
    path = tmp_path / "Gearbox.fmu"
    path.write_bytes(b"not a zip archive")
    assert other_builds.swap_in(path) is False and path.read_bytes() == b"not a zip archive"
    shelf = tmp_path / ".other-builds" / "Gearbox"
    shelf.mkdir(parents=True)
    (shelf / f"{OTHER}.fmu").write_bytes(b"truncated")
    path.unlink()
    assert other_builds.swap_in(path) is False and not (shelf / f"{OTHER}.fmu").exists()


def test_a_run_takes_this_versions_fmus_back_instead_of_building_them(fmu_dir, tmp_path, monkeypatch):
    """The default FMU folder holds another version's FMUs; this version's, set aside by it, are used unbuilt."""
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.provision import project_fmus

    folder = tmp_path / "fmus"
    for name in ("Gearbox", "GeneratorRotor", "WindSource"):
        shelf = folder / ".other-builds" / name
        shelf.mkdir(parents=True)
        shutil.copy(fmu_dir / f"{name}.fmu", shelf / f"{_build_of(fmu_dir / f'{name}.fmu')}.fmu")
    _fmu(folder / "Gearbox.fmu", OTHER)  # the other version's Gearbox in the folder
    monkeypatch.setenv("DTCOSIM_FMU_DIR", str(folder))
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(staleness, "_checks", None)
    monkeypatch.setattr(project_fmus, "ensure_compiled_kernels", lambda *a, **k: None)
    monkeypatch.setattr(project_fmus, "build_all", lambda *a, **k: pytest.fail(f"built {k.get('names')}"))
    paths = project_fmus.ensure_fmus(load_scenario(find_scenario("paper-60s")))
    for comp, name in (("gearbox", "Gearbox"), ("generator", "GeneratorRotor"), ("wind", "WindSource")):
        assert _build_of(paths[comp]) == _build_of(fmu_dir / f"{name}.fmu")
    assert [p.name for p in (folder / ".other-builds" / "Gearbox").iterdir()] == [f"{OTHER}.fmu"]
