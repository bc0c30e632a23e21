"""Project FMUs built from other code than the installed dtcosim.

A project FMU carries the hash of its code and of the model it was built from in its
pythonfmu entry module name (``resources/slavemodule.txt``) and that model in its FMU
record (``resources/dtcosim.json``); it is stale when the installed sources, built from
the same model, would give another hash (:func:`fmus.build.code_hash`).
"""

from __future__ import annotations

import json
import re
import zipfile
import zlib
from pathlib import Path
from typing import Mapping

from fmus.build import code_hash
from fmus.registry import KINDS
from fmus.slaves.record import RECORD_FILE

_BUILD_ID = re.compile(r"^_dtcosim_[a-z]+_([0-9a-f]{12})_slave$")


def broken_fmu(path: Path) -> str | None:
    """Why the FMU file at ``path`` cannot be a whole project FMU (None: it reads as one).

    An interrupted or concurrent build of an older dtcosim could leave a truncated archive, or one without
    its slave module or record; in the folders dtcosim builds into such a file is rebuilt, not used.
    """
    from fmus.archive_checks import corrupt_member, layout_problems

    problems = layout_problems(path)  # a pipe, a zip bomb, names outside the folder: before anything is read
    if problems:
        return "; ".join(problems)
    damaged = corrupt_member(path)  # zipfile's testzip lets a zlib.error of a damaged member through
    if damaged is not None:
        return damaged
    try:
        with zipfile.ZipFile(path) as zf:
            names = set(zf.namelist())
    except (OSError, zipfile.BadZipFile) as exc:
        return f"not a readable zip archive ({exc})"
    missing = [m for m in ("resources/slavemodule.txt", f"resources/{RECORD_FILE}", "modelDescription.xml")
               if m not in names]
    return f"it lacks {', '.join(missing)}" if missing else None


def stale_project_fmus(paths: Mapping[str, Path]) -> list[str]:
    """Warnings for project FMUs built from other code than the installed ``components``/``fmus``.

    Parameters
    ----------
    paths : mapping of str -> Path
        FMU file per component; FMUs that are not the project's are not checked.
    """
    out = []
    for comp, path in paths.items():
        try:
            with zipfile.ZipFile(path) as zf:
                module = zf.read("resources/slavemodule.txt").decode().strip()
                record = json.loads(zf.read(f"resources/{RECORD_FILE}"))
            model = record["model"]
        except (KeyError, OSError, ValueError, TypeError, zipfile.BadZipFile, zlib.error, EOFError):
            continue
        m = _BUILD_ID.match(module)
        name = record.get("fmu")
        if not m or name not in KINDS:
            continue
        if m.group(1) != code_hash(name, model):
            out.append(f"{path} ({comp}) was built from other code than the installed dtcosim (build {m.group(1)}); "
                       f"rebuild it with `dtcosim build --out {path.parent}`")
    return out
