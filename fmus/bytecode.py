"""The bytecode an FMU carries beside its Python sources (:func:`members`), compiled once per source and process.

An FMU is extracted into a new folder for each run, where Python would compile its modules
again every time; the build therefore packs each module's unchecked-hash pyc (PEP 552) beside it.
"""

from __future__ import annotations

import functools
import importlib.util
import types
import zipfile
from pathlib import Path


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
    Remembered: :func:`fmus.build.stage` writes the staged modules' bytecode and :func:`members` then asks for
    the same (source, name) pairs.
    """
    from importlib._bootstrap_external import _code_to_hash_pyc  # what py_compile itself writes with

    code = _renamed(compiled(source), filename)
    return bytes(_code_to_hash_pyc(code, importlib.util.source_hash(source), checked=False))


@functools.lru_cache(maxsize=512)
def compiled(source: bytes):
    return compile(source, "<embedded>", "exec", dont_inherit=True)


def _renamed(code, filename: str):
    """``code`` and every code object in it with ``co_filename`` = ``filename`` (as compiled under that name)."""
    consts = tuple(_renamed(c, filename) if isinstance(c, types.CodeType) else c for c in code.co_consts)
    return code.replace(co_filename=filename, co_consts=consts)
