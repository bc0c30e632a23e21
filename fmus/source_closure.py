"""Which source files a module needs: the static import closure within the project's packages.

Used for two questions whose answer must not depend on file names or folder layout:

* what an FMU carries (:mod:`fmus.build` embeds exactly the closure of its slave
  module, so its build id changes when that code changes and only then);
* what a study point's result depends on (:func:`orchestrator.study.prepare.code_version`).

Imports are read from the syntax tree (every ``import`` and ``from ... import``,
also those inside functions), resolved to modules of the packages given, and
followed recursively. Imports of other packages (numpy, scipy, fmpy, ...) end the walk.
"""

from __future__ import annotations

import ast
import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Mapping

from components.compile.import_statements import ImportStatement, import_statements


@dataclass(frozen=True)
class SourceModule:
    """One module of the closure.

    Attributes
    ----------
    name : str
        Dotted module name (``components.model.assembly``).
    path : pathlib.Path
        Its file (``__init__.py`` for a package).
    is_package : bool
    """

    name: str
    path: Path
    is_package: bool


def _locate(name: str, packages: Mapping[str, Path]) -> SourceModule | None:
    """The file of module ``name`` if it belongs to one of ``packages`` (top name -> directory)."""
    top, *rest = name.split(".")
    if top not in packages:
        return None
    base = Path(packages[top]).joinpath(*rest)
    if (base / "__init__.py").is_file():
        return SourceModule(name, base / "__init__.py", True)
    if base.with_suffix(".py").is_file() and rest:
        return SourceModule(name, base.with_suffix(".py"), False)
    return None


def _absolute(module: SourceModule, statement: ImportStatement) -> str:
    """The absolute module a statement imports from (``from ..x import y`` in ``a.b.c``: ``a.x``); "" for ``import``."""
    if not statement.is_from:
        return ""
    if not statement.level:
        return statement.module or ""
    package = module.name if module.is_package else module.name.rpartition(".")[0]
    parts = package.split(".")
    parts = parts[: len(parts) - (statement.level - 1)] if statement.level > 1 else parts
    return ".".join(parts + ([statement.module] if statement.module else []))


def _statements_of(module: SourceModule) -> tuple[ImportStatement, ...]:
    return import_statements(module.path.read_bytes(), str(module.path))


def _imports(module: SourceModule) -> list[list[str]]:
    """Per imported name of every import statement of ``module``: the absolute names it may be, most specific first."""
    out: list[list[str]] = []
    for statement in _statements_of(module):
        if not statement.is_from:
            for name in statement.names:
                parts = name.split(".")
                out.append([".".join(parts[:i]) for i in range(len(parts), 0, -1)])
            continue
        base = _absolute(module, statement)
        pieces = base.split(".")
        prefixes = [".".join(pieces[:i]) for i in range(len(pieces), 0, -1)]
        out += [[f"{base}.{name}", *prefixes] for name in statement.names if name != "*"]
        if "*" in statement.names:
            out.append(prefixes)
    return out


def direct_imports(name: str, packages: Mapping[str, Path]) -> set[str]:
    """The modules of ``packages`` that module ``name``'s import statements name (every one, also inside functions).

    Each imported name counts as the most specific module it resolves to: ``from .slaves import record``
    is ``fmus.slaves.record``, ``from .record import RECORD_FILE`` is ``fmus.slaves.record``. Parent
    packages run on the way are not counted (no ``__init__`` of this project imports anything).

    Raises
    ------
    LookupError
        If ``name`` is not a module of ``packages``.
    """
    mod = _locate(name, packages)
    if mod is None:
        raise LookupError(f"module {name!r} is not in the packages {', '.join(packages)}")
    out = set()
    for names in _imports(mod):
        found = next((dep for dep in (_locate(n, packages) for n in names) if dep is not None), None)
        if found is not None and found.name != name:
            out.add(found.name)
    return out


def import_closure(roots: Iterable[str], packages: Mapping[str, Path]) -> dict[str, SourceModule]:
    """Every module of ``packages`` reachable by import from the modules ``roots``.

    Parameters
    ----------
    roots : iterable of str
        Dotted names of the starting modules (each must be found in ``packages``).
    packages : mapping of str -> pathlib.Path
        Top-level package name -> its directory, e.g. ``{"components": Path(".../components")}``.

    Returns
    -------
    dict of str -> SourceModule
        By module name, sorted; the parent packages of every module are included.

    Raises
    ------
    LookupError
        If a root is not a module of ``packages``.
    """
    found: dict[str, SourceModule] = {}
    todo = []
    for root in roots:
        mod = _locate(root, packages)
        if mod is None:
            raise LookupError(f"module {root!r} is not in the packages {', '.join(packages)}")
        todo.append(mod)
    while todo:
        mod = todo.pop()
        if mod.name in found:
            continue
        found[mod.name] = mod
        parts = mod.name.split(".")
        candidates = [".".join(parts[:i]) for i in range(1, len(parts))]
        candidates += [name for names in _imports(mod) for name in names]  # every name a statement may mean
        for name in candidates:
            if name not in found:
                dep = _locate(name, packages)
                if dep is not None:
                    todo.append(dep)
    return dict(sorted(found.items()))


def _without_docstrings_and_imports(tree: ast.Module) -> ast.Module:
    """The tree with import statements and docstrings removed (they change no computed number)."""

    class Strip(ast.NodeTransformer):
        def generic_visit(self, node):
            super().generic_visit(node)
            body = getattr(node, "body", None)
            if isinstance(body, list):
                kept = [s for s in body if not isinstance(s, (ast.Import, ast.ImportFrom))]
                if kept and isinstance(kept[0], ast.Expr) and isinstance(kept[0].value, ast.Constant) \
                        and isinstance(kept[0].value.value, str):
                    kept = kept[1:]
                node.body = kept or [ast.Pass()]
            return node

    return Strip().visit(tree)


def behaviour_digest(modules: Mapping[str, SourceModule]) -> str:
    """SHA-256 of what the modules compute, independent of where they live.

    Each module contributes the dump of its syntax tree without docstrings,
    comments, formatting and import statements; the digests are combined in
    sorted order, so moving a module to another package (and rewriting the
    imports that name it) leaves the digest unchanged, while any change to code
    that runs changes it. Which modules take part is decided by
    :func:`import_closure`, so a new dependency is included wherever it lives.
    """
    digests = sorted(
        hashlib.sha256(ast.dump(_without_docstrings_and_imports(ast.parse(m.path.read_bytes()))).encode()).hexdigest()
        for m in modules.values()
    )
    return hashlib.sha256("\n".join(digests).encode()).hexdigest()
