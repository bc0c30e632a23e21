"""Validation of FMUs: ``fmpy.validation`` for any FMU, plus dtcosim's own conventions for the FMUs dtcosim built.

A file that is not a zip archive or whose ``modelDescription.xml`` is missing or
truncated is one problem with a message, never a traceback.
"""

from __future__ import annotations

import os
import re
import zipfile
from pathlib import Path
from typing import Iterable

from fmpy import read_model_description
from fmpy.validation import validate_fmu

from .archive_checks import RECORD_MEMBER, archive_problems, corrupt_member, layout_problems
from .requirements import ARCHIVE_MEMBER, read_from_fmu
from .runtime_guard import RequirementsFormatError

DOCUMENTATION_MEMBER = "documentation/index.html"

#: a structured variable name (FMI 2.0, section 2.2.9) of plain identifiers with array subscripts: the grammar accepts
#: every such name (quoted names and ``der(...)`` are the grammar's other forms)
_PLAIN_STRUCTURED_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+(?:,[0-9]+)*\])?"
                                    r"(?:\.[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+(?:,[0-9]+)*\])?)*")


def fmpy_problems(fmu_path: Path | str) -> list[str]:
    """The problems ``fmpy.validation.validate_fmu`` finds in an FMU, found faster for the usual variable names.

    fmpy checks each name of the structured naming convention with an Earley parser of the
    grammar, built anew for every FMU: most of the time of a build's validation (~0.2 s for the
    Gearbox's 160 names). Where every name is of :data:`_PLAIN_STRUCTURED_NAME`, which the
    grammar accepts, fmpy validates everything else and the names are not parsed again; any
    other name (quoted, ``der(...)``, an illegal one) has fmpy validate all of it.
    """
    from fmpy.model_description import ValidationError
    from lxml import etree

    try:
        with zipfile.ZipFile(fmu_path) as archive:
            root = etree.fromstring(archive.read("modelDescription.xml"))
            backslashes = [f'The file path "{i.orig_filename}" contains a backslash.' for i in archive.filelist
                           if "\\" in i.orig_filename]
    except Exception:  # noqa: BLE001 - what fmpy says about it (it reads the archive itself)
        return validate_fmu(str(fmu_path))
    names = [v.get("name", "") for v in root.iterfind("ModelVariables/ScalarVariable")]
    if root.get("variableNamingConvention") != "structured" or not all(map(_PLAIN_STRUCTURED_NAME.fullmatch, names)):
        return validate_fmu(str(fmu_path))
    try:  # as validate_fmu, without parsing the names again
        read_model_description(str(fmu_path), validate=True, validate_variable_names=False,
                               validate_model_structure=True)
    except ValidationError as exc:
        return list(exc.problems)
    except Exception as exc:  # noqa: BLE001 - as validate_fmu: its message is the problem
        return [str(exc)]
    return backslashes


def convention_problems(fmu_path: Path | str, md=None, names: set[str] | None = None) -> list[str]:
    """dtcosim conventions: described variables, a unit on every Real, state handling enabled (``md``, ``names``:
    the FMU's model description and member names, where the caller has read them)."""
    md = md if md is not None else read_model_description(str(fmu_path), validate=False)
    problems = []
    for v in md.modelVariables:
        if not v.description:
            problems.append(f'Variable "{v.name}" has no description.')
        if v.type == "Real" and not v.unit:
            problems.append(f'Real variable "{v.name}" declares no unit.')
    cs = md.coSimulation
    if cs is None:
        problems.append("The FMU does not support co-simulation.")
    elif not (cs.canGetAndSetFMUstate and cs.canSerializeFMUstate):
        problems.append("canGetAndSetFMUstate and canSerializeFMUstate must be true.")
    return problems + runtime_declaration_problems(fmu_path, names)


def runtime_declaration_problems(fmu_path: Path | str, names: set[str] | None = None) -> list[str]:
    """What a foreign host needs to be told: documentation and readable declared requirements."""
    if names is None:
        with zipfile.ZipFile(fmu_path) as archive:
            names = set(archive.namelist())
    problems = []
    if DOCUMENTATION_MEMBER not in names:
        problems.append(f"The FMU has no {DOCUMENTATION_MEMBER}.")
    if ARCHIVE_MEMBER not in names:
        problems.append(f"The FMU declares no requirements ({ARCHIVE_MEMBER}).")
    else:
        try:
            read_from_fmu(fmu_path)
        except RequirementsFormatError as exc:
            problems.append(f"{ARCHIVE_MEMBER}: {exc}")
    return problems




def _member_names(fmu_path: Path | str) -> tuple[set[str], str | None]:
    """The archive's member names, and why the file cannot be an FMU archive at all (or None)."""
    if os.path.exists(fmu_path) and not os.path.isfile(fmu_path):  # a pipe or a device would block or never end
        return set(), "not a regular file (a device, pipe or folder)"
    try:
        with zipfile.ZipFile(fmu_path) as archive:
            names = set(archive.namelist())
    except zipfile.BadZipFile as exc:
        return set(), f"not a zip archive, so not an FMU ({exc})"
    except OSError as exc:
        return set(), f"cannot be read ({exc})"
    problems = layout_problems(fmu_path)  # a zip bomb, members named outside the folder
    if problems:
        return names, "; ".join(problems)
    damaged = corrupt_member(fmu_path)
    if damaged:
        return names, damaged
    if "modelDescription.xml" not in names:
        return names, "the archive has no modelDescription.xml"
    return names, None


def is_dtcosim_fmu(fmu_path: Path | str) -> bool:
    """True for an FMU dtcosim built (it carries the record ``resources/dtcosim.json``)."""
    return RECORD_MEMBER in _member_names(fmu_path)[0]


def check_fmu(fmu_path: Path | str) -> list[str]:
    """All problems of one FMU (empty if it is valid): a readable archive this platform can load, fmpy's validation,
    and dtcosim's conventions for its own FMUs."""
    names, problem = _member_names(fmu_path)
    if problem is not None:
        return [problem]
    try:
        problems = fmpy_problems(fmu_path)
    except Exception as exc:  # noqa: BLE001 - fmpy raises plain exceptions for XML it cannot parse at all
        return [f"modelDescription.xml cannot be read ({exc})"]
    try:
        md = read_model_description(str(fmu_path), validate=False)
    except Exception:  # noqa: BLE001 - a description fmpy's validation found broken: its problems say why
        return list(problems)
    identifier = md.coSimulation.modelIdentifier if md.coSimulation is not None else None
    # what would crash a host loading it is named also beside the description's problems
    loading = archive_problems(fmu_path, identifier, md.generationTool or "", names)
    if problems:
        return list(problems) + loading
    return loading + (convention_problems(fmu_path, md, names) if RECORD_MEMBER in names else [])


def fmu_files(paths: Iterable[Path | str]) -> list[Path]:
    """``.fmu`` files named directly or contained in the given directories (sorted)."""
    found: list[Path] = []
    for p in map(Path, paths):
        found += sorted(p.glob("*.fmu")) if p.is_dir() else [p]
    return found
