"""Handing freed memory back between the phases of a run (co-simulation, results file, analyses, plots).

A whole run holds its samples, the FMUs' code and the figures' libraries in one process
(Pillow; matplotlib where it draws the event or spectrum figures; numba's LLVM too where
the kernels run just in time; pyarrow only where the caller imported it:
:mod:`orchestrator.parquet_conversion`); what a phase allocates and frees would
otherwise stay in the process and add to the next phase's peak:

* matplotlib figures are reference cycles (figure <-> canvas <-> renderer), so their
  pixel buffers go only when the cyclic garbage collector runs (the run figures'
  renderer, :mod:`orchestrator.raster`, makes none);
* glibc's ``malloc`` keeps freed heap memory mapped (``malloc_trim`` returns it);
  the results files' buffers come from it too.

:func:`release_memory` does both; it changes no result. A full collection costs about
0.1 s in a run's process (matplotlib loaded), so a run calls it
only when it holds many samples (:func:`release_between_phases`), where it lowers the
peak of a 600 s paper run by ~20 MB (``bench_long_run.py``).
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


#: samples a run holds [bytes] above which its phases hand freed memory back (8 MB: a 200 s paper run)
LARGE_RUN_BYTES = 8_000_000


def release_between_phases(held_bytes: int) -> bool:
    """:func:`release_memory` if a run holds more than :data:`LARGE_RUN_BYTES` of samples; True if it ran."""
    if held_bytes <= LARGE_RUN_BYTES:
        return False
    release_memory()
    return True
