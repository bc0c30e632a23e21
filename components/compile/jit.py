"""A kernel's sources compiled just in time by numba, once per process whoever ships them.

Every FMU build carries its own copy of the kernel sources in a private package
(``_dtcosim_gearbox_<build id>.components.model.kernel``), and the host has its own
(``components.model.kernel``). :func:`load_compiled` executes a kernel's files
(:attr:`~components.compile.sources.KernelSource.files`) once per process as the modules of
a package named by the kernel's :attr:`~components.compile.sources.KernelSource.shared_name`,
and every later request, from any copy with the same sources, gets those modules. After each
module executes, its functions become numba dispatchers:

* every function defined in the module is wrapped in ``numba.njit`` (numba compiles it on its
  first call, or loads it from the disk cache of :mod:`components.compile.numba_cache`);
  the names in the module's ``INLINE`` are inlined into their callers (``inline="always"``);
* the module's ``COMPILED`` mapping (name -> function of the same module) replaces a function
  written for the interpreter (numpy calls, or Python floats) by the loop that numba compiles
  better (the linear-algebra primitives of :mod:`components.model.kernel.linalg`, the
  integrator's vector updates, the contact law of every mesh, ...: the interpreted kernel runs
  at numpy's speed instead of an operation per element, the compiled one needs no BLAS and no
  temporaries).

The relative imports of a later module then bind the dispatchers. Nothing else differs from
the interpreted kernel, which is the same files imported normally.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from types import FunctionType, ModuleType

from .numba_cache import enable_stable_cache
from .sources import KernelSource


def _compile_functions(module: ModuleType) -> None:
    """Replace the module's functions by numba dispatchers (see the module docstring)."""
    from numba import njit  # optional requirement: the compiled kernels; the interpreted ones run without

    inline = set(getattr(module, "INLINE", ()))
    replaced = dict(getattr(module, "COMPILED", {}))
    dispatchers = []
    for name, obj in list(vars(module).items()):
        if isinstance(obj, FunctionType) and obj.__module__ == module.__name__:
            function = replaced.get(name, obj)
            dispatcher = njit(cache=False, inline="always" if name in inline else "never")(function)
            setattr(module, name, dispatcher)
            dispatchers.append(dispatcher)
    #: True when numba caches this module's machine code on disk (see :mod:`components.compile.numba_cache`)
    module.DISK_CACHE = enable_stable_cache(dispatchers, module.__file__, module.__name__)


def load_compiled(source: KernelSource) -> ModuleType:
    """The entry module of ``source`` with numba dispatchers, executed on the first request in this process only.

    Raises
    ------
    Exception
        Whatever executing the modules raises (e.g. ImportError without numba); nothing is kept then.
    """
    package = source.shared_name
    entry = f"{package}.{source.module_stem}"
    module = sys.modules.get(entry)
    if module is not None:
        return module
    added = []
    try:
        root = ModuleType(package, f"kernel {source.name} compiled by numba")
        root.__path__ = [str(source.entry.parent)]
        root.__package__ = package
        sys.modules[package] = root
        added.append(package)
        for path in source.files:  # dependencies first: a relative import finds its module in sys.modules
            name = f"{package}.{path.stem}"
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            added.append(name)
            spec.loader.exec_module(module)
            _compile_functions(module)
            setattr(root, path.stem, module)
    except BaseException:
        for name in added:
            sys.modules.pop(name, None)
        raise
    return sys.modules[entry]


#: results of :func:`try_compiled` per kernel version: a module or the reason it could not load
_attempts: dict[str, tuple[ModuleType | None, str | None]] = {}

#: ``DTCOSIM_JIT=0``: nothing is compiled just in time in this process (a kernel runs from its ahead-of-time module
#: where one loads, else interpreted); ``dtcosim run`` sets it while the ahead-of-time modules are being built in the
#: background (:mod:`orchestrator.cosim.compiled_kernels`): compiling just in time costs as much as building them
JIT_VARIABLE = "DTCOSIM_JIT"


#: why just-in-time compilation is off, set beside :data:`JIT_VARIABLE` by the process that turned it off for
#: itself, its FMUs and its workers (``dtcosim run`` while the kernels compile in the background)
JIT_OFF_REASON_VARIABLE = "DTCOSIM_JIT_OFF_REASON"


def jit_enabled() -> bool:
    """False where ``DTCOSIM_JIT=0``."""
    return os.environ.get(JIT_VARIABLE, "1").strip() != "0"


def jit_off_reason() -> str:
    """Why a kernel has no compiled form where just-in-time compilation is off: the reason the process that turned
    it off gave (:data:`JIT_OFF_REASON_VARIABLE`), else that ``DTCOSIM_JIT=0`` is set."""
    given = os.environ.get(JIT_OFF_REASON_VARIABLE, "").strip()
    if given:
        return f"no module compiled ahead of time yet: {given}"
    return f"no module compiled ahead of time, and just-in-time compilation is off ({JIT_VARIABLE}=0)"


def try_compiled(source: KernelSource) -> tuple[ModuleType | None, str | None]:
    """:func:`load_compiled`, tried once per process: the module and None, or None and why it failed.

    A failure (numba missing or broken) is remembered, not retried: the caller runs the
    interpreted kernel instead and says why. With just-in-time compilation off
    (:data:`JIT_VARIABLE`) only a module loaded already is returned.
    """
    key = source.shared_name
    if key not in _attempts and not jit_enabled():
        return None, jit_off_reason()
    if key not in _attempts:
        try:
            _attempts[key] = (load_compiled(source), None)
        except Exception as exc:  # noqa: BLE001 - the caller runs the interpreted kernel instead and says why
            _attempts[key] = (None, f"{type(exc).__name__}: {exc}")
    return _attempts[key]


def already_compiled(source: KernelSource) -> ModuleType | None:
    """The just-in-time module of ``source`` if this process has loaded it already (nothing is loaded here)."""
    if not _attempts:  # nothing compiled just in time here: no need to name the sources' version
        return None
    return _attempts.get(source.shared_name, (None, None))[0]


def entry_point(function, argument_types: tuple):
    """``function`` for one signature without numba's per-call type resolution, where it is a numba dispatcher.

    The compiled overload's own entry point (numba's ``overloads[signature].entry_point``) takes the same
    arguments and saves ~0.2 us per call. ``argument_types`` are numba type names (``"float64[::1]"``,
    ``"int64[::1]"``, ``"float64"``). Anything else (an ahead-of-time function, an interpreted one, or a
    dispatcher whose internals changed) is returned as it is: always correct.
    """
    if not hasattr(function, "overloads") or not hasattr(function, "compile"):
        return function
    try:
        from numba import types  # optional requirement: only a dispatcher has come this far

        signature = tuple(getattr(types, name[:-5])[::1] if name.endswith("[::1]") else getattr(types, name)
                          for name in argument_types)
        function.compile(signature)
        return function.overloads[signature].entry_point
    except Exception:  # noqa: BLE001 - numba internals changed: the dispatcher is always correct
        return function
