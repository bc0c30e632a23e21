"""Session fixtures of the whole suite: the project's FMUs and the toy FMUs, each built once.

``tests/`` mirrors the source tree (``components/{model,reference,analysis}``,
``fmus``, ``orchestrator/{inputs,cosim,interop,run,study,commands}``); plain helpers
are in :mod:`tests.helpers`.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import venv
from pathlib import Path

import pytest

from components.compile.user_cache import CACHE_VARIABLE, user_cache_root
from tests.helpers.scenarios import TOY_SCENARIO, dtcosim, write_scenario


def _compiled_code_folders() -> list[str]:
    """The folders of the per-user cache holding compiled code, keyed by its sources: the kernels compiled ahead of
    time, the FMU binaries and numba's machine code (where numba is installed)."""
    from components.compile.aot import aot_directory
    from components.compile.numba_cache import cache_folder
    from fmus.binary import CACHE_FOLDER

    names = [aot_directory().parent.name, CACHE_FOLDER]
    try:
        names.append(cache_folder().name)
    except ImportError:
        pass
    return names


def pytest_configure(config):
    """The session's own per-user cache (``DTCOSIM_CACHE_DIR``, removed at its end), sharing only the compiled code
    of the user's: the tests build and unpack hundreds of FMUs (~2 GB unpacked) that are no one's after the
    session. Where ``DTCOSIM_CACHE_DIR`` is set already (a worker of a parallel run inherits the controller's),
    everything goes there."""
    if os.environ.get(CACHE_VARIABLE):
        return
    users = user_cache_root()
    session = Path(tempfile.mkdtemp(prefix="dtcosim-test-cache-"))
    for name in _compiled_code_folders():
        try:
            (users / name).mkdir(parents=True, exist_ok=True)
        except OSError:  # a read-only home: the session compiles into its own cache
            continue
        (session / name).symlink_to(users / name, target_is_directory=True)
    os.environ[CACHE_VARIABLE] = str(session)
    config.add_cleanup(lambda: shutil.rmtree(session, ignore_errors=True))


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """In a parallel run (``-n 2``), the controller compiles the kernels once before its workers start
    (:mod:`tests.helpers.kernels`); a serial run compiles them as its tests first need them."""
    if hasattr(session.config, "workerinput") or not getattr(session.config.option, "numprocesses", None):
        return
    from tests.helpers.kernels import compile_once

    compile_once()


@pytest.fixture(scope="session")
def built_fmus(tmp_path_factory):
    """The project's three FMUs (preset table6) built once for the whole suite: ``{name: BuiltFmu}``.

    Tests only read them; a test that needs changed FMUs builds its own.
    """
    from fmus.build import build_all
    from orchestrator.cosim.compiled_kernels import ensure_compiled_kernels

    ensure_compiled_kernels()  # the kernels compiled ahead of time (as `dtcosim build` and `run` do)
    out = tmp_path_factory.mktemp("fmus")
    return {b.name: b for b in build_all(out, "table6")}


@pytest.fixture(scope="session")
def fmu_dir(built_fmus) -> Path:
    """Directory holding WindSource.fmu, Gearbox.fmu and GeneratorRotor.fmu (read only)."""
    return next(iter(built_fmus.values())).path.parent


@pytest.fixture(scope="session")
def fmu_path(built_fmus):
    """``fmu_path(name)`` -> path of a built FMU."""
    return lambda name: built_fmus[name].path


@pytest.fixture(scope="session")
def toy_dir(tmp_path_factory) -> Path:
    """Directory with the toy FMUs (ToySine.fmu, ToyIntegrator.fmu, ...), built once."""
    from tests.helpers.toy_fmus import build_toys

    out = tmp_path_factory.mktemp("toys")
    build_toys(out)
    return out


@pytest.fixture
def toy_scenario(toy_dir, tmp_path):
    """``make(text=TOY_SCENARIO)`` -> path of a scenario file next to copies of the toy FMUs."""
    for fmu in toy_dir.glob("*.fmu"):
        shutil.copy(fmu, tmp_path / fmu.name)

    def make(text: str = TOY_SCENARIO, name: str = "scenario.toml") -> Path:
        return write_scenario(tmp_path, text, name)

    return make


@pytest.fixture(scope="session")
def paper_run(tmp_path_factory):
    """``dtcosim run`` with no arguments, once per session, into a fresh directory.

    ``DTCOSIM_FMU_DIR`` points to an empty directory, so the run also builds the
    missing FMUs. Returns ``(results directory, summary dict, completed process)``.
    """
    work = tmp_path_factory.mktemp("paper-run")
    fmu_dir = work / "fmus"
    fmu_dir.mkdir()
    proc = dtcosim("run", cwd=work, env={"DTCOSIM_FMU_DIR": str(fmu_dir)}, timeout=900)
    assert proc.returncode == 0, proc.stderr
    out = work / "results" / "paper-60s"
    summary = json.loads((out / "summary.json").read_text())
    return out, summary, proc


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
def requirements_python(tmp_path_factory, fmu_dir) -> Path:
    """Python of a fresh virtual environment holding only the FMUs' declared requirements and fmpy.

    Made by ``fmus.selftest.create_environment`` (what ``dtcosim validate --host`` uses),
    with the declared packages pinned by constraints to the versions installed here (the
    versions the FMUs were built and tested with), so results can be compared bit for bit.
    """
    from importlib import metadata

    from fmus.requirements import read_from_fmu
    from fmus.selftest import create_environment

    fmus = sorted(fmu_dir.glob("*.fmu"))
    pins = sorted({f"{p.distribution}=={metadata.version(p.distribution)}"
                   for path in fmus for p in read_from_fmu(path).packages})
    return create_environment(tmp_path_factory.mktemp("venv-declared-requirements"), fmus, pins)


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


@pytest.fixture
def write_study(tmp_path):
    """``write_study(text, name="study.toml")`` -> path of a study file in a fresh directory."""

    def make(text: str, name: str = "study.toml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return make
