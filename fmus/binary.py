"""The linux64 binary of the dtcosim FMUs: ``fmus/native/*.c``, compiled here, and the Python it finds.

pythonfmu's own binary (its C++ wrapper) does not link libpython, so a C host must preload it
(``LD_PRELOAD``) and set ``PYTHONPATH``, and it corrupts the heap the host finds at exit (issue 32).
``fmus/native/`` replaces it on linux64: FMI 2.0 Co-Simulation in C that runs the same Python
slave through the CPython C API, finding and starting Python itself (its module comment says
how). The build (:func:`fmus.build.build_fmu`) puts three things into each FMU:

* ``binaries/linux64/<model>.so``: this file compiled (:func:`compiled_binary`; cached in the
  user cache by the sources' hash; ``cc -shared -fPIC -O2 -fvisibility=hidden``, the compiler the
  compiled kernels need). Without a C compiler the FMU keeps pythonfmu's binary and the build says so;
* ``resources/python.txt`` (:func:`python_record`): the building Python's ``libpython``, home
  (``sys.base_prefix``), version and site-packages, where the binary looks first;
* ``resources/slaveclass.txt``: the slave's class name in the entry module
  (``resources/slavemodule.txt``, written by pythonfmu).

The other platforms' binaries (``win64``) stay pythonfmu's.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import signal
import subprocess
import sys
import sysconfig
import tempfile
import threading
from pathlib import Path
from typing import Iterator

from components.compile.c_compiler import INSTALL_HINT, c_compiler
from components.compile.user_cache import user_cache_root

#: the C sources of the binary (the FMI functions, an instance, the Python runtime) and their header
NATIVE_DIR = Path(__file__).with_name("native")
SOURCES = ("dtcosim_fmi2.c", "instance.c", "python_runtime.c")
HEADER = "dtcosim_fmu.h"
#: resource files the binary reads
PYTHON_FILE = "python.txt"
CLASS_FILE = "slaveclass.txt"
#: the folder of the user cache holding the compiled binaries, one folder per source and compiler, and the file there
CACHE_FOLDER = "native"
BINARY_FILE = "dtcosim_fmi2.so"
#: the FMU member the binary replaces
BINARY_FOLDER = "binaries/linux64"
#: one compile at a time in a process (and one at a time across processes: :func:`_one_compiler`)
_COMPILING = threading.Lock()


class NativeBuildError(RuntimeError):
    """The binary could not be compiled (the message says why and what to install)."""


def libpython() -> Path | None:
    """The shared libpython of this interpreter, or None (a statically linked Python has none)."""
    name = sysconfig.get_config_var("LDLIBRARY") or ""
    libdir = sysconfig.get_config_var("LIBDIR") or ""
    if not name.endswith(".so") and ".so." not in name:
        return None
    path = Path(libdir) / name
    return path if path.is_file() else None


def site_folders() -> list[str]:
    """The site-packages of this environment (purelib, platlib), where numpy and scipy are."""
    paths = sysconfig.get_paths()
    return list(dict.fromkeys(str(Path(paths[k]).resolve()) for k in ("purelib", "platlib") if paths.get(k)))


def python_record() -> str:
    """``resources/python.txt``: ``key=value`` lines the binary reads (libpython, home, version, path...)."""
    lib = libpython()
    lines = [f"libpython={'' if lib is None else lib}", f"home={sys.base_prefix}",
             f"version={sys.version_info.major}.{sys.version_info.minor}"]
    lines += [f"path={p}" for p in site_folders()]
    return "\n".join(lines) + "\n"


def compiler() -> str | None:
    """A C compiler (:func:`components.compile.c_compiler.c_compiler`)."""
    return c_compiler()


def source_digest() -> str:
    """16 hex digits of the binary's source: part of every FMU's build id (a changed binary rebuilds the FMUs)."""
    return hashlib.sha256(_source_bytes()).hexdigest()[:16]


def _source_bytes() -> bytes:
    return b"\0".join((NATIVE_DIR / name).read_bytes() for name in (*SOURCES, HEADER))


def compiled_binary() -> Path:
    """The compiled binary (built once per source version into the user cache).

    Raises
    ------
    NativeBuildError
        No C compiler, or the compiler failed (its output in the message).
    OSError
        The user cache cannot be written (:func:`binary_bytes` then compiles it for the process).
    """
    if not sys.platform.startswith("linux"):
        raise NativeBuildError(f"the dtcosim FMU binary is built for linux64 only (this is {sys.platform})")
    source = _source_bytes()
    cc = compiler()
    if cc is None:
        raise NativeBuildError(f"no C compiler (cc, gcc or clang) to build the FMU binary: {INSTALL_HINT}")
    target = _target(source, cc)
    if target.is_file():
        return target
    # one at a time: a thread of this process, another process (a forked builder, a compile started by
    # start_compile, which holds the lock until it has ended)
    with _COMPILING, _one_compiler(target.parent):
        return target if target.is_file() else _compile(cc, target)


#: the binary compiled by this process where the user cache cannot be written, by source and compiler
_compiled_here: dict[str, bytes] = {}


def binary_bytes() -> bytes:
    """The compiled binary's content: :func:`compiled_binary`'s, or where the user cache cannot be written (read-only,
    missing), compiled once per process in a temporary folder removed at once.

    Raises
    ------
    NativeBuildError
        As :func:`compiled_binary`.
    """
    try:
        return compiled_binary().read_bytes()
    except OSError:
        cc = compiler()
        key = _target(_source_bytes(), cc).parent.name  # the cache's key of the source and the compiler
        with _COMPILING:
            if key not in _compiled_here:
                with tempfile.TemporaryDirectory(prefix="dtcosim-binary-") as tmp:
                    _compiled_here[key] = _compile(cc, Path(tmp) / BINARY_FILE).read_bytes()
        return _compiled_here[key]


def cached_binary() -> Path | None:
    """Where the binary of these sources, compiled by this machine's compiler, is kept (whether compiled yet or not);
    None without a compiler."""
    cc = compiler()
    return None if cc is None else _target(_source_bytes(), cc)


def _target(source: bytes, cc: str) -> Path:
    """Where the binary of ``source`` compiled by ``cc`` is cached."""
    return user_cache_root() / CACHE_FOLDER / hashlib.sha256(source + cc.encode()).hexdigest()[:16] / BINARY_FILE


@contextlib.contextmanager
def _one_compiler(folder: Path) -> Iterator[None]:
    """Hold an exclusive ``flock`` on ``folder`` (created if missing): one process compiles into it at a time, and
    the others then find its result."""
    fd = _locked(folder)
    try:
        yield
    finally:
        os.close(fd)


def _locked(folder: Path, wait: bool = True) -> int | None:
    """A descriptor of ``folder`` (created if missing) that holds its exclusive ``flock`` until it is closed; None
    without ``wait`` where another process holds the lock."""
    import fcntl

    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX if wait else fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return None
    except BaseException:
        os.close(fd)
        raise
    return fd


def _compile(cc: str, target: Path) -> Path:
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent) as tmp:
        out = Path(tmp) / target.name
        # hidden visibility: only the fmi2 functions are exported, so no host symbol can interpose the helpers
        proc = subprocess.run([cc, "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o", str(out),
                               *(str(NATIVE_DIR / name) for name in SOURCES), "-ldl", "-lpthread"],
                              capture_output=True, text=True)
        if proc.returncode != 0 or not out.is_file():
            raise NativeBuildError(f"{cc} could not compile {', '.join(SOURCES)}: {proc.stderr.strip()[-2000:]}")
        os.replace(out, target)  # atomic: a concurrent build finds either nothing or the whole file
    return target


class BackgroundCompile:
    """The binary compiling in a process of its own (:func:`start_compile`)."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.process = process

    def finish(self) -> None:
        """Wait for the compile to end (a build that needed the binary has waited for it already)."""
        self.process.wait()

    def stop(self) -> None:
        """End the compile now (its temporary folder removed): this process was interrupted."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        self.process.wait()


def start_compile() -> BackgroundCompile | None:
    """Start compiling the binary where it is missing (the first build of a machine), in a process of its own that
    holds the compile lock (:func:`_one_compiler`) until it has ended: whoever needs the binary meanwhile - this
    process, a builder it forks, another command - waits for it there, and compiles it itself if it failed (and
    says why). The compiler runs beside the Python work that comes before the binary is needed; a process, not a
    thread, so that this process may fork builders meanwhile (:func:`fmus.build_pool.can_fork`).

    None where there is nothing to start: the binary is there, no compiler or not linux (the build says so), or
    another process is compiling it.
    """
    cc = compiler()
    if not sys.platform.startswith("linux") or cc is None:
        return None
    target = _target(_source_bytes(), cc)
    if target.is_file():
        return None
    try:
        fd = _locked(target.parent, wait=False)
    except OSError:  # an unwritable cache: each build compiles it for its own process (binary_bytes)
        return None
    if fd is None:  # being compiled by another process
        return None
    try:
        if target.is_file():
            return None
        # the lock goes with the inherited descriptor: held until the compiling process has ended
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        process = subprocess.Popen([sys.executable, "-m", __name__, cc, str(target)], pass_fds=(fd,), env=env,
                                   stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        return None
    finally:
        os.close(fd)
    return BackgroundCompile(process)


def native_members(model_identifier: str, class_name: str) -> dict[str, bytes]:
    """The FMU members this module adds or replaces (see the module docstring).

    Raises
    ------
    NativeBuildError
        As :func:`compiled_binary`.
    """
    binary = binary_bytes()
    return {f"{BINARY_FOLDER}/{model_identifier}.so": binary,
            f"resources/{PYTHON_FILE}": python_record().encode(),
            f"resources/{CLASS_FILE}": (class_name + "\n").encode()}


def main(argv: list[str]) -> int:
    """``python -m fmus.binary CC TARGET``: the process :func:`start_compile` starts (it inherits the compile lock)."""
    cc, target = argv
    try:
        _compile(cc, Path(target))
    except (NativeBuildError, OSError, KeyboardInterrupt):  # told by the build that needs it, which compiles again
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
