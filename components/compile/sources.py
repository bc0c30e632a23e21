"""A kernel's sources: an entry module of a kernel package and the sibling modules it imports.

A kernel package (e.g. :mod:`components.model.kernel`) holds plain Python functions on
floats and arrays that import nothing but :mod:`math`, numpy and each other (relative
imports). Imported normally they run interpreted; :mod:`components.compile.jit` loads the
same files for numba and :mod:`components.compile.aot` compiles them ahead of time. Both
find the files through :class:`KernelSource`, whose :attr:`~KernelSource.digest` keys every
compiled form: any copy of the same sources (the host's, each FMU build's) is the same kernel.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from .import_statements import import_statements


def _relative_imports(code: bytes, filename: str) -> tuple[str, ...]:
    """First names of the modules ``code`` imports relatively from its own package, in order."""
    stems: list[str] = []
    for statement in import_statements(code, filename):
        if statement.is_from and statement.level == 1:
            stems += [statement.module.split(".")[0]] if statement.module else list(statement.names)
    return tuple(stems)


def _sibling_imports(path: Path) -> list[str]:
    """Stems of the modules beside ``path`` that it imports relatively (``from .x import ...``, ``from . import x``)."""
    stems = _relative_imports(path.read_bytes(), str(path))
    return [s for s in stems if (path.parent / f"{s}.py").is_file()]


@dataclass(frozen=True)
class KernelSource:
    """One kernel: its name and the file of its entry module.

    Attributes
    ----------
    name : str
        Short name (``"gearbox"``): part of every compiled module's name.
    entry : pathlib.Path
        The entry module's file (``.../components/model/kernel/step.py``); it declares
        ``AOT_EXPORTS`` if the kernel is compiled ahead of time.
    """

    name: str
    entry: Path

    @cached_property
    def files(self) -> tuple[Path, ...]:
        """The entry module and every sibling it imports, directly or not, dependencies first."""
        order: list[Path] = []
        visiting: set[Path] = set()

        def visit(path: Path) -> None:
            if path in order:
                return
            if path in visiting:
                raise ImportError(f"kernel modules import each other in a circle at {path.name}")
            visiting.add(path)
            for stem in _sibling_imports(path):
                visit(path.parent / f"{stem}.py")
            visiting.discard(path)
            order.append(path)

        visit(Path(self.entry))
        return tuple(order)

    @cached_property
    def digest(self) -> str:
        """sha256 (hex) of the names and contents of :attr:`files`."""
        h = hashlib.sha256()
        for path in sorted(self.files, key=lambda p: p.name):
            h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
        return h.hexdigest()

    @property
    def shared_name(self) -> str:
        """``_dtcosim_kernel_<name>_<16 hex digits of the digest>``: the name of this kernel version in any process."""
        return f"_dtcosim_kernel_{self.name}_{self.digest[:16]}"

    @property
    def module_stem(self) -> str:
        """The entry module's name inside its package (``"step"``)."""
        return Path(self.entry).stem
