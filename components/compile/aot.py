"""Ahead-of-time compiled kernels: numba's machine code in a plain extension module that runs without numba.

The compiled kernels (:mod:`components.model.kernel`: the gearbox step and the wind's phasor
step; the master's stepping loop) are numba functions. Used just in time, they bring numba and
llvmlite into every process that steps them: ~75 MB of resident memory and ~0.5 s of
imports even when the machine code comes from numba's disk cache (``bench_long_run.py
--imports``). A kernel's entry module therefore also declares ``AOT_EXPORTS`` (entry point ->
numba signature), and :func:`build_module` compiles those entry points with ``numba.pycc``
into an extension module that imports with numpy alone (the same numba lowering of the same
source: the tests compare its results with the just-in-time functions bit for bit).

* **Name**: ``<shared name>_aot``, the shared name keyed by the kernel's sources
  (:attr:`components.compile.sources.KernelSource.shared_name`), so a module built from other
  sources is never loaded; the directory (:func:`aot_directory`) is keyed by the Python ABI and
  the numpy version it was built against.
* **Building** needs numba and a C compiler (setuptools' compiler: gcc or clang, MSVC on
  Windows) and ~1 MB per kernel, once per machine and source version; it takes tens of seconds
  of CPU per kernel (numba's optimising compile; ``benchmarks/bench_commands.py --first-run``
  measures it). It runs in child processes (:func:`build_in_subprocess`), so the builder's numba
  stays out of the run; or in one detached, low-priority process that outlives the command
  (:func:`build_in_background`), which the first ``dtcosim run`` of a machine starts so that it
  does not wait.
* **Loading** (:func:`load_module`) needs only the file, carried by an FMU beside its copy of
  the kernel's sources or found in the user cache: where it is missing, cannot be imported or
  ``DTCOSIM_AOT=0``, the kernel's owner uses the just-in-time module as before.

:func:`facade` joins the extension module's entry points, the kernel's constants and, for any
other function (the monolithic reference's, test helpers), the just-in-time module, loaded only
when such a name is asked for.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.machinery
import importlib.util
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Callable, Iterator, Sequence

from .c_compiler import INSTALL_HINT, c_compiler
from .numba_cache import user_cache_root, warm_mark
from .sources import KernelSource

#: prefix of a provider that names a kernel source (:meth:`AotKernel.of`)
_KERNEL_PROVIDER = "kernel:"
#: ``DTCOSIM_AOT=0``: never load ahead-of-time modules (the just-in-time kernels run instead)
ENVIRONMENT_VARIABLE = "DTCOSIM_AOT"


@dataclass(frozen=True)
class AotKernel:
    """One kernel that can be compiled ahead of time.

    Attributes
    ----------
    shared : str
        Its shared name (:attr:`~components.compile.sources.KernelSource.shared_name`): the key of the module.
    provider : str
        How the builder process gets the just-in-time kernel module (which defines ``AOT_EXPORTS``):
        ``"kernel:<name>=<entry file>"`` for a :class:`~components.compile.sources.KernelSource`
        (:meth:`of`), or ``"package.module:function"``, a function returning that module.
    source : pathlib.Path or None
        The kernel's entry file: an FMU carries the extension module in :data:`BUNDLE_FOLDER` beside it.
    """

    shared: str
    provider: str
    source: Path | None = None

    @classmethod
    def of(cls, source: KernelSource) -> "AotKernel":
        """The ahead-of-time form of a kernel package's entry module."""
        return cls(source.shared_name, f"{_KERNEL_PROVIDER}{source.name}={source.entry}", Path(source.entry))

    @property
    def module_name(self) -> str:
        """Import name of the extension module."""
        return f"{self.shared}_aot"

    def file(self, directory: Path | None = None) -> Path:
        """Path of the extension module in ``directory`` (default :func:`aot_directory`)."""
        return (directory or aot_directory()) / (self.module_name + importlib.machinery.EXTENSION_SUFFIXES[0])


def aot_directory() -> Path:
    """``<user cache>/aot/<python cache tag>-numpy<major.minor>``: where this interpreter's modules live."""
    import numpy as np

    numpy_version = ".".join(np.__version__.split(".")[:2])
    return user_cache_root() / "aot" / f"{sys.implementation.cache_tag}-numpy{numpy_version}"


def enabled() -> bool:
    """False where ``DTCOSIM_AOT=0``, and in an interpreter a non-Python program embeds (a C host of a PythonFMU).

    In a C host that starts Python through pythonfmu's FMU library (``tests/fmus/test_hosts.py``),
    the process aborts at exit (``free(): corrupted unsorted chunks``, in libgfortran's exit
    handler) when an ahead-of-time module was loaded; the same steps in a C program embedding
    Python (with pythonfmu's thread-state handling) exit cleanly, and valgrind finds pythonfmu's
    exit-time finalisation reading freed memory, so the fault is likely pythonfmu's. Such hosts
    (``sys.orig_argv`` empty: no Python command line) run the just-in-time or numpy kernels.
    """
    if not getattr(sys, "orig_argv", ["python"]):
        return False
    return os.environ.get(ENVIRONMENT_VARIABLE, "1").strip() != "0"


#: folder beside a kernel's source where an FMU carries the kernel's extension module (``fmus.build``)
BUNDLE_FOLDER = "_aot"


def load_module(kernel: AotKernel) -> ModuleType | None:
    """The kernel's extension module if it was built for this interpreter and imports; else None.

    Looked for in the :data:`BUNDLE_FOLDER` beside ``kernel.source`` (an FMU carries its module
    there), then in :func:`aot_directory`.
    """
    if not enabled():
        return None
    module = sys.modules.get(kernel.module_name)
    if module is not None:
        return module
    folders = ([kernel.source.parent / BUNDLE_FOLDER] if kernel.source is not None else []) + [aot_directory()]
    for path in (kernel.file(folder) for folder in folders):
        if not path.is_file():
            continue
        try:
            spec = importlib.util.spec_from_file_location(kernel.module_name, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        except Exception:  # noqa: BLE001 - not importable here (another ABI, a damaged file): the next, or JIT
            continue
        sys.modules[kernel.module_name] = module
        return module
    return None


def facade(module: ModuleType, name: str, constants: ModuleType | None,
           jit_module: Callable[[], tuple[ModuleType | None, str | None]], **extra) -> ModuleType:
    """A module with the entry points of ``module``, the public names of ``constants`` and ``extra``.

    Any other attribute is looked up in the just-in-time module (``jit_module()``, loaded on
    first use); where that cannot load, the attribute error says why.
    """
    front = ModuleType(name, f"ahead-of-time kernel {module.__name__} ({module.__file__})")
    if constants is not None:  # its constants only: a function of it may be an interpreted one
        front.__dict__.update({k: v for k, v in vars(constants).items()
                               if not k.startswith("_") and not callable(v) and not isinstance(v, ModuleType)})
    front.__dict__.update({k: v for k, v in vars(module).items() if not k.startswith("_")})
    front.__dict__.update(extra)
    front.AHEAD_OF_TIME = module.__file__

    def __getattr__(attribute: str):
        jit, reason = jit_module()
        if jit is None:
            raise AttributeError(f"{attribute} is not in the ahead-of-time kernel {module.__name__} and the "
                                 f"just-in-time kernel is unavailable ({reason})")
        return getattr(jit, attribute)

    front.__getattr__ = __getattr__
    return front


_facades: dict[str, ModuleType] = {}


def compiled_or_jit(kernel: AotKernel, jit_module: Callable[[], tuple[ModuleType | None, str | None]],
                    constants: ModuleType | None = None,
                    extra: Callable[[ModuleType], dict] | None = None) -> tuple[ModuleType | None, str | None]:
    """The kernel's :func:`facade` over its ahead-of-time module where one loads, else ``jit_module()``.

    One facade per kernel version and process; ``extra(module)`` gives names the facade adds.
    """
    front = _facades.get(kernel.shared)
    if front is None:
        module = load_module(kernel)
        if module is None:
            return jit_module()
        front = facade(module, kernel.module_name + "_facade", constants, jit_module,
                       **(extra(module) if extra else {}))
        _facades[kernel.shared] = front
    return front, None


def required(jit_module: Callable[[], tuple[ModuleType | None, str | None]]) -> ModuleType:
    """``jit_module()``'s module, or ImportError with its reason (what a builder's provider returns)."""
    module, reason = jit_module()
    if module is None:
        raise ImportError(reason)
    return module


def build_module(kernel: AotKernel, directory: Path | None = None) -> Path:
    """Compile the kernel's ``AOT_EXPORTS`` into its extension module in ``directory``; returns the file.

    Needs numba and a C compiler; written atomically (a concurrent build of the same kernel
    leaves one complete file).
    """
    from numba.pycc import CC  # optional requirement: only the builder needs numba

    if c_compiler() is None:  # numba's own error is three lines about numpy.distutils and conda
        raise RuntimeError(f"no C compiler (cc, gcc or clang) for numba's ahead-of-time build: {INSTALL_HINT}")
    jit = _jit_module_of(kernel.provider)
    directory = Path(directory or aot_directory())
    directory.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=directory, prefix=".build-") as tmp:
        cc = CC(kernel.module_name)
        cc.output_dir = tmp
        cc.verbose = False
        for entry, signature in jit.AOT_EXPORTS.items():
            cc.export(entry, signature)(getattr(jit, entry).py_func)
        cc.compile()
        built = Path(tmp) / kernel.file(Path(".")).name
        if not built.is_file():
            raise RuntimeError(f"numba.pycc wrote no {built.name} in {tmp}")
        target = kernel.file(directory)
        os.replace(built, target)
    return target


def warm_just_in_time(kernel: AotKernel) -> None:
    """Where the kernel has no extension module (no C compiler, say), compile its ``AOT_EXPORTS`` just in time into
    numba's disk cache (:mod:`components.compile.numba_cache`) and mark it warm (:func:`is_warm`): runs then load the
    machine code instead of compiling it themselves (~35 s of CPU for the gearbox kernel, in every process without
    the cache).

    The entry points are compiled for their exports' argument types: what a run calls them with, so a run finds
    every function in the cache (numba keys a function compiled with a declared return type apart).

    Raises
    ------
    RuntimeError
        Where numba cannot keep the machine code on disk (nothing would be warm).
    """
    from numba.core.sigutils import normalize_signature  # optional requirement: only the builder needs numba

    jit = _jit_module_of(kernel.provider)
    if not getattr(jit, "DISK_CACHE", False):
        raise RuntimeError(f"numba cannot keep the just-in-time kernel {kernel.shared} in its disk cache")
    for entry, signature in jit.AOT_EXPORTS.items():
        arguments, _ = normalize_signature(signature)
        getattr(jit, entry).compile(tuple(arguments))
    mark = warm_mark(kernel.shared)
    mark.parent.mkdir(parents=True, exist_ok=True)
    mark.write_text(f"{kernel.provider}\n", encoding="utf-8")


def is_warm(kernel: AotKernel) -> bool:
    """Whether numba's cache holds the kernel's entry points compiled just in time (:func:`warm_just_in_time`)."""
    mark = warm_mark(kernel.shared)
    return mark is not None and mark.is_file()


def _jit_module_of(provider: str) -> ModuleType:
    """The just-in-time module a provider string names (see :class:`AotKernel`)."""
    if provider.startswith(_KERNEL_PROVIDER):
        from .jit import load_compiled

        name, _, entry = provider[len(_KERNEL_PROVIDER):].partition("=")
        return load_compiled(KernelSource(name, Path(entry)))
    provider_module, function = provider.rsplit(":", 1)
    return getattr(importlib.import_module(provider_module), function)()


def missing(kernels: Sequence[AotKernel]) -> list[AotKernel]:
    """The kernels whose extension module is not in :func:`aot_directory`."""
    return [k for k in kernels if not k.file().is_file()]


def failure_file(kernel: AotKernel) -> Path:
    """Where a failed build of ``kernel`` left its reason (so that later runs do not retry it each time)."""
    return aot_directory() / f"{kernel.module_name}.failed"


def failed_before(kernel: AotKernel) -> str | None:
    """The reason a build of this very kernel version failed on this machine, or None."""
    try:
        return failure_file(kernel).read_text(encoding="utf-8").strip() or "unknown reason"
    except OSError:
        return None


def _one_line(problem: str) -> str:
    """The first line of a reason (what every message that quotes it shows in one line)."""
    lines = [line.strip() for line in problem.strip().splitlines() if line.strip()]
    return lines[0] if lines else "unknown reason"


def _remember(kernel: AotKernel, problem: str | None) -> None:
    """Record (or, on success, clear) the failure of a build; best effort (a read-only cache keeps nothing)."""
    path = failure_file(kernel)
    try:
        if problem is None:
            path.unlink(missing_ok=True)
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(_one_line(problem) + "\n", encoding="utf-8")
    except OSError:
        pass


def build_in_subprocess(kernels: Sequence[AotKernel], timeout_s: float = 600.0,
                        just_in_time: bool = False) -> str | None:
    """Build ``kernels`` in child Python processes, one per kernel, concurrently; None on success, else why not.

    The reason is one line (the first failing kernel's last line of output); each kernel's
    outcome is remembered (:func:`failed_before`). ``just_in_time``: :func:`warm_just_in_time` instead (nothing
    remembered: a kernel left cold is compiled by the runs that need it).
    """
    if not kernels:
        return None
    if importlib.util.find_spec("numba") is None:
        return "numba is not installed"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    children = []
    try:
        for k in kernels:
            mode = ["--just-in-time"] if just_in_time else []
            children.append(subprocess.Popen([sys.executable, "-m", __name__, *mode, f"{k.shared}={k.provider}"],
                                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env))
        problems = []
        for kernel, child in zip(kernels, children):
            out, err = child.communicate(timeout=timeout_s)
            problem = None
            if child.returncode != 0:
                lines = [line for line in (err or out).strip().splitlines() if line.strip()]
                problem = lines[-1] if lines else f"the builder exited with status {child.returncode}"
                problems.append(problem)
            if not just_in_time:
                _remember(kernel, problem)
    except (OSError, subprocess.TimeoutExpired) as exc:
        for child in children:
            child.kill()
        return f"{type(exc).__name__}: {exc}"
    return problems[0] if problems else None


def build_lock_file() -> Path:
    """The file that marks a background build in progress: it holds the builder's pid (:func:`build_in_background`)."""
    return aot_directory() / ".building"


def background_builder() -> int | None:
    """The pid of the background build in progress on this machine (None: none; a dead builder's mark is removed)."""
    lock = build_lock_file()
    try:
        pid = int(lock.read_text(encoding="utf-8").split()[0])
    except (OSError, ValueError, IndexError):
        return None
    if not _alive(pid):  # killed before it could remove its mark
        lock.unlink(missing_ok=True)
        return None
    return pid


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        pass
    return True


def build_log() -> Path:
    """Where the background build writes what it did (kernels built, how long, or why not)."""
    return aot_directory() / "build.log"


#: longest a background builder started ``after`` a process waits for that process to end [s]
WAIT_FOR_STARTER_S = 20.0


def build_in_background(kernels: Sequence[AotKernel], after: int | None = None) -> int | None:
    """Build ``kernels`` in one detached process at low priority, one after the other; returns its pid.

    The process outlives the command that starts it (a session of its own, so a Ctrl-C of the
    command does not reach it), holds :func:`build_lock_file` while it builds (a second builder
    started meanwhile leaves at once: the first one's pid is returned where it is known) and
    writes :func:`build_log`. With ``after`` (a pid: the command that starts it) it takes the lock
    at once but compiles only once that process has ended, or after :data:`WAIT_FOR_STARTER_S`:
    a short first run does not share the machine with numba's compiler (on 2 cores it took
    0.4-0.6 s longer). A kernel it cannot build, or whose build failed before, it compiles just in time
    into numba's cache instead (:func:`warm_just_in_time`). None where nothing can be started (numba
    missing, an unwritable cache).
    """
    if not kernels or importlib.util.find_spec("numba") is None:
        return None
    running = background_builder()
    if running is not None:
        return running
    try:
        build_log().parent.mkdir(parents=True, exist_ok=True)
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        with open(build_log(), "a", encoding="utf-8") as log:
            waits = ["--after", str(after)] if after is not None else []
            child = subprocess.Popen([sys.executable, "-m", __name__, "--background", str(build_lock_file()), *waits,
                                      *(f"{k.shared}={k.provider}" for k in kernels)],
                                     stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, env=env,
                                     start_new_session=True, close_fds=True)
    except OSError:
        return None
    return child.pid


@contextlib.contextmanager
def build_lock(timeout_s: float = 900.0) -> Iterator[None]:
    """Be the one builder of this machine's kernels for the block: after a builder in progress has ended (another
    process's ``dtcosim build``, a background build, a parallel test worker), so that nothing is compiled twice."""
    import time

    lock = build_lock_file()
    lock.parent.mkdir(parents=True, exist_ok=True)
    deadline = time.monotonic() + timeout_s
    while not _take(lock):
        if time.monotonic() > deadline:
            raise TimeoutError(f"the build of pid {background_builder()} ({lock}) did not end in {timeout_s:g} s")
        time.sleep(0.2)
    try:
        yield
    finally:
        lock.unlink(missing_ok=True)


def _take(lock: Path) -> bool:
    """Mark this process as the builder (the mark appears whole, with its pid); False if another builder has it."""
    mine = lock.with_name(f".building.{os.getpid()}")
    mine.write_text(f"{os.getpid()}\n", encoding="utf-8")
    try:
        for _ in range(2):  # once more after removing a dead builder's mark
            try:
                os.link(mine, lock)
                return True
            except FileExistsError:
                if background_builder() is not None:
                    return False
        return False
    finally:
        mine.unlink(missing_ok=True)


def _background(lock: Path, items: Sequence[str]) -> int:
    """The detached builder: each kernel in turn, remembering failures (then compiling that kernel just in time into
    numba's cache), then its mark removed."""
    import time

    if not _take(lock):
        print(f"another build is in progress (pid {background_builder()}): nothing to do", flush=True)
        return 0
    try:
        if hasattr(os, "nice"):
            os.nice(10)  # the runs of the user go first
        if items[:1] == ["--after"]:
            starter, items = int(items[1]), items[2:]
            waited = _wait_for_exit(starter, WAIT_FOR_STARTER_S)
            print(f"waited {waited:.1f} s for pid {starter} to end", flush=True)
        start = time.perf_counter()
        for item in items:
            shared, _, provider = item.partition("=")
            kernel = AotKernel(shared, provider)
            if kernel.file().is_file():  # built by a builder before
                continue
            t0 = time.perf_counter()
            if failed_before(kernel) is None:
                try:
                    path = build_module(kernel)
                except Exception as exc:  # noqa: BLE001 - recorded: later runs do not retry it each time
                    _remember(kernel, f"{type(exc).__name__}: {exc}")
                    print(f"{kernel.module_name}: not built ({type(exc).__name__}: {exc})", flush=True)
                else:
                    _remember(kernel, None)
                    print(f"{path}: built in {time.perf_counter() - t0:.1f} s", flush=True)
                    continue
            if not is_warm(kernel):  # no module: numba's cache instead, so that no run compiles it just in time
                _warm(kernel)
        print(f"done in {time.perf_counter() - start:.1f} s (process CPU {time.process_time():.1f} s)", flush=True)
    finally:
        lock.unlink(missing_ok=True)
    return 0


def _warm(kernel: AotKernel) -> None:
    """:func:`warm_just_in_time`, saying in the log what came of it."""
    import time

    t0 = time.perf_counter()
    try:
        warm_just_in_time(kernel)
    except Exception as exc:  # noqa: BLE001 - the runs compile it just in time themselves, as before
        print(f"{kernel.shared}: not compiled just in time ({type(exc).__name__}: {_one_line(str(exc))})", flush=True)
    else:
        print(f"{kernel.shared}: compiled just in time into numba's cache in {time.perf_counter() - t0:.1f} s",
              flush=True)


def _wait_for_exit(pid: int, limit_s: float) -> float:
    """Wait until process ``pid`` has ended or ``limit_s`` has passed; returns the seconds waited."""
    import time

    start = time.monotonic()
    while time.monotonic() - start < limit_s and _alive(pid):
        time.sleep(0.1)
    return time.monotonic() - start


def main(argv: Sequence[str]) -> int:
    """``python -m components.compile.aot [--background LOCK [--after PID] | --just-in-time] SHARED=PROVIDER ...``:
    build each kernel.

    Providers: see :class:`AotKernel`. ``--background``: the detached builder of
    :func:`build_in_background`, which removes ``LOCK`` when it ends (``--after``: it compiles once ``PID`` ended);
    a kernel it cannot build (or that failed before) it compiles just in time into numba's cache
    (:func:`warm_just_in_time`). ``--just-in-time``: only that.
    """
    if argv[:1] == ["--background"]:
        return _background(Path(argv[1]), argv[2:])
    just_in_time = argv[:1] == ["--just-in-time"]
    for item in argv[1:] if just_in_time else argv:
        shared, _, provider = item.partition("=")
        kernel = AotKernel(shared, provider)
        if just_in_time:
            warm_just_in_time(kernel)
        else:
            print(build_module(kernel))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
