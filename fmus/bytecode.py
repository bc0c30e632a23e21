"""The bytecode an FMU carries beside its Python sources (:func:`members`), compiled once per source and process.

An FMU is extracted into a new folder for each run, where Python would compile its modules
again every time; the build therefore packs each module's unchecked-hash pyc (PEP 552) beside it.
The build's own import of the staged modules takes the same bytecode from memory
(:func:`imported_from`).
"""

from __future__ import annotations

import contextlib
import functools
import importlib.machinery
import importlib.util
import sys
import types
import zipfile
from pathlib import Path
from typing import Iterable, Iterator


def members(fmu_path: Path) -> dict[str, bytes]:
    """The bytecode of every Python module in the FMU's ``resources/``, as archive members beside the sources.

    An FMU is extracted into a new folder for each run, where Python would compile its ~45
    modules again every time (~0.05 s per FMU). Each ``<module>.py`` therefore gets its
    ``__pycache__/<module>.<python tag>.pyc`` compiled by this interpreter as an *unchecked-hash* pyc
    (PEP 552): the same Python uses it without looking at the source's time stamp (the
    extraction sets new ones), another version ignores it and compiles the source. Derived
    from the sources like the compiled kernels, they leave the build id alone.
    """
    out = {}
    with zipfile.ZipFile(fmu_path) as archive:
        for member in archive.namelist():
            if member.startswith("resources/") and member.endswith(".py"):
                out[importlib.util.cache_from_source(member)] = unchecked_pyc(archive.read(member), member)
    return out


@functools.lru_cache(maxsize=256)
def unchecked_pyc(source: bytes, filename: str) -> bytes:
    """What ``py_compile`` writes for ``source`` as an unchecked-hash pyc whose code names ``filename``.

    The FMUs of one build embed mostly the same modules (under their own package names): each
    distinct source is compiled once per process (:func:`compiled`) and its code objects renamed.
    Remembered: :func:`fmus.build.stage` asks for the staged modules' bytecode (the build's own import takes it
    from memory) and :func:`members` then for the same (source, name) pairs.
    """
    from importlib._bootstrap_external import _code_to_hash_pyc  # what py_compile itself writes with

    code = _renamed(compiled(source), filename)
    return bytes(_code_to_hash_pyc(code, importlib.util.source_hash(source), checked=False))


@functools.lru_cache(maxsize=512)
def compiled(source: bytes) -> types.CodeType:
    """The code of module source ``source``, compiled once per process (named ``<embedded>``: see
    :func:`unchecked_pyc`)."""
    return compile(source, "<embedded>", "exec", dont_inherit=True)


def _renamed(code, filename: str):
    """``code`` and every code object in it with ``co_filename`` = ``filename`` (as compiled under that name)."""
    consts = tuple(_renamed(c, filename) if isinstance(c, types.CodeType) else c for c in code.co_consts)
    return code.replace(co_filename=filename, co_consts=consts)


class _MemoryBytecodeLoader(importlib.machinery.SourceFileLoader):
    """Python's loader of a source file, reading its bytecode from ``pycs`` (by ``__pycache__`` path) where it is
    there and writing none."""

    def __init__(self, fullname: str, path: str, pycs: dict[str, bytes]):
        super().__init__(fullname, path)
        self._pycs = pycs

    def get_data(self, path):
        pyc = self._pycs.get(path)
        return pyc if pyc is not None else super().get_data(path)

    def set_data(self, path, data, *, _mode=0o666):
        pass  # the staged folder stays as staged: pythonfmu copies it


class _MemoryBytecodeFinder:
    """Finds the modules under the top-level names ``tops`` as the path finder does, loaded by
    :class:`_MemoryBytecodeLoader`."""

    def __init__(self, pycs: dict[str, bytes], tops: Iterable[str]):
        self._pycs, self._tops = pycs, frozenset(tops)

    def find_spec(self, fullname, path=None, target=None):
        if fullname.partition(".")[0] not in self._tops:
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path, target)
        if spec is not None and type(spec.loader) is importlib.machinery.SourceFileLoader:
            spec.loader = _MemoryBytecodeLoader(fullname, spec.origin, self._pycs)
        return spec


@contextlib.contextmanager
def imported_from(pycs: dict[str, bytes], tops: Iterable[str]) -> Iterator[None]:
    """While in the block, modules under the top-level names ``tops`` imported from source files whose bytecode
    ``pycs`` holds (by the path of their ``__pycache__`` file, as :func:`importlib.util.cache_from_source` names it)
    load that bytecode instead of reading or writing a ``.pyc`` file; other modules import as usual."""
    finder = _MemoryBytecodeFinder(pycs, tops)
    sys.meta_path.insert(0, finder)
    try:
        yield
    finally:
        sys.meta_path.remove(finder)
