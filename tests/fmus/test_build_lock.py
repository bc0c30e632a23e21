"""One build at a time per folder, and no temporary folder of a killed build left (issue 35.3: "under a lock").

Two ``dtcosim build`` into one folder both built every FMU and renamed over each other; a build killed with
SIGKILL left its ``.<Name>-building-*/`` folder (2-3 MB) in the FMU folder for good.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from fmus import build as fmu_build
from fmus.build_lock import build_lock
from fmus.validation import check_fmu

ROOT = Path(__file__).resolve().parents[2]

HOLD = """
import sys
sys.path.insert(0, {root!r})
from fmus.build_lock import build_lock
with build_lock({folder!r}, report=lambda text: print(text, flush=True)):
    print("held", flush=True)
    sys.stdin.readline()
print("released", flush=True)
"""


def _holder(folder: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", HOLD.format(root=str(ROOT), folder=str(folder))],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def test_a_second_process_waits_for_the_first_and_says_so(tmp_path):
    first = _holder(tmp_path)
    assert first.stdout.readline() == "held\n"
    second = _holder(tmp_path)
    try:
        # it tells why it waits before it blocks, and takes the lock only once the first has let it go
        assert second.stdout.readline() == f"waiting for another process building FMUs into {tmp_path} ...\n"
        first.stdin.write("\n")
        first.stdin.flush()
        assert first.stdout.readline() == "released\n"
        assert second.stdout.readline() == "held\n"
        second.stdin.write("\n")
        second.stdin.flush()
        assert second.stdout.readline() == "released\n"
    finally:
        for proc in (first, second):
            if proc.poll() is None:
                proc.kill()
            proc.wait(timeout=60)


def test_the_lock_is_reentrant_within_a_process(tmp_path):
    """Provisioning holds it while it decides and fmus.build takes it again for each FMU."""
    with build_lock(tmp_path), build_lock(tmp_path / "sub" / "..") as again:
        assert again.resolve() == tmp_path


def test_the_temporary_folders_of_killed_builds_are_removed_by_the_next_build(tmp_path):
    out = tmp_path / "fmus"
    for left in (".Gearbox-building-k1ll3d", ".WindSource-building-0ld"):
        (out / left).mkdir(parents=True)
        (out / left / "Gearbox.fmu").write_bytes(b"half an archive")
    (out / ".mine").mkdir()  # not a build's: kept, as every other file
    (out / "notes.txt").write_text("mine")
    built = fmu_build.build_fmu("WindSource", out)
    assert check_fmu(built.path) == []
    assert sorted(p.name for p in out.iterdir()) == [".mine", "WindSource.fmu", "notes.txt"]


def test_a_full_disk_during_a_build_names_the_fmu_and_leaves_nothing(tmp_path, monkeypatch, capsys):
    """``dtcosim build`` on a full disk said 'error: No space left on device' (pythonfmu's zip write names no file)."""
    import errno

    from orchestrator.commands import cli

    def half_an_archive(name, kind, model, origin, source, part_dir, resources, validate):
        (part_dir / f"{name}.fmu").write_bytes(b"PK\x03\x04 half")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(fmu_build, "_build_archive", half_an_archive)
    out = tmp_path / "fmus"
    assert cli.main(["build", "--out", str(out), "--fmu", "WindSource"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim build: error: {out / 'WindSource.fmu'} not built: No space left on device (the build "
                   f"writes into {out} and the temporary folder {tempfile.gettempdir()})"]
    assert list(out.iterdir()) == []
