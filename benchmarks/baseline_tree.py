"""Copies of the sources without their bytecode: another git revision's (``--baseline REV``), or this tree's as a
fresh clone would have it (the first run after install compiles dtcosim's modules: ``pip install -e .`` does not)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def archive_tree(revision: str, out_dir: Path) -> Path:
    """The files of git ``revision`` in ``out_dir/baseline-tree`` (``git archive``: the repository is not touched)."""
    tree, archive = out_dir / "baseline-tree", out_dir / "baseline.tar"
    subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", f"--output={archive}", revision], check=True,
                   capture_output=True)
    shutil.unpack_archive(archive, tree)
    return tree


def working_tree_copy(out_dir: Path) -> Path:
    """The files of this working tree that git tracks or would track (its changes included), without the bytecode
    its runs wrote, in ``out_dir`` (created)."""
    listed = subprocess.run(["git", "-C", str(REPO), "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            check=True, capture_output=True).stdout.decode().split("\0")
    for name in filter(None, listed):
        source = REPO / name
        if source.is_file():
            target = out_dir / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
    return out_dir
