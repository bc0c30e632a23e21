"""A study point's code identity follows what its result depends on, not file names or folders."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import components
import fmus
import orchestrator
from orchestrator.study.prepare import code_version


@pytest.fixture
def tree(tmp_path):
    """A copy of the three packages: ``(root, packages mapping)``."""
    packages = {}
    for module in (components, orchestrator, fmus):
        src = Path(module.__file__).parent
        shutil.copytree(src, tmp_path / src.name, ignore=shutil.ignore_patterns("__pycache__", "*.fmu"))
        packages[src.name] = tmp_path / src.name
    return tmp_path, packages


def _append(path: Path, text: str) -> None:
    path.write_text(path.read_text() + text)


def test_the_installed_code_and_its_copy_have_one_version(tree):
    _, packages = tree
    assert code_version(packages) == code_version()


def test_moving_a_module_to_another_subpackage_keeps_the_version(tree):
    root, packages = tree
    before = code_version(packages)
    old = root / "orchestrator" / "study" / "measure_values.py"
    new = root / "orchestrator" / "cosim" / "measure_values.py"
    new.write_text(old.read_text().replace("from ..inputs.measures", "from ..inputs.measures"))
    old.unlink()
    engine = root / "orchestrator" / "study" / "engine.py"
    text = engine.read_text()
    assert "from .measure_values import" in text
    engine.write_text(text.replace("from .measure_values import", "from ..cosim.measure_values import"))
    assert code_version(packages) == before


@pytest.mark.parametrize("rel", ["orchestrator/run/plots.py", "orchestrator/study/report.py",
                                 "orchestrator/commands/run.py", "components/analysis/campbell.py"])
def test_code_a_point_never_runs_does_not_change_the_version(tree, rel):
    root, packages = tree
    before = code_version(packages)
    _append(root / rel, "\n\ndef _an_unrelated_edit():\n    return 1\n")
    assert code_version(packages) == before


def test_docstrings_and_comments_do_not_change_it_code_does(tree):
    root, packages = tree
    before = code_version(packages)
    contact = root / "components" / "model" / "contact.py"
    text = contact.read_text()
    contact.write_text(text.replace('"""Gear contact laws', '"""Gear contact laws (reworded)', 1) + "\n# a comment\n")
    assert code_version(packages) == before
    contact.write_text(text.replace("CONTACT_LOSS_THRESHOLD_N = 1.0", "CONTACT_LOSS_THRESHOLD_N = 2.0"))
    assert code_version(packages) != before


def test_a_new_dependency_counts_wherever_it_lives(tree):
    root, packages = tree
    before = code_version(packages)
    (root / "orchestrator" / "run" / "helper_new.py").write_text("FACTOR = 3.0\n")
    assert code_version(packages) == before  # nothing imports it yet
    _append(root / "orchestrator" / "study" / "engine.py", "\nfrom ..run.helper_new import FACTOR  # noqa\n")
    assert code_version(packages) != before
