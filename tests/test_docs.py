"""The documentation: the site builds with warnings as errors, the API reference covers every subpackage,
the README stays short, and every image in docs/ is made by a named command."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("components", "fmus", "orchestrator")


def _subpackages(top: str) -> list[str]:
    """``top.<name>`` for every folder of ``top`` with an ``__init__.py``."""
    return sorted(f"{top}.{p.parent.name}" for p in (ROOT / top).glob("*/__init__.py"))


def _tree_listing() -> set[str]:
    """Every path in the source tree outside the folders that tools and runs may write (venv, caches, results)."""
    skip = {".git", ".venv", "venv", "results", ".pytest_cache"}
    return {str(p.relative_to(ROOT)) for p in ROOT.rglob("*")
            if not (set(p.relative_to(ROOT).parts) & skip or "__pycache__" in p.parts or ".egg-info" in str(p))}


@pytest.mark.slow
def test_the_site_builds_strict_into_a_temporary_folder(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings_handlers.python")
    before = _tree_listing()
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(ROOT / "mkdocs.yml"), "--site-dir", str(tmp_path / "site")],
                          cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert "WARNING" not in proc.stderr, proc.stderr[-4000:]
    site = tmp_path / "site"
    assert (site / "index.html").is_file()
    for package in PACKAGES:  # the API reference rendered the docstrings
        page = (site / "api" / package / "index.html").read_text(encoding="utf-8")
        assert f'id="{package}' in page, package
    assert _tree_listing() == before, "the build wrote into the source tree"


@pytest.mark.parametrize("top", PACKAGES)
def test_every_subpackage_has_its_api_page(top):
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    parent = (ROOT / "docs" / "api" / f"{top}.md").read_text(encoding="utf-8")
    assert f"::: {top}\n" in parent
    for sub in _subpackages(top):
        page = ROOT / "docs" / "api" / f"{sub}.md"
        assert page.is_file(), f"add docs/api/{sub}.md (::: {sub}) and list it in mkdocs.yml's nav"
        assert f"::: {sub}\n" in page.read_text(encoding="utf-8"), page
        assert f"api/{sub}.md" in config, f"list docs/api/{sub}.md in mkdocs.yml's nav"
        name = sub.split(".")[1]
        assert f'"!^{name}$"' in parent, f"filter {name} out of docs/api/{top}.md (it has its own page)"


def test_the_readme_is_short_and_its_links_exist():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.encode("utf-8")) <= 15_000
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" not in target:
            assert (ROOT / target).exists(), target


def test_every_docs_image_is_made_by_the_figure_command():
    script = (ROOT / "benchmarks" / "make_docs_figures.py").read_text(encoding="utf-8")
    images = sorted(p.name for p in (ROOT / "docs" / "img").glob("*.png"))
    assert images
    for name in images:
        assert f'"{name}"' in script, f"docs/img/{name} is made by no command in benchmarks/make_docs_figures.py"
