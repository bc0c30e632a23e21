"""One parser of import statements for kernels, FMU closures and FMU requirements: every import, parsed once per content."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from components.compile.import_statements import ImportStatement, import_statements

ROOT = Path(__file__).resolve().parents[2]

NESTED = '''
import a.b, c as d
from . import e
from ..f.g import h, i
def fn():
    import j
    class K:
        if x:
            from k import *
        else:
            try:
                import l
            except E:
                import m
            finally:
                import n
    with w:
        for _ in y:
            while z:
                import o
    match v:
        case 1:
            import p
x = lambda: __import__("not_a_statement")
'''


def test_every_kind_of_block_is_visited_and_each_statement_kept_whole():
    found = import_statements(NESTED, "nested.py")
    assert found[:3] == (ImportStatement(False, None, 0, ("a.b", "c"), 2), ImportStatement(True, None, 1, ("e",), 3),
                         ImportStatement(True, "f.g", 2, ("h", "i"), 4))
    assert [s.names[0] for s in found[3:]] == ["j", "*", "l", "m", "n", "o", "p"]
    assert found[4] == ImportStatement(True, "k", 0, ("*",), 9)


def _walked(code: bytes) -> list[tuple]:
    """What a walk over every node of the syntax tree finds (the slow way)."""
    out = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.Import):
            out.append((False, None, 0, tuple(a.name for a in node.names), node.lineno))
        elif isinstance(node, ast.ImportFrom):
            out.append((True, node.module, node.level, tuple(a.name for a in node.names), node.lineno))
    return sorted(out, key=repr)


@pytest.mark.parametrize("package", ["components", "fmus", "orchestrator"])
def test_the_project_s_modules_give_what_a_walk_over_every_node_gives(package):
    files = sorted((ROOT / package).rglob("*.py"))
    assert len(files) > 10
    for path in files:
        code = path.read_bytes()
        found = [(s.is_from, s.module, s.level, s.names, s.line) for s in import_statements(code, str(path))]
        assert sorted(found, key=repr) == _walked(code), path


def test_a_content_is_parsed_once_whatever_its_file_and_a_changed_one_again():
    first = import_statements(b"import numpy\n", "one.py")
    assert import_statements("import numpy\n", "two.py") is first  # the same answer, not parsed again
    assert import_statements(b"import scipy\n", "one.py")[0].names == ("scipy",)


def test_a_syntax_error_names_the_file():
    with pytest.raises(SyntaxError) as info:
        import_statements(b"import (\n", "broken_module.py")
    assert info.value.filename == "broken_module.py"
