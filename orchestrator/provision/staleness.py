"""Project FMUs built from other code than the installed dtcosim, or broken.

A project FMU carries the hash of its code and of the model it was built from in its
pythonfmu entry module name (``resources/slavemodule.txt``) and that model in its FMU
record (``resources/dtcosim.json``); it is stale when the installed sources, built from
the same model, would give another hash (:func:`fmus.build.code_hash`).

Hashing the installed sources reads and parses every module an FMU carries (about 0.1 s
per FMU), and a run checks its FMUs more than once (when it looks for them, before it
runs them). So each verdict is remembered, in this process and in ``fmu-checks.json`` of
the user cache, under the FMU file's stats (device, inode, size, modification time) and
the stamp of the installed sources (:func:`fmus.build.sources_stamp`, by file stats too):
a file or a source that changed in any way is checked again.
"""

from __future__ import annotations

import json
import os
import re
import zipfile
import zlib
from pathlib import Path
from typing import Callable, Mapping

from components.compile.user_cache import user_cache_root
from fmus.build import code_hash, sources_stamp
from fmus.registry import KINDS
from fmus.slaves.record import RECORD_FILE

from ..atomic_files import atomic_path

_BUILD_ID = re.compile(r"^_dtcosim_[a-z]+_([0-9a-f]{12})_slave$")

#: the remembered verdicts, in the user cache
CHECKS_FILE = "fmu-checks.json"
#: at most this many are kept (the newest)
MAX_CHECKS = 512

_checks: dict[str, dict] | None = None


def checks_path() -> Path:
    """Where the verdicts of earlier checks are kept."""
    return user_cache_root() / CHECKS_FILE


def _loaded() -> dict[str, dict]:
    global _checks
    if _checks is None:
        try:
            _checks = json.loads(checks_path().read_text(encoding="utf-8"))
            if not isinstance(_checks, dict):
                _checks = {}
        except (OSError, ValueError):
            _checks = {}
    return _checks


def _file_key(path: Path) -> str | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return f"{os.path.realpath(path)}:{st.st_dev}:{st.st_ino}:{st.st_size}:{st.st_mtime_ns}"


def remembered(kind: str, path: Path, check: Callable[[Path], dict]) -> dict:
    """``check(path)``'s verdict on the FMU file ``path``, computed once for the file's stats and the installed sources.

    ``kind`` names the check; the verdict (a JSON-able dict) is kept in this process and,
    best effort, in :func:`checks_path` (a read-only cache only costs the checks again).
    """
    key = _file_key(path)
    if key is None:
        return check(path)
    key = f"{kind}:{sources_stamp()}:{key}"
    checks = _loaded()
    if key in checks:
        return checks[key]
    verdict = check(path)
    checks[key] = verdict
    while len(checks) > MAX_CHECKS:
        del checks[next(iter(checks))]
    try:
        checks_path().parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(checks_path()) as tmp:
            tmp.write_text(json.dumps(checks), encoding="utf-8")
    except OSError:
        pass
    return verdict


def broken_fmu(path: Path) -> str | None:
    """Why the FMU file at ``path`` cannot be a whole project FMU (None: it reads as one); remembered (:func:`remembered`)."""
    return remembered("broken", Path(path), lambda p: {"problem": _broken(p)})["problem"]


def _broken(path: Path) -> str | None:
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
        build = stale_build(Path(path))
        if build is not None:
            out.append(f"{path} ({comp}) was built from other code than the installed dtcosim (build {build}); "
                       f"rebuild it with `dtcosim build --out {Path(path).parent}`")
    return out


def stale_build(path: Path) -> str | None:
    """The build id of the project FMU ``path`` if it was built from other code than the installed (None: current,
    or not the project's); remembered (:func:`remembered`)."""
    return remembered("stale", Path(path), lambda p: {"stale_build": _stale_build(p)})["stale_build"]


def _stale_build(path: Path) -> str | None:
    """The build id of a project FMU built from other code than the installed (None: current, or not the project's)."""
    try:
        with zipfile.ZipFile(path) as zf:
            module = zf.read("resources/slavemodule.txt").decode().strip()
            record = json.loads(zf.read(f"resources/{RECORD_FILE}"))
        model = record["model"]
    except (KeyError, OSError, ValueError, TypeError, zipfile.BadZipFile, zlib.error, EOFError):
        return None
    m = _BUILD_ID.match(module)
    name = record.get("fmu")
    if not m or name not in KINDS:
        return None
    return m.group(1) if m.group(1) != code_hash(name, model) else None
