"""Where numba keeps the compiled gearbox kernel: one per-user directory keyed by the code hash.

numba's own cache lives next to the source file or under ``NUMBA_CACHE_DIR`` in a
folder named after the source file's *directory*. An FMU's sources are extracted
to a new temporary folder on every load, so that folder changes every run and
numba would compile again each time (seconds). :func:`enable_stable_cache` gives
the kernel's dispatchers a locator whose directory is

    <user cache>/dtcosim/numba-<numba version>/<sha256 of the kernel source>[:16]/<module name>

(``<user cache>``: ``$DTCOSIM_CACHE_DIR``, else ``$XDG_CACHE_HOME`` or
``~/.cache`` on POSIX, ``%LOCALAPPDATA%`` on Windows), and whose freshness stamp is
the same hash: any copy of the same kernel source, wherever it was extracted,
finds the machine code compiled by the first run. The module name is part of
the key because numba's cache refers to the module by name; the kernels are
loaded under a name keyed by their sources (:mod:`components.compile.jit`),
the same for the host and every FMU build, so a machine compiles each version once.
Nothing else numba caches in the process is affected.

This uses numba's cache classes (``numba.core.caching``), which are not public
API; if they change, :func:`enable_stable_cache` returns False and the kernel is
compiled in memory once per process instead (correct, only slower to start).

Loading from the cache is lighter than numba's own load (:func:`register_runtime_symbols`):
numba refreshes its whole compilation context before every cache load, which imports
and registers every numba implementation (array, list, dict, random, ... lowerings) and
compiles its runtime's LLVM module, about 45 MB of resident memory and 0.3 s that
running machine code read from disk does not need (issue 14, ``bench_long_run.py``).
"""

from __future__ import annotations

import hashlib
import importlib
import os
import sys
from pathlib import Path

from .user_cache import user_cache_root


def source_hash(path: str | os.PathLike) -> str:
    """sha256 of a source file's bytes, hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def cache_folder(version: str | None = None) -> Path:
    """``<user cache>/numba-<numba version>``: where numba ``version`` (default: the installed one, imported) keeps
    every kernel's machine code."""
    if version is None:
        import numba  # optional requirement: the compiled gearbox kernel

        version = numba.__version__
    return user_cache_root() / f"numba-{version}"


#: the folder of :func:`cache_folder` that holds the marks of :func:`warm_mark`
WARM_FOLDER = "warm"


def warm_mark(shared: str) -> Path | None:
    """The file that says numba's cache holds kernel ``shared``'s entry points for this Python, compiled just in time
    ahead of its runs (:func:`components.compile.aot.warm_just_in_time`); None where numba is not installed.

    Inside the numba version's folder, so that removing that folder removes the mark; found without importing numba.
    """
    from importlib import metadata

    try:
        version = metadata.version("numba")
    except metadata.PackageNotFoundError:
        return None
    return cache_folder(version) / WARM_FOLDER / f"{shared}.{sys.implementation.cache_tag}"


def kernel_cache_dir(source_path: str | os.PathLike, module_name: str) -> Path:
    """Cache directory of the kernel module ``module_name`` compiled from ``source_path``.

    Keyed by numba version, code hash and module name.
    """
    safe = "".join(c if c.isalnum() or c in "._-" else "_" for c in module_name)
    return cache_folder() / source_hash(source_path)[:16] / safe


def enable_stable_cache(dispatchers, source_path: str | os.PathLike, module_name: str) -> bool:
    """Make ``dispatchers`` (numba ``njit`` functions of one module) cache under :func:`kernel_cache_dir`.

    Returns
    -------
    bool
        True if the on-disk cache is in use; False if it could not be set up (the
        functions still compile, in memory).
    """
    try:
        from numba.core import caching  # optional requirement: the compiled gearbox kernel

        base_locator = getattr(caching, "_CacheLocator")
        impl = getattr(caching, "CompileResultCacheImpl")
        function_cache = getattr(caching, "FunctionCache")
        directory = kernel_cache_dir(source_path, module_name)
        stamp = source_hash(source_path)

        class _StableLocator(base_locator):
            def __init__(self, py_func, py_file):
                self._lineno = py_func.__code__.co_firstlineno
                self._py_file = py_file  # numba names it in its warning about a function it cannot cache

            def get_cache_path(self):
                return str(directory)

            def get_source_stamp(self):
                return stamp

            def get_disambiguator(self):
                return str(self._lineno)

            @classmethod
            def from_function(cls, py_func, py_file):
                locator = cls(py_func, py_file)
                locator.ensure_cache_path()
                return locator

        class _StableImpl(impl):
            _locator_classes = [_StableLocator]

        class _StableCache(function_cache):
            _impl_class = _StableImpl

            def load_overload(self, sig, target_context):
                # a cache miss returns None and numba compiles as usual (its compiler refreshes the context)
                if not register_runtime_symbols():
                    return super().load_overload(sig, target_context)
                with self._guard_against_spurious_io_errors():
                    return self._load_overload(sig, target_context)

        for dispatcher in dispatchers:
            dispatcher._cache = _StableCache(dispatcher.py_func)
        return True
    except Exception:  # noqa: BLE001 - any problem with numba's internals: compile in memory instead
        return False


#: numba versions (major, minor) whose runtime symbols the light cache load was tested to register completely
LIGHT_LOAD_TESTED = {("0", "68")}


def register_runtime_symbols() -> bool:
    """Make the C helpers of numba's runtime (NRT) known to the JIT linker, without compiling anything.

    That is all machine code loaded from the cache needs; numba's own cache load
    refreshes the whole compilation context first (every lowering registry imported
    and installed, the runtime's LLVM module compiled), which registers these symbols
    and, beyond them, only the hash secrets of ``numba.cpython.hashing`` (imported here
    too: 0.5 MB; tested, since a symbol missing at load would abort the process in LLVM).
    ``rtsys.initialize`` registers the same symbols before compiling its module, so
    registering them twice is harmless. Returns False (nothing done) if numba's
    internals are not as expected, or numba is not a version it was tested with
    (:data:`LIGHT_LOAD_TESTED`): numba's own load then.
    """
    try:
        import numba  # optional requirement: the compiled gearbox kernel

        # only where tested: a symbol missing at load aborts inside LLVM instead of raising
        if tuple(numba.__version__.split(".")[:2]) not in LIGHT_LOAD_TESTED:
            return False
        from numba.core.runtime import nrt  # optional requirement: the compiled gearbox kernel

        importlib.import_module("numba.cpython.hashing")  # registers its hash secrets on import

        if not nrt.rtsys._init:
            for name, address in nrt._nrt.c_helpers.items():
                nrt.ll.add_symbol(name if name.startswith("_") else "NRT_" + name, address)
        return True
    except Exception:  # noqa: BLE001 - numba's internals changed: its own (heavier) load instead
        return False
