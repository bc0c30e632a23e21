"""``dtcosim cache [--prune]``: what the per-user cache of compiled code and unpacked FMUs holds, and removing what is stale.

The cache (:func:`components.compile.user_cache.user_cache_root`, ``~/.cache/dtcosim``) keeps
the kernels compiled ahead of time (``aot/<python tag>-numpy<version>/``, one module per
kernel version: :mod:`components.compile.aot`, with the log of their last build), numba's
just-in-time machine code (``numba-<numba version>/<source hash>/``), the FMU binary
(``native/<source and compiler hash>/``: :mod:`fmus.binary`) and the FMUs runs have unpacked
(``unpacked/<content hash>-<Python tag>/``: :mod:`orchestrator.cosim.unpacked_fmus`). Every new version of a
kernel's or the binary's sources adds entries (with, for each, the reason its ahead-of-time build failed, or
the mark that numba's cache holds it compiled just in time) and nothing removes the old ones: ``--prune`` deletes
every entry that the installed dtcosim, Python, numpy, numba and C compiler would not load (FMUs carry their own compiled
modules and binary, so an older FMU keeps running; a later run rebuilds what it needs), and every unpacked
FMU that is not one of the FMU folder's (:func:`orchestrator.provision.folders.default_fmu_dir`;
a later run of it unpacks it again) unless a process holds it (a run is loading it). The FMU folder itself
(``fmus/`` where no other is chosen) is the FMUs dtcosim builds: its size is printed, and its folders of FMUs built
from drivetrain files and load records (one per content: every edit of a file adds one) are listed, stale when no
command used them for :data:`~orchestrator.provision.folders.UNUSED_DAYS` days (a later run builds them again).
"""

from __future__ import annotations

import argparse
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from components.compile.aot import aot_directory, build_log, failure_file
from components.compile.numba_cache import WARM_FOLDER, cache_folder, source_hash, warm_mark
from components.compile.user_cache import user_cache_root
from components.model.kernel import KERNELS
from fmus.binary import CACHE_FOLDER as NATIVE_FOLDER
from fmus.binary import cached_binary

from ..cosim.compiled_kernels import aot_kernels
from ..cosim.fmu_interface import file_sha256
from ..cosim.unpacked_fmus import FOLDER as UNPACKED_FOLDER
from ..cosim.unpacked_fmus import folder_name, in_use, remove_unheld
from ..provision.folders import UNUSED_DAYS, content_folders, default_fmu_dir, last_used
from .catalogue import help_line


@dataclass(frozen=True)
class CacheEntry:
    """One file or folder of the cache: its path, size [bytes] and whether the installed code uses it."""

    path: Path
    size_bytes: int
    current: bool


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def _jit_keys() -> tuple[str | None, set[str]]:
    """numba's version directory name and the source hashes of the kernels its cache is keyed by."""
    try:
        folder = cache_folder()  # numba is an optional requirement: only to name the current just-in-time cache
    except ImportError:
        return None, set()
    files = {f for k in KERNELS for f in k.files} | {k.source for k in aot_kernels() if k.source is not None}
    return folder.name, {source_hash(f)[:16] for f in files}


def cache_entries(root: Path | None = None) -> list[CacheEntry]:
    """Every module of ``aot/``, every kernel folder of ``numba-*/``, every FMU binary and every unpacked FMU, marked
    current or stale."""
    root = Path(root or user_cache_root())
    entries = []
    current_aot_dir = aot_directory()
    current_files = {k.file().name for k in aot_kernels()} | {failure_file(k).name for k in aot_kernels()}
    for folder in sorted((root / "aot").glob("*")):
        for path in sorted(p for p in folder.iterdir() if not p.name.startswith(".")):  # a build's own files
            current = folder == current_aot_dir and (path.name in current_files or path == build_log())
            entries.append(CacheEntry(path, _size(path), current))
    numba_dir, hashes = _jit_keys()
    marks = {warm_mark(k.shared) for k in aot_kernels()}
    for folder in sorted(root.glob("numba-*")):
        for kernel_dir in sorted(p for p in folder.iterdir() if p.is_dir() and p.name != WARM_FOLDER):
            current = folder.name == numba_dir and kernel_dir.name in hashes
            entries.append(CacheEntry(kernel_dir, _size(kernel_dir), current))
        for mark in sorted((folder / WARM_FOLDER).glob("*")):  # what the runs of a machine without C compiler load
            entries.append(CacheEntry(mark, _size(mark), mark in marks))
    binary = cached_binary()
    for folder in sorted(p for p in (root / NATIVE_FOLDER).glob("*") if p.is_dir()):
        entries.append(CacheEntry(folder, _size(folder), binary is not None and folder == binary.parent))
    fmu_dir = default_fmu_dir()
    if fmu_dir.is_dir():  # the drivetrain files' and load records' FMUs no command used for UNUSED_DAYS days
        since = time.time() - UNUSED_DAYS * 86400.0
        entries += [CacheEntry(p, _size(p), last_used(p) >= since) for p in content_folders(fmu_dir)]
    unpacked = sorted(p for p in (root / UNPACKED_FOLDER).glob("*") if p.is_dir())
    if unpacked:
        built = {folder_name(file_sha256(p)) for p in fmu_dir.rglob("*.fmu") if p.is_file()}
        entries += [CacheEntry(p, _size(p), p.name in built or in_use(p)) for p in unpacked]
    return entries


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``cache`` subcommand."""
    p = sub.add_parser("cache", help=help_line("cache"),
                       description=__doc__.splitlines()[0].split(": ", 1)[1])
    p.add_argument("--prune", action="store_true",
                   help="delete every entry the installed dtcosim, Python, numpy, numba and C compiler would not load, "
                        "the unpacked FMUs no run holds that are not the FMU folder's, and the FMU folder's drivetrain "
                        f"and load record FMUs no command used for {UNUSED_DAYS} days")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print the entries (and prune the stale ones with ``--prune``)."""
    root = user_cache_root()
    entries = cache_entries(root)
    print(f"cache: {root}")
    if not entries:
        print("  (empty)")
        return 0
    for e in entries:
        print(f"  {'current' if e.current else 'stale  '}  {e.size_bytes / 1e6:7.2f} MB  {_shown(e.path, root)}")
    stale = [e for e in entries if not e.current]
    total = sum(e.size_bytes for e in entries) / 1e6
    print(f"{len(entries)} entries, {total:.1f} MB; stale: {len(stale)}, {sum(e.size_bytes for e in stale) / 1e6:.1f} MB")
    if args.prune:
        for e in stale:
            if e.path.parent == root / UNPACKED_FOLDER:
                remove_unheld(e.path)  # unless a run has taken it since it was listed
            elif e.path.is_dir():
                _remove_folder(e.path)
            else:
                e.path.unlink(missing_ok=True)
        for folder in [*(root / "aot").glob("*"), *root.glob(f"numba-*/{WARM_FOLDER}"), *root.glob("numba-*"),
                       root / NATIVE_FOLDER, root / UNPACKED_FOLDER]:
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
        print(f"pruned {len(stale)} stale entries")
    elif stale:
        print("`dtcosim cache --prune` removes the stale entries")
    fmu_dir = default_fmu_dir()
    if fmu_dir.is_dir():
        print(f"FMU folder {fmu_dir}: {_size(fmu_dir) / 1e6:.1f} MB (the FMUs runs build; of its drivetrain and load "
              f"record folders, those no command used for {UNUSED_DAYS} days are stale)")
    return 0


def _shown(path: Path, root: Path) -> str:
    """``path`` relative to the cache where it is in it (the FMU folder may be elsewhere: $DTCOSIM_FMU_DIR)."""
    return str(path.relative_to(root)) if path.is_relative_to(root) else str(path)


def _remove_folder(path: Path) -> None:
    """Remove ``path``: renamed away first, so that a command building into it meanwhile starts a new folder."""
    gone = path.with_name(f".removing-{path.name}")
    try:
        path.rename(gone)
    except OSError:
        return
    shutil.rmtree(gone, ignore_errors=True)
