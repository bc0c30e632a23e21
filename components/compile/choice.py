"""Which form of a kernel runs, as asked: ``$DTCOSIM_KERNEL`` or a ``kernel`` argument.

A kernel (:class:`~components.compile.sources.KernelSource`) is one set of plain Python
sources; it runs in one of two forms:

* ``compiled``: its ahead-of-time extension module (:mod:`components.compile.aot`) where one
  is built, else the same sources compiled just in time by numba (:mod:`components.compile.jit`);
* ``numpy``: the same sources imported normally and interpreted (numpy alone: what an FMU runs
  in a Python without numba where no ahead-of-time module was built).

``auto`` (the default) takes the compiled form where it loads, else the interpreted one;
``compiled`` is an error (a :class:`~components.errors.ParameterError` saying why) where it
cannot load. Both forms run the same equations; the tests compare them per step.
"""

from __future__ import annotations

import os
from types import ModuleType
from typing import Callable

from ..errors import ParameterError
from .aot import AotKernel, compiled_or_jit
from .jit import already_compiled, try_compiled
from .sources import KernelSource

KERNELS = ("auto", "numpy", "compiled")
ENVIRONMENT_VARIABLE = "DTCOSIM_KERNEL"


def requested_kernel(kernel: str | None = None) -> str:
    """The kernel asked for: ``kernel`` if given, else ``$DTCOSIM_KERNEL``, else ``auto``."""
    value = kernel if kernel is not None else os.environ.get(ENVIRONMENT_VARIABLE, "auto")
    value = str(value).strip().lower() or "auto"
    if value not in KERNELS:
        source = "kernel" if kernel is not None else ENVIRONMENT_VARIABLE
        raise ParameterError(source, value, f"one of {', '.join(KERNELS)}")
    return value


def compiled_or_numpy(kernel: str | None, load: Callable[[], tuple[ModuleType | None, str | None]],
                      what: str) -> tuple[ModuleType | None, str | None]:
    """The compiled module to use (None: the numpy path) and why a wanted one is not used.

    Parameters
    ----------
    kernel : str or None
        As :func:`requested_kernel`.
    load : callable
        Returns the compiled module, or None and the reason it cannot be imported.
    what : str
        What the module is, for the note (``"compiled gearbox kernel"``).

    Returns
    -------
    module : module or None
        The compiled module, or None for the numpy path.
    fallback_reason : str or None
        Why the compiled path was wanted (``auto``) but is not used; None otherwise.

    Raises
    ------
    ParameterError
        Unknown name, or ``compiled`` requested where it cannot be imported.
    """
    wanted = requested_kernel(kernel)
    if wanted == "numpy":
        return None, None
    module, reason = load()
    if module is not None:
        return module, None
    if wanted == "compiled":
        raise ParameterError("kernel", "compiled", f"a compiled kernel: an ahead-of-time module or numba ({reason})")
    return None, f"{what} unavailable ({reason}); running it interpreted (numpy)"


def compiled_module(source: KernelSource, interpreted: ModuleType | None = None,
                    ahead_of_time: bool = True) -> tuple[ModuleType | None, str | None]:
    """The compiled form of ``source``: its ahead-of-time module where built, else numba's; or None and why not.

    Parameters
    ----------
    source : KernelSource
    interpreted : module, optional
        The interpreted entry module: the ahead-of-time facade takes its constants from it.
    ahead_of_time : bool
        False: numba's just-in-time module only (for entry points that are not compiled ahead of time).
    """
    if not ahead_of_time:
        return try_compiled(source)
    return compiled_or_jit(AotKernel.of(source), lambda: try_compiled(source), interpreted)


def kernel_module(source: KernelSource, interpreted: ModuleType, kernel: str | None = None,
                  what: str = "compiled kernel", ahead_of_time: bool = True,
                  brief: bool = False) -> tuple[ModuleType, str, str | None]:
    """The form of ``source`` to run.

    Parameters
    ----------
    source : KernelSource
    interpreted : module
        The entry module imported normally (the interpreted form).
    kernel : {"auto", "numpy", "compiled"}, optional
        As :func:`requested_kernel`.
    what : str
        What the kernel is, for the note (``"compiled gearbox kernel"``).
    ahead_of_time : bool
        See :func:`compiled_module`.
    brief : bool
        For a short evaluation (a static deflection, one Jacobian): with ``auto``, a kernel that is
        compiled just in time only (``ahead_of_time=False``) runs compiled only where this process has
        loaded it already, else interpreted: importing numba and loading the machine code from its
        cache costs about 0.25 s, the interpreted evaluation milliseconds (and compiling it, on a
        machine's first run, much more).

    Returns
    -------
    module : module
        The compiled form, or ``interpreted``.
    form : str
        ``"compiled"`` or ``"numpy"``.
    fallback_reason : str or None
        Why the compiled form was wanted (``auto``) but is not used; None otherwise.

    Raises
    ------
    ParameterError
        Unknown name, or ``compiled`` requested where it cannot load.
    """
    if brief and not ahead_of_time and requested_kernel(kernel) == "auto" and already_compiled(source) is None:
        return interpreted, "numpy", None
    module, note = compiled_or_numpy(kernel, lambda: compiled_module(source, interpreted, ahead_of_time), what)
    return (interpreted, "numpy", note) if module is None else (module, "compiled", note)
