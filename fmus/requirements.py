"""The runtime requirements an FMU declares, derived from its code and the build environment.

Which packages
--------------
Exactly the third-party top-level modules that the FMU's embedded code imports
(:func:`third_party_modules`: every absolute ``import`` of the embedded modules'
syntax trees, less the standard library and what the FMU carries itself:
its copy of ``components``/``fmus.slaves`` and pythonfmu's Python package),
mapped to the distributions that provide them in the build environment. An
import whose line says ``# optional requirement: <what it gives>`` (the code
falls back without it, e.g. numba for the compiled gearbox kernel) makes an
*optional* requirement, unless the module is also imported without that note.

Which versions (the range policy)
---------------------------------
The versions come from the environment the FMU is built in, where the test
suite and ``dtcosim validate`` run it:

* a package installed as ``X.Y.Z`` is declared ``>=X.Y,<X+1``: the lower end
  is the tested minor release (patch releases of numpy and scipy change no API),
  the upper end the next major release, whose API changes are not covered.
  ``dtcosim validate --host`` installs the newest release inside that range into
  a fresh virtual environment and runs the FMU there, which tests the upper end
  at the time it is run;
* the Python is declared ``>=3.M,<3.M+1`` for a build on Python ``3.M``:
  pythonfmu's binary calls CPython's (non-limited) C API, and only the build's
  minor version is tested. An older Python makes ``fmi2Instantiate`` fail with a
  message; a newer one runs with a warning.

The format of ``resources/requirements.txt`` and the checks the FMU makes at
instantiation live in :mod:`fmus.runtime_guard` (which the FMU carries).
"""

from __future__ import annotations

import functools
import importlib.util
import sys
import zipfile
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Callable, Iterable, Mapping

from components.compile.import_statements import import_statements

from .runtime_guard import (
    REQUIREMENTS_FILE,
    PackageRequirement,
    RuntimeRequirements,
    installed_version,
    parse_requirements,
    python_problem,
    release,
    version_warnings,
)

#: Top-level packages an FMU carries in its resources (never requirements).
EMBEDDED_PACKAGES = frozenset({"components", "fmus", "pythonfmu"})

#: Member of the FMU archive holding the declaration.
ARCHIVE_MEMBER = f"resources/{REQUIREMENTS_FILE}"


#: the note on an import line that makes its module an optional requirement
OPTIONAL_NOTE = "# optional requirement:"


def imported_modules(sources: Iterable[Path]) -> tuple[dict[str, None], dict[str, str]]:
    """Third-party top-level modules imported by ``sources``: ``(required, optional -> purpose)``.

    Neither the standard library nor what the FMU carries counts; a module imported
    both with and without :data:`OPTIONAL_NOTE` is required.
    """
    required: dict[str, None] = {}
    optional: dict[str, str] = {}
    for path in sources:
        for name, note in _imports_of(str(path), Path(path).read_text(encoding="utf-8")):
            if note is None:
                required[name] = None
            else:
                optional.setdefault(name, note)
    ignored = set(sys.stdlib_module_names) | {"__future__"} | EMBEDDED_PACKAGES
    required = {m: None for m in sorted(required) if m not in ignored}
    optional = {m: p for m, p in sorted(optional.items()) if m not in ignored and m not in required}
    return required, optional


def _imports_of(path: str, text: str) -> tuple[tuple[str, str | None], ...]:
    """The top-level modules of every absolute import in ``text`` (the file ``path``), each with the note of its
    line after :data:`OPTIONAL_NOTE` (None: required)."""
    lines = text.splitlines()
    found = []
    for statement in import_statements(text, path):
        if not statement.is_from:
            names = [name.split(".")[0] for name in statement.names]
        elif statement.level == 0 and statement.module:
            names = [statement.module.split(".")[0]]
        else:
            continue
        line = lines[statement.line - 1]
        note = line.partition(OPTIONAL_NOTE)[2].strip() if OPTIONAL_NOTE in line else None
        found += [(name, note) for name in names]
    return tuple(found)


def third_party_modules(sources: Iterable[Path]) -> tuple[str, ...]:
    """Sorted top-level modules the code of ``sources`` requires (optional ones left out)."""
    return tuple(imported_modules(sources)[0])


def distribution_of(module: str) -> str:
    """The installed distribution providing top-level ``module`` (the module name if none is known)."""
    return _distribution_of(module)


@functools.lru_cache(maxsize=64)
def _distribution_of(module: str) -> str:
    """:func:`distribution_of`, first by the distribution of the module's own name where that one provides it
    (numpy, scipy, pythonfmu: one file list read), else from every installed distribution's file list
    (``importlib.metadata.packages_distributions()``: ~0.5 s, once per process)."""
    try:
        same_name = metadata.distribution(module)
    except metadata.PackageNotFoundError:
        same_name = None
    if same_name is not None and module in _top_level_names(same_name):
        return same_name.metadata["Name"] or module
    names = _distributions().get(module) or [module]
    return names[0]


def _top_level_names(dist: metadata.Distribution) -> set[str]:
    """The top-level modules and packages ``dist`` installs (from its file list; empty if it has none)."""
    out = set()
    for file in dist.files or ():
        first = file.parts[0] if file.parts else ""
        if len(file.parts) > 1 and not first.endswith((".dist-info", ".egg-info", ".data")) and first != "..":
            out.add(first)
        elif len(file.parts) == 1 and first.endswith((".py", ".so", ".pyd")):
            out.add(first.split(".")[0])
    return out


@functools.lru_cache(maxsize=1)
def _distributions() -> Mapping[str, list[str]]:
    """``importlib.metadata.packages_distributions()`` once per process (it reads every installed
    distribution's file list)."""
    return metadata.packages_distributions()


def tested_range(version: str) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``"2.4.6"`` -> ``((2, 4), (3,))``: the minor release tested up to the next major one."""
    parts = release(version) + (0,)
    return parts[:2], (parts[0] + 1,)


def python_range(version: tuple[int, ...]) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``(3, 11, 7)`` -> ``((3, 11), (3, 12))``: only the build's minor version is tested."""
    return tuple(version[:2]), (version[0], version[1] + 1)


def from_environment(fmu: str, modules: Iterable[str], python: tuple[int, ...] | None = None,
                     version_of: Callable[[str], str] = metadata.version,
                     distribution: Callable[[str], str] = distribution_of,
                     optional: dict[str, str] | None = None) -> RuntimeRequirements:
    """Requirements of FMU ``fmu`` whose code imports ``modules``, from the versions installed here.

    Parameters
    ----------
    fmu : str
        FMU model name.
    modules : iterable of str
        Third-party top-level modules (:func:`third_party_modules`).
    python : tuple of int, optional
        Python version of the build (default: this interpreter).
    version_of, distribution : callable
        Installed version of a distribution; distribution of a module (default: this environment).
    optional : mapping of str -> str, optional
        Optional modules and what they give (:func:`imported_modules`); those not installed here
        are left out (the FMU was tested without them).

    Raises
    ------
    metadata.PackageNotFoundError
        If a module's distribution is not installed here (the FMU could not have been tested).
    """
    python = tuple(sys.version_info[:3]) if python is None else tuple(python)
    packages = []
    for module in sorted(set(modules)):
        dist = distribution(module)
        version = version_of(dist)
        minimum, below = tested_range(version)
        packages.append(PackageRequirement(dist, module, minimum, below, version))
    extras = []
    for module, purpose in sorted((optional or {}).items()):
        dist = distribution(module)
        try:
            version = version_of(dist)
        except metadata.PackageNotFoundError:
            continue
        minimum, below = tested_range(version)
        extras.append(PackageRequirement(dist, module, minimum, below, version, purpose))
    py_min, py_below = python_range(python)
    return RuntimeRequirements(fmu, py_min, py_below, ".".join(map(str, python)), tuple(packages), tuple(extras))


def read_from_fmu(fmu_path: Path | str) -> RuntimeRequirements | None:
    """The requirements an FMU archive declares (None if it declares none)."""
    with zipfile.ZipFile(fmu_path) as archive:
        if ARCHIVE_MEMBER not in archive.namelist():
            return None
        text = archive.read(ARCHIVE_MEMBER).decode("utf-8")
    return parse_requirements(text, Path(fmu_path).stem)


@dataclass(frozen=True)
class EnvironmentCheck:
    """How this interpreter meets an FMU's requirements.

    Attributes
    ----------
    missing : tuple of str
        What stops the FMU from starting here (old Python, a module that cannot be found).
    warnings : tuple of str
        Versions outside the tested ranges.
    """

    missing: tuple[str, ...]
    warnings: tuple[str, ...]


def check_environment(req: RuntimeRequirements, python: tuple[int, ...] | None = None,
                      find_module: Callable[[str], object] = importlib.util.find_spec,
                      installed: Callable[[PackageRequirement], str | None] = installed_version) -> EnvironmentCheck:
    """Check ``req`` against an interpreter (default: this one) without importing anything."""
    missing = []
    problem = python_problem(req, python)
    if problem:
        missing.append(problem)
    for p in req.packages:
        if find_module(p.module) is None:
            missing.append(f"module {p.module!r} not found: install {p.specifier} (tested with {p.tested})")
    present = {p.module for p in req.packages + req.optional if find_module(p.module) is not None}
    warnings = list(version_warnings(req, python, lambda p: installed(p) if p.module in present else None))
    for p in req.optional:
        if p.module not in present:
            warnings.append(f"optional module {p.module!r} not found ({p.specifier}: {p.purpose}); the FMU runs "
                            "without it")
    return EnvironmentCheck(tuple(missing), tuple(warnings))
