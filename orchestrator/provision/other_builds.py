"""Project FMUs of other dtcosim versions, set aside in the folders dtcosim manages instead of built over.

Every install of a user (two virtual environments, two checkouts, an upgrade tried beside the old
version) shares the per-user FMU folder. Each finds the other's FMUs stale and rebuilt them on every
run: 1-2 s per run, and the FMU files a host was pointed at changed each time. In the folders dtcosim
manages - the default FMU folder, the drivetrain and load-record folders in it - a stale FMU is
therefore moved to ``.other-builds/<Name>/<build id>.fmu`` beside it, and a current one found there
(this install's, set aside by the other) is moved back instead of built: going back and forth between
installs costs two renames. The :data:`KEEP` builds of each FMU set aside last are kept, older ones
removed. Callers hold the folder's build lock (:func:`fmus.build_lock.build_lock`).
"""

from __future__ import annotations

import os
from pathlib import Path

from .staleness import broken_fmu, stale_build

#: the folder beside the FMUs that holds other versions' builds
STORE = ".other-builds"
#: builds kept per FMU
KEEP = 3


def _shelf(path: Path) -> Path:
    """Where other builds of the FMU ``path`` are kept: ``<folder>/.other-builds/<Name>/``."""
    return path.parent / STORE / path.stem


def swap_in(path: Path) -> bool:
    """Make the FMU file ``path`` a current build without building it, if one was set aside: True if it now is.

    A whole FMU at ``path`` built from other code is set aside first (a broken one is left to be built over).
    """
    path = Path(path)
    if path.is_file():
        if broken_fmu(path) is not None:
            return False
        build = stale_build(path)
        if build is None:
            return True
        set_aside(path, build)
    return take_back(path)


def set_aside(path: Path, build: str) -> Path:
    """Move the FMU file ``path`` (build ``build``) to its shelf; the oldest beyond :data:`KEEP` are removed."""
    shelf = _shelf(path)
    shelf.mkdir(parents=True, exist_ok=True)
    target = shelf / f"{build}.fmu"
    os.replace(path, target)
    os.utime(target)  # when it was set aside: the order in which shelved builds are dropped
    for old in _shelved(shelf)[KEEP:]:
        old.unlink(missing_ok=True)
    return target


def _shelved(shelf: Path) -> list[Path]:
    """The builds on ``shelf``, the one set aside last first."""
    return sorted(shelf.glob("*.fmu"), key=lambda p: p.stat().st_mtime_ns, reverse=True)


def take_back(path: Path) -> bool:
    """Move a current build of the FMU ``path`` from its shelf to ``path``: True if there was one."""
    shelf = _shelf(path)
    if not shelf.is_dir():
        return False
    for candidate in _shelved(shelf):
        if broken_fmu(candidate) is not None:
            candidate.unlink(missing_ok=True)
        elif stale_build(candidate) is None:
            os.replace(candidate, path)
            return True
    return False
