"""Nothing is written into the source tree: after the commands a README user runs, ``git status`` of a checkout is clean.

The commands run in a fresh git checkout of this source tree (its packages ahead of the
installed ones), from its root as the README has them, with a per-user cache of their own
(``DTCOSIM_CACHE_DIR``) and no ``DTCOSIM_FMU_DIR``: the FMUs they build must go to that
cache, the results to ``results/`` (ignored), and nothing else may appear in the checkout.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[3]
#: what a checkout holds that the commands can write next to (the tests and docs are not needed to run them)
CHECKOUT = ("components", "fmus", "orchestrator", "build_fmus.py", "pyproject.toml", "README.md", ".gitignore")


def _git(*args: str, cwd: Path) -> str:
    return subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, check=True).stdout


@pytest.fixture(scope="module")
def checkout(tmp_path_factory) -> Path:
    """A git checkout of this source tree (its tracked and new files), committed, with nothing untracked."""
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    dest = tmp_path_factory.mktemp("checkout") / "dtcosim"
    listed = _git("ls-files", "-z", "--cached", "--others", "--exclude-standard", "--", *CHECKOUT, cwd=ROOT)
    for rel in filter(None, listed.split("\0")):
        source = ROOT / rel
        if source.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, dest / rel)
    _git("init", "-q", cwd=dest)
    _git("add", "-A", cwd=dest)
    _git("-c", "user.name=test", "-c", "user.email=test@example.org", "commit", "-q", "-m", "checkout", cwd=dest)
    assert _git("status", "--porcelain", "--untracked-files=all", cwd=dest) == ""
    return dest


def _user_cache(tmp_path: Path) -> Path:
    """A per-user cache of its own, sharing this one's compiled kernels (compiling them anew takes minutes)."""
    from components.compile.user_cache import user_cache_root

    cache = tmp_path / "user-cache"
    cache.mkdir()
    shared = user_cache_root() / "aot"
    shared.mkdir(parents=True, exist_ok=True)
    (cache / "aot").symlink_to(shared, target_is_directory=True)
    for jit in user_cache_root().glob("numba-*"):
        (cache / jit.name).symlink_to(jit, target_is_directory=True)
    return cache


def _run(checkout: Path, cache: Path, *argv: str) -> subprocess.CompletedProcess:
    """``argv`` (``dtcosim ...`` or ``python build_fmus.py ...``) from the checkout's root, with its packages."""
    env = {k: v for k, v in os.environ.items() if k not in ("DTCOSIM_FMU_DIR", "PYTHONPATH")}
    env.update(DTCOSIM_CACHE_DIR=str(cache), PYTHONPATH=str(checkout))
    if argv[0] == "dtcosim":
        argv = (sys.executable, "-c", "from orchestrator.commands.cli import console_main; console_main()", *argv[1:])
    else:
        argv = (sys.executable, *argv[1:])
    return subprocess.run(argv, cwd=checkout, env=env, capture_output=True, text=True, timeout=1200)


def test_readme_commands_write_nothing_into_the_checkout(checkout, tmp_path):
    cache = _user_cache(tmp_path)
    commands = [
        ("python", "build_fmus.py", "--fmu", "GeneratorRotor"),
        ("dtcosim", "build", "--fmu", "WindSource"),
        ("dtcosim", "build", "--drivetrain", "grc-like", "--fmu", "GeneratorRotor"),
        ("dtcosim", "run", "--stop", "0.1", "--no-plots", "--quiet"),
        ("dtcosim", "validate"),
        ("dtcosim", "export-ssp", "--out", "results/paper.ssp"),
    ]
    for argv in commands:
        proc = _run(checkout, cache, *argv)
        assert proc.returncode == 0, (argv, proc.stderr)
        # the code that ran is the checkout's, and everything it wrote outside results/ is in the cache
        assert _git("status", "--porcelain", "--untracked-files=all", cwd=checkout) == "", argv
    fmus = cache / "fmus"
    assert sorted(p.name for p in fmus.glob("*.fmu")) == ["Gearbox.fmu", "GeneratorRotor.fmu", "WindSource.fmu"]
    assert list(fmus.glob("drivetrains/grc-like-*/GeneratorRotor.fmu"))
    assert list(checkout.glob("results/paper-60s*/summary.json")) and (checkout / "results" / "paper.ssp").is_file()
    assert not list(checkout.rglob("*.fmu"))


def test_the_commands_run_the_checkouts_code(checkout, tmp_path):
    proc = _run(checkout, tmp_path, "python", "-c", "import fmus, orchestrator; print(fmus.__file__, orchestrator.__file__)")
    assert proc.returncode == 0, proc.stderr
    assert all(Path(p).is_relative_to(checkout) for p in proc.stdout.split()), proc.stdout
