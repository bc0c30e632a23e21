"""What an FMU archive must hold before a host loads its binary: the checks that keep a broken file from crashing it.

A host that loads an FMU's shared library trusts the archive: a PythonFMU
binary without its ``resources/`` (``slavemodule.txt`` names the slave module)
dereferences nothing and the process dies with a segmentation fault, and an FMU
without a binary for this platform cannot be loaded at all. :func:`archive_problems`
finds these from the archive's directory (nothing is extracted or loaded), so
``dtcosim run --check``, ``run``, ``sweep`` and ``validate`` refuse such a file
with a message instead.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

#: the file a PythonFMU binary reads at instantiation to find its slave module
PYTHONFMU_MODULE_FILE = "resources/slavemodule.txt"
#: a dtcosim FMU's record
RECORD_MEMBER = "resources/dtcosim.json"


#: shared-library extension of each FMI 2.0 platform folder
PLATFORM_EXTENSIONS = {"linux64": ".so", "linux32": ".so", "win64": ".dll", "win32": ".dll", "darwin64": ".dylib"}


def _slave_module(path: Path | str) -> str | None:
    """The module ``resources/slavemodule.txt`` names (None: unreadable)."""
    try:
        with zipfile.ZipFile(path) as archive:
            return archive.read(PYTHONFMU_MODULE_FILE).decode("utf-8").strip() or None
    except (zipfile.BadZipFile, OSError, KeyError, UnicodeDecodeError):
        return None


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
        module = _slave_module(path)
        if module is not None and not ({f"resources/{module}.py", f"resources/{module}/__init__.py"} & names):
            problems.append(f"{PYTHONFMU_MODULE_FILE} names the slave module {module!r}, which is not in "
                            f"resources/ (no resources/{module}.py): the FMU cannot create its slave")
    if tool.startswith("dtcosim") and RECORD_MEMBER not in names:
        problems.append(f"no {RECORD_MEMBER}: a dtcosim FMU reads its model from its record")
    return problems
