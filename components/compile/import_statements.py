"""The import statements of a Python source, parsed once per process and content.

Three questions read a module's imports: which sibling modules a kernel needs
(:mod:`components.compile.sources`), which project modules an FMU carries or a study
result depends on (:mod:`fmus.source_closure`) and which third-party packages an FMU
requires (:mod:`fmus.requirements`). They share this one parser. It visits statements
only - an import is a statement, so it is found in the bodies of modules, functions,
classes, ``if``/``try``/``with``/loops and ``match`` cases, never inside an
expression - about a tenth of the nodes a walk over the whole syntax tree visits, and
it keeps each answer under the content's sha256: the copies of a module that every FMU
of one build embeds (under their own package names) are parsed once.
"""

from __future__ import annotations

import ast
import hashlib
from dataclasses import dataclass
from typing import Iterator

#: the fields of a statement that hold statements (an import is a statement, found only in these),
_BODIES = ("body", "cases", "handlers", "orelse", "finalbody")  # in source order

#: the answers of this process by the sha256 of the source
_PARSED: dict[bytes, tuple["ImportStatement", ...]] = {}


@dataclass(frozen=True)
class ImportStatement:
    """One ``import`` or ``from ... import`` statement.

    Attributes
    ----------
    is_from : bool
        ``from MODULE import NAMES`` (else ``import NAMES``).
    module : str or None
        ``MODULE`` of a ``from`` statement, None for ``from . import x`` and for ``import`` statements.
    level : int
        The leading dots of a ``from`` statement (0: absolute).
    names : tuple of str
        The names imported: dotted modules of ``import a.b, c``; ``NAMES`` of a ``from`` statement (``*`` too).
    line : int
        Its first line (1-based).
    """

    is_from: bool
    module: str | None
    level: int
    names: tuple[str, ...]
    line: int


def statements(body: list) -> Iterator[ast.stmt]:
    """Every statement of ``body`` and, depth first, of the bodies nested in it."""
    for node in body:
        yield node
        for field in _BODIES:
            inner = getattr(node, field, None)
            if inner:
                yield from statements(inner)


def import_statements(code: bytes | str, filename: str = "<source>") -> tuple[ImportStatement, ...]:
    """The import statements of ``code`` in source order (every one, also those inside functions).

    Raises
    ------
    SyntaxError
        If ``code`` is not Python (``filename`` names it).
    """
    data = code.encode("utf-8") if isinstance(code, str) else code
    key = hashlib.sha256(data).digest()
    found = _PARSED.get(key)
    if found is None:
        out = []
        for node in statements(ast.parse(data, filename=filename).body):
            if isinstance(node, ast.Import):
                out.append(ImportStatement(False, None, 0, tuple(a.name for a in node.names), node.lineno))
            elif isinstance(node, ast.ImportFrom):
                out.append(ImportStatement(True, node.module, node.level, tuple(a.name for a in node.names),
                                           node.lineno))
        found = _PARSED[key] = tuple(out)
    return found
