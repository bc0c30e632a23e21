"""The check that project FMUs are current: hashed once per FMU file and installed sources, remembered across runs."""

from __future__ import annotations

import json
import os
import zipfile

import pytest

from fmus import build, registry
from fmus.slaves.record import RECORD_FILE
from orchestrator.provision import staleness


@pytest.fixture
def checks(tmp_path, monkeypatch):
    """A fresh user cache (the remembered verdicts), and a count of the hashes computed."""
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(staleness, "_checks", None)
    hashed = []
    real = staleness.code_hash
    monkeypatch.setattr(staleness, "code_hash", lambda *a, **k: hashed.append(a[0]) or real(*a, **k))
    return hashed


def _fmu(path, build_id: str | None = None):
    """A project-FMU-shaped archive of the Gearbox of preset table6, carrying ``build_id`` (default: the current one)."""
    model = registry.kind("Gearbox").model(registry.drivetrain_of_preset("table6"), None)
    build_id = build_id or build.code_hash("Gearbox", model)
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("resources/slavemodule.txt", f"_dtcosim_gearbox_{build_id}_slave")
        zf.writestr(f"resources/{RECORD_FILE}", json.dumps({"fmu": "Gearbox", "model": model}))
        zf.writestr("modelDescription.xml", "<fmiModelDescription/>")
    return path


def test_a_current_fmu_is_hashed_once_then_remembered_across_processes(checks, tmp_path, monkeypatch):
    fmu = _fmu(tmp_path / "Gearbox.fmu")
    assert staleness.stale_project_fmus({"gearbox": fmu}) == []
    assert staleness.stale_project_fmus({"gearbox": fmu}) == []
    assert checks == ["Gearbox"]
    monkeypatch.setattr(staleness, "_checks", None)  # a new process reads the verdicts from the user cache
    assert staleness.stale_project_fmus({"gearbox": fmu}) == [] and checks == ["Gearbox"]
    assert staleness.checks_path().is_file()


def test_a_stale_fmu_is_named_with_its_build_and_the_remedy(checks, tmp_path):
    fmu = _fmu(tmp_path / "Gearbox.fmu", "0123456789ab")
    (warning,) = staleness.stale_project_fmus({"gearbox": fmu})
    assert warning == (f"{fmu} (gearbox) was built from other code than the installed dtcosim (build 0123456789ab); "
                       f"rebuild it with `dtcosim build --out {tmp_path}`")
    assert staleness.stale_project_fmus({"gearbox": fmu}) == [warning] and checks == ["Gearbox"]


def test_a_replaced_fmu_file_is_checked_again(checks, tmp_path):
    fmu = _fmu(tmp_path / "Gearbox.fmu")
    assert staleness.stale_project_fmus({"gearbox": fmu}) == []
    replacement = _fmu(tmp_path / "new.fmu", "0123456789ab")
    os.replace(replacement, fmu)  # what a build into the folder does
    assert len(staleness.stale_project_fmus({"gearbox": fmu})) == 1 and checks == ["Gearbox", "Gearbox"]


def test_other_installed_sources_check_every_fmu_again(checks, tmp_path, monkeypatch):
    fmu = _fmu(tmp_path / "Gearbox.fmu")
    assert staleness.stale_project_fmus({"gearbox": fmu}) == []
    monkeypatch.setattr(staleness, "sources_stamp", lambda: "another stamp")
    assert staleness.stale_project_fmus({"gearbox": fmu}) == [] and checks == ["Gearbox", "Gearbox"]


@pytest.mark.parametrize("change", ["touch", "edit", "new module"])
def test_the_sources_stamp_follows_the_files(tmp_path, change):
    import shutil

    installed = build.SourceTree.installed()
    shutil.copytree(installed.components_dir, tmp_path / "components")
    shutil.copytree(installed.slaves_dir, tmp_path / "fmus" / "slaves")
    source = build.SourceTree.at(tmp_path)
    stamp = build.sources_stamp(source)
    assert build.sources_stamp(source) == stamp
    kernel = source.components_dir / "model" / "kernel" / "contact.py"
    if change == "touch":
        st = kernel.stat()
        os.utime(kernel, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    elif change == "edit":
        kernel.write_text(kernel.read_text() + "\n")
    else:
        (source.slaves_dir / "extra.py").write_text("")
    assert build.sources_stamp(source) != stamp


@pytest.mark.parametrize("name", registry.names_built_from(registry.PRESET))
def test_the_stamp_covers_every_file_the_build_id_reads(name):
    stamped = set(build.stamped_files())
    assert {path for _, path in build._embedded_files(name, build.SourceTree.installed())} <= stamped
    assert {build.binary.NATIVE_DIR / f for f in (*build.binary.SOURCES, build.binary.HEADER)} <= stamped


@pytest.mark.parametrize("managed", [True, False])
def test_a_stale_preset_fmu_is_rebuilt_in_the_projects_own_folder_and_kept_in_one_the_user_names(
        checks, fmu_dir, tmp_path, monkeypatch, managed):
    """After an upgrade the FMUs in the user cache were built by the older dtcosim: a run warned, then failed on
    the old record ("expected exactly the fields of Drivetrain: ..., gravity, ...") instead of rebuilding them."""
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario
    from orchestrator.provision import project_fmus

    scenario = load_scenario(find_scenario("paper-60s"))
    assert project_fmus._missing_preset_fmus(scenario, fmu_dir, managed) == []  # current: nothing to build
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "upgraded"))  # the verdicts of the upgraded code
    monkeypatch.setattr(staleness, "_checks", None)
    monkeypatch.setattr(staleness, "code_hash", lambda *a, **k: "0123456789ab")  # the installed code changed
    stale = project_fmus._missing_preset_fmus(scenario, fmu_dir, managed)
    assert stale == (["Gearbox", "GeneratorRotor", "WindSource"] if managed else [])
