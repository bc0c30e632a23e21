"""FMUs unpacked once per content into the user cache, where every later run loads them as they are.

Loading an FMU needs its archive extracted (fmpy loads the binary from a folder, pythonfmu
imports the slave's modules from its ``resources/``). Extracting the paper scenario's three
FMUs decompresses and writes ~50 files each, and checking an archive before that reads every
member once more: 0.26 s of CPU in every run of it (``dtcosim run --no-plots``: 1.05 s against
0.80 s reusing the folders). So an FMU is unpacked once, into
``unpacked/<first 16 hex digits of its SHA-256>-<Python bytecode tag>/`` of the user cache
(:func:`components.compile.user_cache.user_cache_root`), and a run of an FMU with the same
content (the same SHA-256, which :func:`orchestrator.cosim.fmu_interface.read_fmu_interface`
computes anyway) loads that folder:

* **Whole or absent.** The FMU is extracted into a temporary folder beside it and renamed
  into place when whole: a folder under its final name holds every member, each read to its
  end and its CRC checked by ``zipfile``; two processes unpacking the same FMU at once both
  finish, one rename wins. Its archive is therefore known to be intact
  (:func:`is_unpacked`), and the member check before a run is not repeated.
* **Checked at each use.** The folder lists its files with their sizes (:data:`MANIFEST`,
  written before the rename); one whose files are not all there as listed (deleted or
  changed since) is never loaded: it is set aside and the FMU unpacked anew.
* **Held while used.** A process that loads a folder holds a shared lock (``flock``) on its
  :data:`MANIFEST` until it ends (a forked child shares it): an FMU's modules may import more of
  its files at any time of a run, however long.
* **Bounded.** Each use touches the folder; when a new one is added, those beyond the
  :data:`KEPT` most recently used are removed unless a process holds them (the remover takes
  the lock exclusively, without waiting, and moves the folder away before deleting it; a
  process that takes a folder checks after locking that it is still the one under that name).
  Where nothing can be locked (Windows, a file system without ``flock``), one used within the
  last hour is kept instead; a process using more than :data:`MAX_HELD` folders uses the
  others unlocked (its own pruning spares them, another's does not).
  ``dtcosim cache`` lists them.
* **Best effort.** Where the cache cannot be written (read-only, full) the FMU is
  extracted into a temporary folder of the run's own, as before, which goes when the process ends.

Nothing in the folder is written after the rename (fmpy and the slaves write nothing there,
numba caches in the user cache): the FMUs' modules come with their bytecode
(:func:`fmus.bytecode.members`), and what this interpreter would still compile (an FMU
built by another Python version) is compiled before the rename. The folder's name therefore
carries the interpreter's bytecode tag: another Python version unpacks a folder of its own.
"""

from __future__ import annotations

import atexit
import importlib.util
import json
import os
import py_compile
import shutil
import sys
import tempfile
import time
from pathlib import Path

from components.compile.user_cache import user_cache_root

try:
    import fcntl
except ImportError:  # Windows: no flock; folders used within the last hour are kept instead
    fcntl = None

#: the folder of the user cache holding the unpacked FMUs
FOLDER = "unpacked"
#: unpacked FMUs kept (the most recently used; 3-4 MB each)
KEPT = 32
#: without ``flock`` (Windows), an unpacked FMU used this recently [s] is never removed; a partial folder (being
#: unpacked, or set aside) is removed once this old
IN_USE_S = 3600.0
#: prefix of a folder being unpacked or set aside as damaged (never loaded; removed by a later unpacking once unused)
PARTIAL_PREFIX = ".unpacking-"
#: the file of an unpacked folder listing every other file with its size: a folder whose files are not all there
#: as listed (deleted or changed since) is never loaded, but set aside and unpacked anew
MANIFEST = ".members.json"

_temporary_root: Path | None = None
#: the folders this process uses: their manifest's open descriptor (the shared lock), None where it could not lock
#: it (its own pruning spares them all)
_held: dict[Path, int | None] = {}
#: the most folders a process holds (one open descriptor each); beyond, it uses them unlocked
MAX_HELD = 256


def store() -> Path:
    """Where FMUs are unpacked (not created here)."""
    return user_cache_root() / FOLDER


def folder_name(sha256: str) -> str:
    """The name of the unpacked folder of the FMU whose content has this SHA-256, for this interpreter."""
    return f"{sha256[:16]}-{sys.implementation.cache_tag}"


def _folder(sha256: str) -> Path:
    return store() / folder_name(sha256)


def is_unpacked(sha256: str) -> bool:
    """True if the FMU whose content has this SHA-256 is unpacked whole (its archive then reads without fault)."""
    return _folder(sha256).is_dir()


def unpacked(path: Path, sha256: str, extract, fallback: bool = True) -> Path | None:
    """The folder of the FMU ``path`` (content ``sha256``) unpacked whole, extracted by ``extract(path, folder)`` if not yet.

    ``extract`` raises what it raises (a damaged archive, a full disk); a folder it leaves
    behind is removed first. Where the cache cannot be written: a temporary folder of this process, or None
    without ``fallback``.
    """
    final = _folder(sha256)
    if final.is_dir():
        if _whole(final) and (final in _held or _hold(final)):
            _touch(final)
            return final
        _release(_held.pop(final, None))
        _set_aside(final)  # files deleted or changed since (or being removed): unpacked anew
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
        partial = Path(tempfile.mkdtemp(prefix=PARTIAL_PREFIX, dir=final.parent))
    except OSError:  # a read-only or full cache: a folder of this process's own
        return _extract_temporarily(path, sha256, extract) if fallback else None
    try:
        extract(path, partial)
        _compile_missing_bytecode(partial)
        _write_manifest(partial)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    _hold(partial)  # held across the rename: the folder is never unheld under its name
    try:
        os.rename(partial, final)
    except OSError:  # another process renamed its copy first (or the cache refuses): use that one, or our own
        _release(_held.pop(partial, None))
        if not final.is_dir() or not _hold(final):
            if not fallback:
                shutil.rmtree(partial, ignore_errors=True)
                return None
            return _keep_temporarily(partial)
        shutil.rmtree(partial, ignore_errors=True)
    else:
        _held[final] = _held.pop(partial, None)
    _prune(final.parent)
    return final


def _files(folder: Path) -> dict[str, int]:
    return {p.relative_to(folder).as_posix(): p.stat().st_size for p in folder.rglob("*")
            if p.is_file() and p.name != MANIFEST}


def _write_manifest(folder: Path) -> None:
    """List every file of ``folder`` with its size in :data:`MANIFEST` (before the rename: part of the folder)."""
    (folder / MANIFEST).write_text(json.dumps(_files(folder), sort_keys=True), encoding="utf-8")


def _whole(folder: Path) -> bool:
    """Every file :data:`MANIFEST` lists is there with its size (~1 ms for an FMU of ~150 files)."""
    try:
        listed = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        return all((folder / name).stat().st_size == size for name, size in listed.items())
    except (OSError, ValueError, AttributeError):  # no manifest, a missing file, a damaged manifest
        return False


def _set_aside(folder: Path) -> None:
    """Rename a damaged folder out of the way (a partial one's name: :func:`_prune` removes it once unused)."""
    try:
        os.rename(folder, folder.with_name(f"{PARTIAL_PREFIX}{folder.name}-damaged-{os.getpid()}"))
    except OSError:  # another process set it aside (or unpacked it anew) first
        pass


def _compile_missing_bytecode(folder: Path) -> None:
    """Bytecode for this interpreter of every module under ``resources/`` that has none (as the build makes it)."""
    for source in (folder / "resources").rglob("*.py"):
        cached = Path(importlib.util.cache_from_source(str(source)))
        if not cached.is_file():
            try:
                py_compile.compile(str(source), cfile=str(cached), doraise=True,
                                   invalidation_mode=py_compile.PycInvalidationMode.UNCHECKED_HASH)
            except py_compile.PyCompileError:  # the slave's import reports it, as for any FMU
                pass


def _lock(folder: Path, exclusive: bool) -> int | None:
    """The open descriptor of ``folder``'s manifest locked shared (or exclusively), without waiting; None where it is
    locked the other way or has no manifest.

    Raises
    ------
    OSError
        Nothing can be locked here: no ``flock`` (Windows), no descriptor left, a file system without locks.
    """
    if fcntl is None:
        raise OSError("no flock on this platform")
    try:
        fd = os.open(folder / MANIFEST, os.O_RDONLY)
    except FileNotFoundError:
        return None
    try:
        fcntl.flock(fd, (fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH) | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return None
    except OSError:
        os.close(fd)
        raise
    return fd


def _release(fd: int | None) -> None:
    if fd is not None:
        os.close(fd)


def _hold(folder: Path) -> bool:
    """Hold ``folder`` for the rest of this process (a shared lock on its manifest); False where it is being removed,
    or is no longer the folder that was locked. True without locking it where nothing can be locked, or where this
    process holds :data:`MAX_HELD` folders already (then only this process's pruning spares it)."""
    if len(_held) >= MAX_HELD:
        _held[folder] = None
        return True
    try:
        fd = _lock(folder, exclusive=False)
    except OSError:
        _held[folder] = None
        return True
    if fd is None:
        return False
    try:
        same = os.fstat(fd).st_ino == (folder / MANIFEST).stat().st_ino  # not moved away meanwhile
    except OSError:
        same = False
    if not same:
        os.close(fd)
        return False
    _held[folder] = fd
    return True


def in_use(folder: Path) -> bool:
    """True if a process holds ``folder`` (one without its manifest cannot be held: it is never loaded); where nothing
    can be locked, if it was used or set aside within the last :data:`IN_USE_S`."""
    if folder in _held:
        return True
    try:
        fd = _lock(folder, exclusive=True)
    except OSError:
        return _recent(folder)
    _release(fd)
    return fd is None and (folder / MANIFEST).is_file()


def _recent(folder: Path) -> bool:
    try:
        return time.time() - folder.stat().st_mtime <= IN_USE_S
    except OSError:
        return False


def _touch(folder: Path) -> None:
    try:
        os.utime(folder)
    except OSError:
        pass


def _extract_temporarily(path: Path, sha256: str, extract) -> Path:
    global _temporary_root
    if _temporary_root is None:
        _temporary_root = Path(tempfile.mkdtemp(prefix="dtcosim-fmus-"))
        atexit.register(shutil.rmtree, _temporary_root, True)
    target = _temporary_root / sha256[:16]
    if not target.is_dir():
        try:
            extract(path, target)
        except BaseException:
            shutil.rmtree(target, ignore_errors=True)
            raise
    return target


def _keep_temporarily(folder: Path) -> Path:
    atexit.register(shutil.rmtree, folder, True)
    return folder


def _prune(root: Path) -> None:
    """Remove the unpacked FMUs beyond the :data:`KEPT` most recently used that no process holds, and partial folders
    abandoned :data:`IN_USE_S` ago."""
    now = time.time()
    try:
        entries = [(p, p.stat().st_mtime) for p in root.iterdir() if p.is_dir()]
    except OSError:
        return
    whole = sorted(((p, t) for p, t in entries if not p.name.startswith(PARTIAL_PREFIX)), key=lambda e: -e[1])
    for folder, _ in whole[KEPT:]:
        if folder not in _held:
            remove_unheld(folder)
    for folder, made in entries:
        if folder.name.startswith(PARTIAL_PREFIX) and now - made > IN_USE_S:
            shutil.rmtree(folder, ignore_errors=True)


def remove_unheld(folder: Path) -> None:
    """Remove ``folder`` unless a process holds it: locked exclusively, moved out of the way, deleted (one without its
    manifest, which no process can hold or load, at once). Where nothing can be locked: once unused for an hour."""
    try:
        fd = _lock(folder, exclusive=True)
    except OSError:
        if not _recent(folder):
            shutil.rmtree(folder, ignore_errors=True)
        return
    if fd is None and (folder / MANIFEST).is_file():  # held by a process
        return
    try:
        gone = folder.with_name(f"{PARTIAL_PREFIX}{folder.name}-removed-{os.getpid()}")
        os.rename(folder, gone)
    except OSError:
        return
    finally:
        _release(fd)
    shutil.rmtree(gone, ignore_errors=True)
