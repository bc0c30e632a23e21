"""Fixtures of the FMU tests: the FMUs built once per session, a venv without dtcosim, libpython."""

from __future__ import annotations

import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

from fmus.build import build_all


@pytest.fixture(scope="session")
def built_fmus(tmp_path_factory):
    """The three FMUs (preset table6) built once: ``{name: BuiltFmu}``."""
    out = tmp_path_factory.mktemp("fmus")
    return {b.name: b for b in build_all(out, "table6")}


@pytest.fixture(scope="session")
def fmu_dir(built_fmus) -> Path:
    """Directory holding WindSource.fmu, Gearbox.fmu and GeneratorRotor.fmu."""
    return next(iter(built_fmus.values())).path.parent


@pytest.fixture(scope="session")
def fmu_path(built_fmus):
    """``fmu_path(name)`` -> path of a built FMU."""
    return lambda name: built_fmus[name].path


@pytest.fixture(scope="session")
def bare_python(tmp_path_factory) -> Path:
    """Python of a fresh virtual environment with numpy, scipy and fmpy but not dtcosim."""
    env_dir = tmp_path_factory.mktemp("venv-without-dtcosim")
    venv.EnvBuilder(with_pip=True, system_site_packages=False).create(env_dir)
    python = env_dir / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "--quiet", "numpy", "scipy", "fmpy"], check=True,
                   capture_output=True, timeout=600)
    return python


@pytest.fixture(scope="session")
def libpython() -> Path:
    """The shared libpython of this interpreter (to LD_PRELOAD for C hosts such as libcosim)."""
    path = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")
    if not path.exists():
        pytest.skip(f"no shared libpython at {path}")
    return path


@pytest.fixture(scope="session")
def this_python() -> Path:
    return Path(sys.executable)
