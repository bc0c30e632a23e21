"""A kernel's files and digest (components.compile.sources): every relative import found, wherever it is written."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from components.compile import sources
from components.compile.sources import KernelSource
from components.model.kernel import KERNELS

NESTED = """\
from .a import x
import math


def f():
    from .b import y
    return y


if math.pi > 3:
    from . import c
else:
    from .d import z
try:
    from .e import w
except ImportError:
    from .f import v
finally:
    pass
for _ in range(1):
    with open(__file__):
        from .g import u
while False:
    from .h import t
class K:
    from .i import s
match 1:
    case 1:
        from .j import r
"""


def _walked(path: Path) -> list[str]:
    """The relative imports by a walk over every node (what the statement walk must find)."""
    stems = []
    for node in ast.walk(ast.parse(path.read_bytes())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            stems += [node.module.split(".")[0]] if node.module else [a.name for a in node.names]
    return sorted(s for s in stems if (path.parent / f"{s}.py").is_file())


def test_relative_imports_are_found_in_every_kind_of_block(tmp_path):
    entry = tmp_path / "entry.py"
    entry.write_text(NESTED)
    for stem in "abcdefghij":
        (tmp_path / f"{stem}.py").write_text("")
    assert sorted(sources._sibling_imports(entry)) == list("abcdefghij") == _walked(entry)
    source = KernelSource("nested", entry)
    assert [p.name for p in source.files] == [f"{s}.py" for s in "abcdefghij"] + ["entry.py"]


@pytest.mark.parametrize("kernel", KERNELS, ids=lambda k: k.name)
def test_the_packaged_kernels_find_what_a_walk_over_every_node_finds(kernel):
    for path in kernel.files:
        assert sorted(sources._sibling_imports(path)) == _walked(path), path.name


def test_copies_of_the_same_sources_are_the_same_kernel_and_an_edit_another(tmp_path):
    copies = []
    for name in ("one", "two"):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "entry.py").write_text("from .helper import h\n")
        (folder / "helper.py").write_text("def h():\n    return 1\n")
        copies.append(KernelSource("copy", folder / "entry.py"))
    assert copies[0].shared_name == copies[1].shared_name
    (tmp_path / "two" / "helper.py").write_text("def h():\n    return 2\n")
    assert KernelSource("copy", tmp_path / "two" / "entry.py").shared_name != copies[0].shared_name
