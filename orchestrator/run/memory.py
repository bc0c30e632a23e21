"""Handing freed memory back between the phases of a run (co-simulation, results file, analyses, plots).

A whole run holds its samples, the FMUs' code (numba's LLVM for the compiled gearbox
kernel), pyarrow and matplotlib in one process; what a phase allocates and frees
would otherwise stay in the process and add to the next phase's peak:

* matplotlib figures are reference cycles (figure <-> canvas <-> renderer), so their
  pixel buffers go only when the cyclic garbage collector runs;
* glibc's ``malloc`` keeps freed heap memory mapped (``malloc_trim`` returns it);
  the results files' buffers come from it too (pyarrow's own pool would keep them:
  :func:`orchestrator.columnar_files._memory_pool`).

:func:`release_memory` does both; it changes no result. ``bench_long_run.py``
measures what it saves.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import sys
from functools import lru_cache


@lru_cache(maxsize=1)
def _malloc_trim():
    """glibc's ``malloc_trim`` (None elsewhere: macOS, Windows, musl)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim = libc.malloc_trim
    except (OSError, AttributeError):
        return None
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    return trim


def release_memory() -> None:
    """Collect reference cycles and return the free heap to the OS (glibc; elsewhere only the first)."""
    gc.collect()
    trim = _malloc_trim()
    if trim is not None:
        trim(0)
