"""The FMUs' own linux64 binary (fmus/binary.py, fmus/native/): what it exports, what it records, how it builds."""

from __future__ import annotations

import ctypes
import sys
import sysconfig
import zipfile

import pytest

from fmus import binary

#: the FMI 2.0 functions of a co-simulation FMU (the standard's fmi2Functions.h: common and co-simulation)
FMI2_CS_FUNCTIONS = (
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
    "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset",
    "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus",
    "fmi2GetRealStatus", "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus",
)

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the binary is built for linux64")


@pytest.fixture(scope="module")
def library():
    try:
        path = binary.compiled_binary()
    except binary.NativeBuildError as exc:
        pytest.skip(str(exc))
    return ctypes.CDLL(str(path))


def test_it_exports_every_fmi2_co_simulation_function_and_no_helper(library):
    missing = [name for name in FMI2_CS_FUNCTIONS if not hasattr(library, name)]
    assert missing == []
    for helper in ("start_python", "call", "say", "log_text", "flush_log", "py"):  # hidden: no host can interpose them
        assert not hasattr(library, helper), helper
    library.fmi2GetVersion.restype = ctypes.c_char_p
    library.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    assert library.fmi2GetVersion() == b"2.0" and library.fmi2GetTypesPlatform() == b"default"


def test_python_record_names_this_interpreter():
    lines = binary.python_record().splitlines()
    record = {}
    for line in lines:
        key, _, value = line.partition("=")
        record.setdefault(key, []).append(value)
    assert record["home"] == [sys.base_prefix]
    assert record["version"] == [f"{sys.version_info.major}.{sys.version_info.minor}"]
    assert sysconfig.get_paths()["purelib"] in record["path"] or any(p.endswith("site-packages") for p in record["path"])
    lib = binary.libpython()
    assert record["libpython"] == ["" if lib is None else str(lib)]


def test_the_build_id_follows_the_binary_s_sources(monkeypatch, tmp_path):
    before = binary.source_digest()
    copy = tmp_path / "native"
    copy.mkdir()
    for name in (*binary.SOURCES, binary.HEADER):
        (copy / name).write_bytes((binary.NATIVE_DIR / name).read_bytes())
    (copy / binary.SOURCES[0]).write_bytes((copy / binary.SOURCES[0]).read_bytes() + b"\n/* changed */\n")
    monkeypatch.setattr(binary, "NATIVE_DIR", copy)
    assert binary.source_digest() != before


def test_every_built_fmu_carries_the_binary_and_its_records(fmu_path):
    for name in ("Gearbox", "WindSource", "GeneratorRotor"):
        with zipfile.ZipFile(fmu_path(name)) as archive:
            names = set(archive.namelist())
            assert f"binaries/linux64/{name}.so" in names and "binaries/win64/" + name + ".dll" in names
            assert archive.read(f"binaries/linux64/{name}.so") == binary.compiled_binary().read_bytes()
            assert archive.read("resources/slaveclass.txt").decode().strip() == name
            assert archive.read("resources/python.txt").decode() == binary.python_record()


def test_a_build_waits_for_the_compile_started_in_its_own_process_and_compiles_nothing_itself(tmp_path, monkeypatch):
    if binary.compiler() is None:
        pytest.skip("no C compiler")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    compiles = []
    real = binary._compile
    monkeypatch.setattr(binary, "_compile", lambda cc, target: compiles.append(target) or real(cc, target))
    compiling = binary.start_compile()
    assert compiling is not None and binary.start_compile() is None  # one compiling process at a time
    path = binary.compiled_binary()  # while the other process compiles: waits for it (or finds its result)
    compiling.finish()
    assert compiling.process.returncode == 0
    assert path.is_file() and path.is_relative_to(tmp_path) and compiles == []  # compiled there, not here
    assert ctypes.CDLL(str(path)).fmi2GetVersion  # the whole file
    assert binary.start_compile() is None  # nothing to compile any more
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary folder left


def test_an_interrupted_compile_leaves_no_binary_and_no_temporary_folder(tmp_path, monkeypatch):
    if binary.compiler() is None:
        pytest.skip("no C compiler")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    compiling = binary.start_compile()
    compiling.stop()
    assert not list((tmp_path / "native").glob("*/*"))  # nothing half-written
    assert binary.compiled_binary().is_file()  # the next build compiles it


def test_a_failing_background_compile_leaves_the_error_to_the_caller(tmp_path, monkeypatch, capfd):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(binary, "compiler", lambda: str(tmp_path / "broken-cc"))
    (tmp_path / "broken-cc").write_text("#!/bin/sh\necho 'broken-cc: cannot compile' >&2\nexit 1\n")
    (tmp_path / "broken-cc").chmod(0o755)
    compiling = binary.start_compile()
    compiling.finish()
    assert compiling.process.returncode == 1
    assert capfd.readouterr().err == ""  # nothing of the compiling process reaches the user
    with pytest.raises(binary.NativeBuildError, match="broken-cc could not compile .*cannot compile"):
        binary.compiled_binary()


def test_where_the_cache_cannot_be_written_each_process_compiles_its_own_and_leaves_nothing(tmp_path, monkeypatch):
    if binary.compiler() is None:
        pytest.skip("no C compiler")
    blocked = tmp_path / "a-file"
    blocked.write_text("where the cache would be")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(blocked))
    monkeypatch.setattr(binary, "_compiled_here", {})
    monkeypatch.setattr(binary.tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    with pytest.raises(OSError):
        binary.compiled_binary()
    assert binary.start_compile() is None
    first = binary.binary_bytes()
    assert first[:4] == b"\x7fELF" and binary.binary_bytes() is first  # compiled once per process
    assert list((tmp_path / "tmp").iterdir()) == []  # its temporary folder is gone
    assert binary.native_members("Gearbox", "Gearbox")["binaries/linux64/Gearbox.so"] == first
