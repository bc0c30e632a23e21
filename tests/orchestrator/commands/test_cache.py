"""``dtcosim cache``: the per-user cache (compiled kernels, FMU binaries, unpacked FMUs) listed, and only its stale
entries pruned."""

from __future__ import annotations

import hashlib
import os
import time

import pytest

from components.compile.aot import aot_directory, build_log, failure_file
from components.compile.numba_cache import source_hash, warm_mark
from fmus.binary import cached_binary
from orchestrator.commands.cli import main
from orchestrator.cosim import unpacked_fmus
from orchestrator.cosim.compiled_kernels import aot_kernels
from orchestrator.cosim.unpacked_fmus import MANIFEST, folder_name
from orchestrator.provision.folders import UNUSED_DAYS, USED_MARK, mark_used
from tests.helpers.holders import held_elsewhere


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache with each installed kernel's module and JIT folder (current) and entries of older code (stale); one
    unpacked FMU is held by another process while the test runs (a run loading it)."""
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(unpacked_fmus, "_held", {})
    numba = pytest.importorskip("numba")
    current = []
    for kernel in aot_kernels():
        module = kernel.file()
        module.parent.mkdir(parents=True, exist_ok=True)
        module.write_bytes(b"x" * 1000)
        jit = tmp_path / f"numba-{numba.__version__}" / source_hash(kernel.source)[:16]
        jit.mkdir(parents=True)
        (jit / "index.nbi").write_bytes(b"y" * 10)
        current += [module, jit]
    failed, warm = failure_file(aot_kernels()[0]), warm_mark(aot_kernels()[0].shared)  # as without a C compiler
    failed.write_text("RuntimeError: no C compiler\n")
    warm.parent.mkdir(parents=True)
    warm.write_text("kernel:...\n")
    current += [failed, warm]
    build_log().write_text("the log of the last build\n")
    (aot_directory() / ".building").write_text("123\n")  # a build's own bookkeeping: not an entry
    current.append(build_log())
    binary = cached_binary()
    if binary is not None:  # the FMU binary of these sources and this compiler
        binary.parent.mkdir(parents=True)
        binary.write_bytes(b"b" * 200)
        current.append(binary.parent)
    stale = [aot_directory() / "_dtcosim_compiled_kernel_0000000000000000_aot.cpython-311-x86_64-linux-gnu.so",
             tmp_path / "native" / "0000000000000000",  # the binary of older sources
             tmp_path / "aot" / "cpython-310-numpy1.26" / "_dtcosim_compiled_wind_0000000000000000_aot.so",
             tmp_path / f"numba-{numba.__version__}" / "0000000000000000",
             tmp_path / "numba-0.60.0" / source_hash(aot_kernels()[0].source)[:16]]
    older_warm = warm.with_name("_dtcosim_kernel_gearbox_0000000000000000.cpython-311")  # older sources' mark
    older_warm.write_text("kernel:...\n")
    monkeypatch.delenv("DTCOSIM_FMU_DIR", raising=False)
    built = tmp_path / "fmus" / "drivetrains" / "x-0123" / "Gearbox.fmu"  # an FMU of the FMU folder
    built.parent.mkdir(parents=True)
    built.write_bytes(b"an FMU")
    current.append(built.parent)  # built now (before the folders' marks: dated by its files)
    used = tmp_path / "fmus" / "series" / "record-4567"  # built long ago, used by a run yesterday
    (used / "TimeSeriesSource.fmu").parent.mkdir(parents=True)
    (used / "TimeSeriesSource.fmu").write_bytes(b"a record's FMU")
    mark_used(used)
    long_ago = time.time() - (UNUSED_DAYS + 1) * 86400
    os.utime(used / "TimeSeriesSource.fmu", (long_ago, long_ago))
    os.utime(used / USED_MARK, (long_ago + UNUSED_DAYS * 86400, long_ago + UNUSED_DAYS * 86400))
    current.append(used)
    for unused in (tmp_path / "fmus" / "drivetrains" / "x-89ab", tmp_path / "fmus" / "series" / "record-cdef"):
        (unused / "Gearbox.fmu").parent.mkdir(parents=True)  # a drivetrain file since edited, a record since changed
        (unused / "Gearbox.fmu").write_bytes(b"an older FMU")
        mark_used(unused)
        for path in (unused / "Gearbox.fmu", unused / USED_MARK):
            os.utime(path, (long_ago, long_ago))
    unpacked = tmp_path / "unpacked" / folder_name(hashlib.sha256(b"an FMU").hexdigest())
    (unpacked / "resources").mkdir(parents=True)
    (unpacked / "resources" / "x.py").write_bytes(b"u" * 100)
    current.append(unpacked)
    stale.append(tmp_path / "unpacked" / folder_name("0" * 64))  # an FMU run from elsewhere (or rebuilt since)
    running = tmp_path / "unpacked" / folder_name("1" * 64)  # one from elsewhere that a run is loading
    running.mkdir()
    (running / MANIFEST).write_text("{}")
    current.append(running)
    for path in stale:
        if path.suffix == ".so":
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(b"z" * 500)
        else:
            path.mkdir(parents=True)
            (path / "index.nbi").write_bytes(b"z")
    (stale[-1] / MANIFEST).write_text("{}")
    a_minute_ago = time.time() - 60
    os.utime(stale[-1], (a_minute_ago, a_minute_ago))  # used a minute ago, but no process holds it
    stale += [older_warm, tmp_path / "fmus" / "drivetrains" / "x-89ab", tmp_path / "fmus" / "series" / "record-cdef"]
    with held_elsewhere(running):
        yield tmp_path, current, stale


def test_the_listing_marks_what_the_installed_code_loads(cache, capsys):
    root, current, stale = cache
    assert main(["cache"]) == 0
    out = capsys.readouterr().out
    assert f"cache: {root}" in out
    for path in current:
        assert "current" in next(line for line in out.splitlines() if line.endswith(str(path.relative_to(root))))
    for path in stale:
        assert "stale" in next(line for line in out.splitlines() if line.endswith(str(path.relative_to(root))))
    assert f"{len(current) + len(stale)} entries" in out and f"stale: {len(stale)}," in out
    assert "`dtcosim cache --prune`" in out and ".building" not in out
    assert f"FMU folder {root / 'fmus'}: 0.0 MB (the FMUs runs build; of its drivetrain and load record folders, " \
           f"those no command used for {UNUSED_DAYS} days are stale)" in out
    assert all(p.exists() for p in current + stale)  # listing changes nothing


def test_prune_removes_only_the_stale_entries(cache, capsys):
    root, current, stale = cache
    assert main(["cache", "--prune"]) == 0
    assert f"pruned {len(stale)} stale entries" in capsys.readouterr().out
    assert all(p.exists() for p in current) and not any(p.exists() for p in stale)
    assert not (root / "aot" / "cpython-310-numpy1.26").exists() and not (root / "numba-0.60.0").exists()
    assert (root / "unpacked").is_dir()  # still holds the current one


def test_an_empty_cache_says_so(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "nothing"))
    assert main(["cache", "--prune"]) == 0
    assert "(empty)" in capsys.readouterr().out
