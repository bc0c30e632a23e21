"""One build at a time in a folder of FMUs, and nothing left behind by a build that was killed.

:func:`fmus.build.build_fmu` writes an archive under a temporary folder
``.<Name>-building-<random>/`` inside the output folder and renames it to
``<Name>.fmu`` when whole. It does so holding :func:`build_lock` on the output
folder: an exclusive ``flock`` on the folder itself (no lock file of its own),
taken by every build into the folder and by the callers that decide what to
build (:mod:`orchestrator.provision`), so

* two builds into one folder (two ``dtcosim build``, or two runs that find the
  same FMUs missing) take turns, and the second finds the first's FMUs whole
  instead of building them again;
* a temporary folder found while the lock is held belongs to no running build:
  a build killed (SIGKILL, a power cut) before it could remove its own; it is
  removed (they accumulated, 2-3 MB each).

The lock is re-entrant within a process (a caller holding it may build), and
released with the process, so a killed holder never blocks the next build.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import threading
from pathlib import Path
from typing import Callable, Iterator

#: the middle of the temporary folder's name: ``.<Name>-building-<random>``
BUILDING_MARK = "-building-"

_held: dict[str, int] = {}
_guard = threading.Lock()


def building_prefix(name: str) -> str:
    """Prefix of the temporary folder a build of FMU ``name`` writes its archive in."""
    return f".{name}{BUILDING_MARK}"


def abandoned_builds(folder: str | Path) -> list[Path]:
    """The temporary folders of builds into ``folder`` (all abandoned while :func:`build_lock` is held)."""
    return sorted(p for p in Path(folder).glob(f".*{BUILDING_MARK}*") if p.is_dir() and not p.is_symlink())


@contextlib.contextmanager
def build_lock(folder: str | Path, report: Callable[[str], None] | None = None) -> Iterator[Path]:
    """Hold the exclusive build lock of ``folder`` (created if missing) for the ``with`` block.

    Parameters
    ----------
    folder : path
        The folder FMUs are built into.
    report : callable(str), optional
        Told once when another process holds the lock and this one waits for it.

    Yields
    ------
    pathlib.Path
        ``folder``. On taking the lock, the temporary folders of killed builds are removed.
    """
    import fcntl

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    key = os.path.realpath(folder)
    with _guard:
        nested = key in _held
        if nested:
            _held[key] += 1
    if nested:
        try:
            yield folder
        finally:
            with _guard:
                _held[key] -= 1
        return
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            if report is not None:
                report(f"waiting for another process building FMUs into {folder} ...")
            fcntl.flock(fd, fcntl.LOCK_EX)
        with _guard:
            _held[key] = 1
        for left in abandoned_builds(folder):
            shutil.rmtree(left, ignore_errors=True)
        try:
            yield folder
        finally:
            with _guard:
                _held.pop(key, None)
    finally:
        os.close(fd)
