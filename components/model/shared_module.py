"""A compiled-kernel module loaded once per process under a name keyed by its source, whoever ships it.

Every FMU build carries its own copy of the kernel sources in a private package
(``_dtcosim_gearbox_<build id>.components.model``), and the host has its own
(``components.model``). Imported normally, each copy is a separate module with a
build-specific name, and numba compiles and caches each one separately (about 20 s and
4-7 MB per Gearbox build). The kernel modules hold pure functions of their arguments,
so copies with the same source are the same code: :func:`load_shared` executes such a
module once per process as ``_dtcosim_<stem>_<digest>``, the digest covering the
module's own source and that of the project modules it imports, and every later
request, from any copy with the same sources, gets that module. numba's disk cache
(:mod:`components.model.numba_cache`) is keyed by that name, so a machine compiles a
kernel once per version of its sources, not once per FMU build.

The module's relative imports resolve in the package of the copy that loaded it first
(the digest guarantees the other copies' modules have the same source).
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType


def shared_name(path: Path, dependencies: tuple[str, ...]) -> str:
    """``_dtcosim_<stem>_<16 hex digits>``: the sha256 of ``path`` and of its ``dependencies`` (file names beside it)."""
    digest = hashlib.sha256()
    for file in (path, *(path.parent / name for name in dependencies)):
        digest.update(file.name.encode() + b"\0" + file.read_bytes() + b"\0")
    return f"_dtcosim_{path.stem}_{digest.hexdigest()[:16]}"


def load_shared(path: Path, package: str, dependencies: tuple[str, ...]) -> ModuleType:
    """The module of source ``path`` under its :func:`shared_name`, executed on the first request only.

    Parameters
    ----------
    path : pathlib.Path
        The module's file (e.g. ``.../components/model/compiled_kernel.py``).
    package : str
        The package of that copy (``__package__`` of the caller): the module's relative imports
        resolve there.
    dependencies : tuple of str
        File names, beside ``path``, of the project modules it imports; part of the digest.

    Raises
    ------
    Exception
        Whatever executing the module raises (e.g. ImportError without numba); nothing is kept then.
    """
    name = shared_name(path, dependencies)
    module = sys.modules.get(name)
    if module is not None:
        return module
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    module.__package__ = package
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


#: results of :func:`try_load_shared` per (file, dependencies): a module or the reason it could not load
_attempts: dict[tuple[str, tuple[str, ...]], tuple[ModuleType | None, str | None]] = {}


def try_load_shared(path: Path, package: str, dependencies: tuple[str, ...]) -> tuple[ModuleType | None, str | None]:
    """:func:`load_shared`, tried once per process: the module and None, or None and why it failed.

    For optional compiled modules: a failure (numba missing or broken) is remembered, not retried.
    """
    key = (str(path), dependencies)
    if key not in _attempts:
        try:
            _attempts[key] = (load_shared(path, package, dependencies), None)
        except Exception as exc:  # noqa: BLE001 - the caller runs its numpy path instead and says why
            _attempts[key] = (None, f"{type(exc).__name__}: {exc}")
    return _attempts[key]
