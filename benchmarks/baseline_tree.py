"""The sources of another git revision, for benchmarks that measure against a baseline (``--baseline REV``)."""

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
