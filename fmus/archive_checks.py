"""What an FMU archive must hold before a host loads its binary: the checks that keep a broken file from crashing it.

A host that loads an FMU's shared library trusts the archive: a PythonFMU
binary without its ``resources/`` (``slavemodule.txt`` names the slave module)
dereferences nothing and the process dies with a segmentation fault, and an FMU
without a binary for this platform cannot be loaded at all. :func:`archive_problems`
finds these from the archive's directory (nothing is extracted or loaded), so
``dtcosim run --check``, ``run``, ``sweep`` and ``validate`` refuse such a file
with a message instead.

Before any of that, :func:`layout_problems` checks what reading or extracting the
archive would do, from its directory alone: a regular file (a FIFO or a device would
block or never end), at most :data:`MAX_FMU_MEMBERS` members that expand to at most
:data:`MAX_FMU_BYTES` together, no member expanding more than :data:`MAX_FMU_RATIO`
times (a zip bomb: a 3 GiB member was extracted until the temporary folder was full),
and member names that stay inside the folder they are extracted to (no absolute
path, drive letter, backslash or ``..``). :func:`corrupt_member` reads every member
once (a damaged member is found before a run, not as a ``zlib.error`` in the middle of
one), and :func:`extract_fmu` extracts within the same bounds, whatever the
directory says.
"""

from __future__ import annotations

import os
import stat
import zipfile
import zlib
from pathlib import Path

from components.errors import DtcosimError

#: the most members of an FMU archive
MAX_FMU_MEMBERS = 10_000
#: the most bytes an FMU archive's members expand to together (dtcosim's FMUs: about 5 MB)
MAX_FMU_BYTES = 1 << 30
#: the most a member above :data:`RATIO_FLOOR_BYTES` may expand (uncompressed / compressed size)
MAX_FMU_RATIO = 200
RATIO_FLOOR_BYTES = 1 << 20
#: what reading a damaged member raises
CORRUPT_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError)


class FmuArchiveError(DtcosimError, ValueError):
    """An FMU archive that is unsafe to extract or damaged (names the file, the member and the bound)."""

#: the file a PythonFMU binary reads at instantiation to find its slave module
PYTHONFMU_MODULE_FILE = "resources/slavemodule.txt"
#: a dtcosim FMU's record
RECORD_MEMBER = "resources/dtcosim.json"


#: shared-library extension of each FMI 2.0 platform folder
PLATFORM_EXTENSIONS = {"linux64": ".so", "linux32": ".so", "win64": ".dll", "win32": ".dll", "darwin64": ".dylib"}


def _slave_module_problem(path: Path | str, names: set[str]) -> str | None:
    """What keeps a PythonFMU binary from importing the module ``resources/slavemodule.txt`` names (None: nothing).

    The binary takes the file's first line as the module name, as it is: an empty line, bytes that are
    not UTF-8 or a name that is not a module's crashed pythonfmu's binary (a segmentation fault) as a
    module it does not carry did. A member that cannot be read is left to the archive checks.
    """
    try:
        with zipfile.ZipFile(path) as archive:
            line = archive.read(PYTHONFMU_MODULE_FILE).split(b"\n", 1)[0]
    except (OSError, KeyError, *CORRUPT_ERRORS):
        return None
    cannot = "the FMU cannot create its slave"
    try:
        module = line.decode("utf-8")
    except UnicodeDecodeError:
        return f"{PYTHONFMU_MODULE_FILE} is not UTF-8 text ({line[:40]!r}): {cannot}"
    if not module:
        return f"{PYTHONFMU_MODULE_FILE} names no slave module (its first line is empty): {cannot}"
    if not all(part.isidentifier() for part in module.split(".")):
        return f"{PYTHONFMU_MODULE_FILE} names {module!r}, which is not a Python module name: {cannot}"
    if not {f"resources/{module}.py", f"resources/{module}/__init__.py"} & names:
        return (f"{PYTHONFMU_MODULE_FILE} names the slave module {module!r}, which is not in resources/ (no "
                f"resources/{module}.py): {cannot}")
    return None


def _illegal_name(name: str) -> bool:
    """True for a member name that would be written outside the folder it is extracted to."""
    return name.startswith("/") or "\\" in name or ":" in name or ".." in name.split("/")


def _limit_problems(infos: list[zipfile.ZipInfo]) -> list[str]:
    if len(infos) > MAX_FMU_MEMBERS:
        return [f"{len(infos)} archive members, expected at most {MAX_FMU_MEMBERS} (a limit against zip bombs)"]
    problems = []
    total = sum(i.file_size for i in infos)
    if total > MAX_FMU_BYTES:
        problems.append(f"expands to {total / 2**20:.0f} MiB, expected at most {MAX_FMU_BYTES / 2**20:.0f} MiB (a "
                        "limit against zip bombs)")
    for info in infos:
        ratio = info.file_size / max(info.compress_size, 1)
        if info.file_size > RATIO_FLOOR_BYTES and ratio > MAX_FMU_RATIO:
            problems.append(f"archive member {info.filename!r} expands {ratio:.0f} times ({info.compress_size} -> "
                            f"{info.file_size} bytes), expected at most {MAX_FMU_RATIO} times (a limit against zip "
                            "bombs)")
            break
    for info in infos:
        if _illegal_name(info.filename):
            problems.append(f"archive member {info.filename!r} would be extracted outside the FMU's folder (an "
                            "absolute path, a drive letter, a backslash or '..'; FMI 2.0: relative names with '/')")
            break
    return problems


def layout_problems(path: str | Path) -> list[str]:
    """What makes the file at ``path`` unsafe to read or extract as an FMU (empty: nothing; nothing is decompressed)."""
    try:
        info = os.stat(path)
    except OSError as exc:
        return [f"cannot be read ({exc.strerror})"]
    if not stat.S_ISREG(info.st_mode):
        return ["not a regular file (a device, pipe or folder)"]
    try:
        with zipfile.ZipFile(path) as archive:
            infos = archive.infolist()
    except (zipfile.BadZipFile, OSError) as exc:
        return [f"not a readable zip archive ({exc})"]
    return _limit_problems(infos)


def corrupt_member(path: str | Path) -> str | None:
    """What is wrong with the first damaged member (its data does not decompress or match its CRC), or None."""
    try:
        with zipfile.ZipFile(path) as archive:
            for info in archive.infolist():
                try:
                    with archive.open(info) as member:
                        while member.read(1 << 20):
                            pass
                except CORRUPT_ERRORS as exc:
                    return f"archive member {info.filename!r} is damaged ({exc or type(exc).__name__})"
    except (zipfile.BadZipFile, OSError) as exc:
        return f"not a readable zip archive ({exc})"
    return None


def extract_fmu(path: str | Path, target: str | Path) -> Path:
    """Extract the FMU at ``path`` into the folder ``target`` within the limits of :func:`layout_problems`.

    The bytes written are counted as they are written: the extraction stops at
    :data:`MAX_FMU_BYTES` whatever the archive's directory declares.

    Raises
    ------
    FmuArchiveError
        The archive is beyond a limit, names a member outside ``target``, or a member is damaged.
    OSError
        ``target`` cannot take the files (a full disk, a file-size limit).
    """
    path, target = Path(path), Path(target)
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as exc:
        raise FmuArchiveError(f"{path}: not a readable zip archive ({exc})") from None
    with archive:
        infos = archive.infolist()
        problems = _limit_problems(infos)
        if problems:
            raise FmuArchiveError(f"{path}: {problems[0]}")
        left = MAX_FMU_BYTES
        target.mkdir(parents=True, exist_ok=True)
        made = {target}  # folders made (or there): each is made once, not asked for again by every member
        for info in infos:
            dest = target.joinpath(*info.filename.split("/"))
            folder = dest if info.is_dir() else dest.parent
            if folder not in made:
                folder.mkdir(parents=True, exist_ok=True)
                made.add(folder)
            if info.is_dir():
                continue
            try:
                with archive.open(info) as member, open(dest, "wb") as out:
                    while chunk := member.read(1 << 20):
                        left -= len(chunk)
                        if left < 0:
                            raise FmuArchiveError(f"{path}: expands beyond {MAX_FMU_BYTES / 2**20:.0f} MiB (a limit "
                                                  "against zip bombs)")
                        out.write(chunk)
            except CORRUPT_ERRORS as exc:
                raise FmuArchiveError(f"{path}: archive member {info.filename!r} is damaged "
                                      f"({exc or type(exc).__name__})") from None
    return target


def platform_binary(model_identifier: str) -> str:
    """The archive member of the binary this host loads: ``binaries/linux64/<id>.so`` here."""
    from fmpy import platform, sharedLibraryExtension

    return f"binaries/{platform}/{model_identifier}{sharedLibraryExtension}"


def binary_platforms(path: str | Path, model_identifier: str) -> tuple[str, ...]:
    """Platforms whose ``binaries/<platform>/<modelIdentifier><ext>`` the FMU archive holds (sorted)."""
    try:
        with zipfile.ZipFile(path) as archive:
            names = set(archive.namelist())
    except (OSError, zipfile.BadZipFile):
        return ()
    return _platforms_in(names, model_identifier)


def _platforms_in(names: set[str], model_identifier: str) -> tuple[str, ...]:
    return tuple(sorted(platform for platform, ext in PLATFORM_EXTENSIONS.items()
                        if f"binaries/{platform}/{model_identifier}{ext}" in names))


def archive_problems(path: str | Path, model_identifier: str | None, generation_tool: str = "",
                     names: set[str] | None = None) -> list[str]:
    """What keeps the FMU at ``path`` from being loaded on this platform (empty: nothing found).

    Parameters
    ----------
    model_identifier : str or None
        The co-simulation model identifier (None: not a co-simulation FMU, no binary check).
    generation_tool : str
        The model description's ``generationTool`` (PythonFMU and dtcosim FMUs need their resources).
    names : set of str, optional
        The archive's member names, when the caller has read them already.
    """
    if names is None:
        try:
            with zipfile.ZipFile(path) as archive:
                names = set(archive.namelist())
        except (zipfile.BadZipFile, OSError) as exc:
            return [f"not a readable zip archive ({exc})"]
    problems = []
    if model_identifier:
        binary = platform_binary(model_identifier)
        if binary not in names:
            from fmpy import platform

            carried = _platforms_in(names, model_identifier)
            problems.append(f"no co-simulation binary for this platform ({platform}: {binary}); it has binaries "
                            f"for: {', '.join(carried) or 'none'}")
    tool = generation_tool.lower()
    if "pythonfmu" in tool and PYTHONFMU_MODULE_FILE not in names:
        problems.append(f"no {PYTHONFMU_MODULE_FILE}: a PythonFMU binary cannot find its slave without its "
                        "resources folder")
    elif "pythonfmu" in tool:
        problem = _slave_module_problem(path, names)
        if problem is not None:
            problems.append(problem)
    if tool.startswith("dtcosim") and RECORD_MEMBER not in names:
        problems.append(f"no {RECORD_MEMBER}: a dtcosim FMU reads its model from its record")
    return problems
