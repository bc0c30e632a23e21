"""Work around pythonfmu 0.7's use-after-free at process exit (the "known shutdown race").

The pythonfmu C++ wrapper keeps its interpreter state in a global
``std::shared_ptr<PyState>`` and also registers a library destructor,
``finalizePythonInterpreter``, that resets that pointer. At process exit the
C++ static destructor runs first (``__cxa_atexit``) and frees the shared
pointer's control block; the library destructor then runs (``_dl_fini``) and
decrements the use count *in the freed block*. Whether that write corrupts the
heap depends on where glibc keeps the freed chunk: in a small bin it lands on
the ``bk`` pointer and the process aborts later with "corrupted double-linked
list" (in libgfortran's or OpenBLAS's destructors). It was rare (under 1 in 30
runs); with numba loaded (the compiled gearbox kernel) the heap at exit looks
different and it happened in most runs of an in-process host.

The fix: while the interpreter still runs (a Python ``atexit`` handler, which
runs before any C-level exit handler), call the library's exported
``finalizePythonInterpreter`` ourselves. The static is alive then, so the call
is well defined: it nulls the global pointer and drops its reference (any live
instance keeps its own). At exit the static destructor and the library
destructor then find a null pointer and do nothing.

Only for a Python host (``sys.orig_argv`` non-empty): when a C host embeds
Python through pythonfmu, Python is finalised *by* the PyState worker, and
releasing the state from inside that finalisation would join the thread from
itself.
"""

from __future__ import annotations

import atexit
import ctypes
import os
import sys
from pathlib import Path

_SHARED_SUFFIXES = (".so", ".dylib")
_registered: set[str] = set()


def _binaries(resources: str | os.PathLike) -> list[str]:
    """Shared libraries of the FMU whose ``resources`` folder is given (all platform folders)."""
    root = Path(resources).parent / "binaries"
    if not root.is_dir():
        return []
    return sorted(str(p) for p in root.glob("*/*") if p.suffix in _SHARED_SUFFIXES)


def _release(binary: str) -> None:
    """Call ``finalizePythonInterpreter`` of an already loaded pythonfmu library (never loads one)."""
    try:
        # RTLD_NOLOAD: only a library the host already loaded; matched by its load path, so this
        # works after the host removed the extracted FMU folder
        lib = ctypes.CDLL(binary, mode=os.RTLD_NOLOAD | os.RTLD_LAZY)
    except OSError:
        return
    finalize = getattr(lib, "finalizePythonInterpreter", None)
    if finalize is not None:
        finalize.restype = None
        finalize.argtypes = []
        finalize()


def _release_all(binaries: list[str]) -> None:
    for binary in binaries:
        try:
            _release(binary)
        except Exception:  # noqa: BLE001 - never fail an interpreter's shutdown
            pass


def register_state_release(resources: str | os.PathLike | None) -> None:
    """Arrange the early release of the pythonfmu state of this FMU's library at interpreter exit (once per library)."""
    if resources is None or os.name != "posix" or not getattr(sys, "orig_argv", None):
        return
    binaries = [b for b in _binaries(resources) if b not in _registered]
    if binaries:
        _registered.update(binaries)
        atexit.register(_release_all, binaries)
