"""FMU archives are read and extracted within bounds, and a broken one is one named error (issues 35.7, 35.9).

A damaged member (a zlib.error traceback from fmpy), a member named outside the FMU's folder (fmpy's "Exception:
Illegal path"), a member that declares 3 GiB (extracted until the temporary folder was full, also from inside an
.ssp), a member that expands 1000 times, a pipe named as an FMU: each is refused by ``run --check``, ``run`` and
``validate`` with one line, before anything is decompressed where the archive's directory tells.
"""

from __future__ import annotations

import os
import shutil
import struct
import zipfile
from pathlib import Path

import pytest

from fmus import archive_checks
from fmus.archive_checks import FmuArchiveError, corrupt_member, extract_fmu, layout_problems
from fmus.validation import check_fmu
from orchestrator.commands import cli
from tests.helpers.scenarios import TOY_SCENARIO


def _copy(src: Path, dest: Path, compression=zipfile.ZIP_DEFLATED, extra: dict[str, bytes] | None = None) -> Path:
    """``src`` repacked (deflated) with the ``extra`` members added."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dest, "w", compression) as zout:
        for info in zin.infolist():
            zout.writestr(info.filename, zin.read(info.filename))
        for name, data in (extra or {}).items():
            zout.writestr(name, data)
    return dest


def damaged(src: Path, dest: Path) -> Path:
    """A copy whose compressed binary has 200 flipped bytes (its zip directory intact)."""
    _copy(src, dest)
    with zipfile.ZipFile(dest) as z:
        info = z.getinfo("binaries/linux64/ToySine.so")
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra) + 200
    data = bytearray(dest.read_bytes())
    data[start:start + 200] = bytes(b ^ 0x5A for b in data[start:start + 200])
    dest.write_bytes(bytes(data))
    return dest


def declaring(src: Path, dest: Path, size: int) -> Path:
    """A copy with a small member ``resources/big.bin`` whose zip directory declares ``size`` bytes."""
    _copy(src, dest, zipfile.ZIP_STORED, {"resources/big.bin": b"0123456789"})
    data = bytearray(dest.read_bytes())
    central = data.rindex(b"PK\x01\x02")  # the last directory entry: the member added last
    assert data[central + 46:central + 46 + 17] == b"resources/big.bin"
    data[central + 24:central + 28] = struct.pack("<I", size)  # uncompressed size in the central directory
    dest.write_bytes(bytes(data))
    return dest


@pytest.fixture
def sine(toy_dir, tmp_path):
    return toy_dir / "ToySine.fmu"


def _scenario_with(tmp_path: Path, toy_dir: Path, fmu: Path) -> Path:
    for name in ("ToyIntegrator.fmu", "ToyFailer.fmu"):
        shutil.copy(toy_dir / name, tmp_path / name)
    path = tmp_path / "scenario.toml"
    path.write_text(TOY_SCENARIO.replace('fmu = "ToySine.fmu"', f'fmu = "{fmu.name}"'))
    return path


BROKEN = {
    # zlib's word for the damage depends on where it lands: "Error -3 while decompressing data: ..."
    "damaged": (damaged, "archive member 'binaries/linux64/ToySine.so' is damaged ("),
    "absolute": (lambda s, d: _copy(s, d, extra={"/tmp/dtcosim-escaped.txt": b"x"}),
                 "archive member '/tmp/dtcosim-escaped.txt' would be extracted outside the FMU's folder"),
    "backslash": (lambda s, d: _copy(s, d, extra={"..\\escaped.txt": b"x"}),
                  "archive member '..\\\\escaped.txt' would be extracted outside the FMU's folder"),
    "dot-dot": (lambda s, d: _copy(s, d, extra={"resources/../../escaped.txt": b"x"}),
                "archive member 'resources/../../escaped.txt' would be extracted outside the FMU's folder"),
    "3 GiB member": (lambda s, d: declaring(s, d, 3 << 30), "expands to 3073 MiB, expected at most 1024 MiB"),
    "expands 1000 x": (lambda s, d: _copy(s, d, extra={"resources/zeros.bin": bytes(4 << 20)}),
                       "archive member 'resources/zeros.bin' expands"),
}


@pytest.mark.parametrize("case", list(BROKEN))
def test_a_broken_or_unsafe_fmu_is_one_named_error_in_check_run_and_validate(toy_dir, tmp_path, capsys, sine, case):
    make, message = BROKEN[case]
    fmu = make(sine, tmp_path / "Broken.fmu")
    scenario = _scenario_with(tmp_path, toy_dir, fmu)
    for extra in (["--check"], ["--out", str(tmp_path / "out"), "-q"]):
        assert cli.main(["run", str(scenario), "--no-build", *extra]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0], err
        assert err[0].startswith("dtcosim run: error: invalid scenario entry components.src.fmu")
    assert not (tmp_path / "out").exists()  # refused before the output folder is prepared
    problems = check_fmu(fmu)
    assert len(problems) == 1 and message in problems[0], problems
    assert not Path("/tmp/dtcosim-escaped.txt").exists()


# pythonfmu's binary takes the first line of resources/slavemodule.txt as the module to import: with an empty
# line or bytes that are not UTF-8 a run died with a segmentation fault (exit 139) after --check and validate
# had passed the FMU, as with a module it does not carry (issue 35.1)
SLAVE_MODULE_LINES = {
    "empty": (b"", "resources/slavemodule.txt names no slave module (its first line is empty)"),
    "not UTF-8": (b"caf\xe9\n", "resources/slavemodule.txt is not UTF-8 text (b'caf\\xe9')"),
    "a space": (b"toysine_slave \n", "resources/slavemodule.txt names 'toysine_slave ', which is not a Python module"),
    "carriage return": (b"toysine_slave\r\n", "names 'toysine_slave\\r', which is not a Python module name"),
}


@pytest.mark.parametrize("case", list(SLAVE_MODULE_LINES))
def test_a_slave_module_line_pythonfmu_cannot_import_is_refused_before_loading(toy_dir, tmp_path, capsys, sine,
                                                                               case):
    from fmus.model_description import rewrite_archive

    line, message = SLAVE_MODULE_LINES[case]
    fmu = tmp_path / "Broken.fmu"
    shutil.copy(sine, fmu)
    rewrite_archive(fmu, {"resources/slavemodule.txt": line})
    scenario = _scenario_with(tmp_path, toy_dir, fmu)
    for extra in (["--check"], ["--out", str(tmp_path / "out"), "-q"]):
        assert cli.main(["run", str(scenario), "--no-build", *extra]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0] and "the FMU cannot create its slave" in err[0], err
    problems = [p for p in check_fmu(fmu) if "InitialUnknowns" not in p]  # fmpy's complaint about every toy
    assert len(problems) == 1 and message in problems[0], problems


def test_a_slave_module_on_a_later_line_is_read_as_pythonfmu_reads_it(tmp_path, sine):
    from fmus.model_description import rewrite_archive

    fmu = tmp_path / "Two-lines.fmu"
    shutil.copy(sine, fmu)
    rewrite_archive(fmu, {"resources/slavemodule.txt": b"toysine_slave\nanything\n"})
    assert check_fmu(fmu) == check_fmu(sine)  # fmpy's complaint about the toy's InitialUnknowns, nothing more


@pytest.mark.parametrize("case", ["damaged", "absolute", "3 GiB member"])
def test_the_extraction_itself_refuses_what_the_checks_refuse(toy_dir, tmp_path, sine, case):
    """fmi_runtime extracts through extract_fmu, never fmpy's unbounded extractall."""
    from orchestrator.cosim import fmi_runtime
    from orchestrator.cosim.fmu_interface import read_fmu_interface
    from orchestrator.errors import InitializationError

    make, message = BROKEN[case]
    fmu = make(sine, tmp_path / "Broken.fmu")
    with pytest.raises(FmuArchiveError, match=message.replace("(", r"\(").replace("\\\\", "\\\\\\\\")):
        extract_fmu(fmu, tmp_path / "x")
    iface = read_fmu_interface(sine)
    object.__setattr__(iface, "path", fmu)  # an interface read before the file was replaced
    object.__setattr__(iface, "sha256", "f" * 64)
    with pytest.raises(InitializationError, match="cannot extract the FMU: .*Broken.fmu: "):
        fmi_runtime._extract(iface)


def test_extraction_counts_the_bytes_it_writes_whatever_the_directory_declares(tmp_path, sine, monkeypatch):
    monkeypatch.setattr(archive_checks, "MAX_FMU_BYTES", 100_000)
    monkeypatch.setattr(archive_checks, "_limit_problems", lambda infos: [])  # a directory that lies
    with pytest.raises(FmuArchiveError, match=r"ToySine.fmu: expands beyond 0 MiB \(a limit against zip bombs\)"):
        extract_fmu(sine, tmp_path / "x")
    written = sum(f.stat().st_size for f in (tmp_path / "x").rglob("*") if f.is_file())
    assert written <= 100_000 + (1 << 20)  # stopped within one chunk of the bound


def test_a_good_fmu_extracts_as_fmpy_does(tmp_path, sine):
    from fmpy import extract

    assert layout_problems(sine) == [] and corrupt_member(sine) is None
    ours, theirs = extract_fmu(sine, tmp_path / "ours"), Path(extract(str(sine), str(tmp_path / "fmpy")))
    files = sorted(p.relative_to(ours) for p in ours.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(theirs) for p in theirs.rglob("*") if p.is_file()) and len(files) > 10
    assert all((ours / f).read_bytes() == (theirs / f).read_bytes() for f in files)


def test_a_pipe_named_as_an_fmu_is_refused_without_blocking(toy_dir, tmp_path, capsys):
    pipe = tmp_path / "Pipe.fmu"
    os.mkfifo(pipe)
    scenario = _scenario_with(tmp_path, toy_dir, pipe)
    assert cli.main(["run", str(scenario), "--no-build", "--check"]) == 1
    err = capsys.readouterr().err
    assert f"components.src.fmu = 'Pipe.fmu': expected a regular FMU file ({pipe} is a device, pipe or folder)" in err
    assert err.count("\n") == 1
    assert check_fmu(pipe) == ["not a regular file (a device, pipe or folder)"]


def test_an_fmu_inside_an_ssp_that_declares_3_gib_is_refused(tmp_path):
    from orchestrator.errors import ScenarioError
    from orchestrator.interop.ssp import import_ssp
    from tests.helpers.ssp_documents import feedthrough, real, ssd, write_ssp, zip_folder

    folder = write_ssp(tmp_path / "ssp", ssd(f"""
  <ssd:System name="root">
    <ssd:Elements>{feedthrough("ft", real("Float64_continuous_input", "input"))}</ssd:Elements>
  </ssd:System>"""))
    fmu = folder / "resources" / "Feedthrough.fmu"
    declaring(fmu, tmp_path / "bomb.fmu", 3 << 30)
    shutil.copy(tmp_path / "bomb.fmu", fmu)
    archive = zip_folder(folder, tmp_path / "system.ssp")
    with pytest.raises(ScenarioError, match=r"components\.ft\.fmu = '.*/system\.ssp!resources/Feedthrough\.fmu': "
                                            r"expected a readable FMU \(expands to 3072 MiB"):
        import_ssp(archive)


def test_a_damaged_member_in_a_folder_dtcosim_builds_into_marks_the_fmu_for_a_rebuild(tmp_path, sine):
    """zipfile's testzip let the zlib.error of a damaged member through the provisioning check."""
    from orchestrator.provision.staleness import broken_fmu, stale_project_fmus

    fmu = damaged(sine, tmp_path / "Gearbox.fmu")
    assert broken_fmu(fmu).startswith("archive member 'binaries/linux64/ToySine.so' is damaged (")
    assert stale_project_fmus({"gearbox": fmu}) == []
