"""FMUs built on two processes (issue 34.3: a first run builds three FMUs while a second core idles).

The pool's own behaviour (tests/helpers/build_pool_cases.py, each case in a fresh Python): both processes
build, results in the order of the names, the first failure in that order raised, a killed or interrupted
child reported and waited for; then real FMUs built on two processes against one process.
"""

from __future__ import annotations

import json
import marshal
import os
import re
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import pytest

from fmus import build_pool
from fmus.build import build_all

ROOT = Path(__file__).resolve().parents[2]


def run_case(case: str, folder: Path, *args: str, **env: str) -> dict:
    lines = case_lines(case, folder, *args, **env)
    return lines[-1]


def case_lines(case: str, folder: Path, *args: str, **env: str) -> list[dict]:
    """Every JSON line a case printed (its result last)."""
    proc = subprocess.run([sys.executable, "-m", "tests.helpers.build_pool_cases", case, str(folder), *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=60, env={**os.environ, **env})
    assert proc.returncode == 0, proc.stderr
    return [json.loads(line) for line in proc.stdout.strip().splitlines()]


def test_two_processes_build_and_the_results_keep_the_names_order(tmp_path):
    out = run_case("both_processes", tmp_path)
    assert out["names"] == ["a", "b", "c", "d"]
    assert len(out["pids"]) == 2 and out["parent"] in out["pids"]


@pytest.mark.parametrize("case, env", [("one_process", {build_pool.WORKERS_ENV: "1"}), ("beside_a_thread", {})])
def test_one_process_when_asked_or_beside_another_thread(tmp_path, case, env):
    out = run_case(case, tmp_path, **env)
    assert out["pids"] == [out["parent"]]


def test_the_first_failure_in_the_names_order_is_raised_and_no_further_build_starts(tmp_path):
    out = run_case("first_failure_in_order", tmp_path)
    assert out["raised"] == "ValueError"
    assert out["message"].startswith("cannot build b ")


def test_an_exception_that_does_not_pickle_comes_back_as_its_text(tmp_path):
    out = run_case("unpicklable_failure_in_child", tmp_path)
    assert out["raised"] == "BuildPoolError"
    assert re.fullmatch(r"_Local: [ab] failed in the child", out["message"])  # whichever name the child took


def test_a_killed_child_is_an_error_naming_what_it_left_unbuilt(tmp_path):
    out = run_case("child_killed", tmp_path)
    assert out["raised"] == "BuildPoolError"
    assert "was killed by SIGKILL" in out["message"]
    left = sorted(set("abc") - set(out["built_here"]))
    assert left and out["message"].startswith(", ".join(n + ".fmu" for n in left) + " not built: ")


def test_an_interrupted_parent_stops_the_child_cleanly_and_waits_for_it(tmp_path):
    out = run_case("interrupted", tmp_path)
    assert out["cleaned"] and not out["unreaped_child"]
    assert out["seconds"] < 10  # not the child's 30 s build


@pytest.mark.parametrize("value, match", [("0", None), ("two", "DTCOSIM_BUILD_WORKERS='two': not a whole number")])
def test_the_number_of_processes_from_the_environment(monkeypatch, value, match):
    monkeypatch.setenv(build_pool.WORKERS_ENV, value)
    if match is None:
        assert build_pool.workers() == 1
    else:
        with pytest.raises(build_pool.BuildPoolError, match=match):
            build_pool.workers()


def _members(path: Path) -> dict[str, object]:
    """Every member but ``modelDescription.xml`` (its generationDateAndTime differs); a pyc as its header and code
    (marshal writes equal code with back-references that depend on reference counts)."""
    with zipfile.ZipFile(path) as archive:
        out = {}
        for name in archive.namelist():
            data = archive.read(name)
            if name.endswith(".pyc"):
                code = marshal.loads(data[16:])
                out[name] = (data[:16], code, code.co_filename)
            elif name != "modelDescription.xml":
                out[name] = data
        return out


def test_the_fmu_binary_compiles_in_a_process_of_its_own_beside_the_builds(tmp_path, monkeypatch):
    """A first build compiles the binary in another process from its start (beside
    :func:`fmus.build.prepare_builds`); no thread runs at the fork, and the builds wait for the binary where they
    need it."""
    from fmus import binary, build

    if binary.compiler() is None:
        pytest.skip("no C compiler")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    threads = threading.active_count()
    started, seen = [], []
    real_start = binary.start_compile
    monkeypatch.setattr(binary, "start_compile", lambda: started.append(real_start()) or started[-1])
    monkeypatch.setattr(binary, "_compile", lambda cc, target: seen.append("compiled here"))
    monkeypatch.setattr(build, "prepare_builds", lambda names, source=None: seen.append(
        ("prepare", started[0].process.pid, threading.active_count() - threads)))
    monkeypatch.setattr(build, "build_each", lambda one, names: seen.append(
        ("fork", threading.active_count() - threads)) or [binary.compiled_binary()])
    built = build.build_several(["GeneratorRotor", "WindSource"], tmp_path / "fmus")
    assert seen == [("prepare", started[0].process.pid, 0), ("fork", 0)]
    assert built[0].is_file() and started[0].process.returncode == 0  # compiled by it, waited for and reaped


def test_the_fmu_binary_is_compiled_once_when_both_processes_need_it(tmp_path):
    out = run_case("binary_compiled_once", tmp_path, DTCOSIM_CACHE_DIR=str(tmp_path / "cache"))
    assert len(out["compiles"]) == 1
    assert out["paths"][0] == out["paths"][1] and Path(out["paths"][0]).is_file()


@pytest.mark.slow
def test_fmus_built_on_two_processes_equal_those_built_on_one(tmp_path, monkeypatch):
    names = ["GeneratorRotor", "WindSource"]
    monkeypatch.setenv(build_pool.WORKERS_ENV, "1")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "c"))  # both without compiled kernels to carry
    one = build_all(tmp_path / "one", names=names)
    lines = case_lines("fmus_on_two_processes", tmp_path / "two", ",".join(names), DTCOSIM_CACHE_DIR=str(tmp_path / "c"),
                       **{build_pool.WORKERS_ENV: "2"})
    out = lines[-1]
    assert out["pool_runs"] == [2]  # built on two processes
    # each FMU unpacked for the run by the process that built it: one of them by the child
    unpacked = {name: (pid, folder) for name, pid, folder in (line["unpacked"] for line in lines[:-1])}
    assert sorted(unpacked) == sorted(names) and out["unpacked_now"] == [True, True]
    assert len({pid for pid, _ in unpacked.values()}) == 2 and out["parent"] in {p for p, _ in unpacked.values()}
    assert all(Path(folder).parent == tmp_path / "c" / "unpacked" for _, folder in unpacked.values())
    assert [[name, build_id] for name, _, build_id in out["built"]] == [[b.name, b.build_id] for b in one]
    for a, (name, path, _) in zip(one, out["built"]):
        assert Path(path) == tmp_path / "two" / f"{name}.fmu"
        assert _members(a.path) == _members(Path(path))
    assert not list((tmp_path / "two").glob(".*-building-*"))
