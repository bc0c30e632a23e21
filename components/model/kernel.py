"""Which implementation of the gearbox hot path runs: the compiled kernel or the numpy path.

``DTCOSIM_KERNEL`` (environment) or the ``kernel`` argument of
:class:`~components.model.gearbox_model.GearboxModel` and
:class:`~components.reference.solver.MonolithicSystem` chooses:

* ``auto`` (default): the compiled kernel (:mod:`components.model.compiled_kernel`,
  numba) where it is built ahead of time (:mod:`components.model.aot`) or numba imports,
  else the numpy path;
* ``numpy``: always the numpy path (the single source of truth of the equations);
* ``compiled``: the compiled kernel, or a :class:`~components.errors.ParameterError`
  saying why it is unavailable.

Both paths give the same results to round-off (the tests compare them to 1e-9).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from . import kernel_layout
from .aot import AotKernel, compiled_or_jit, required
from .kernel_request import ENVIRONMENT_VARIABLE, KERNELS, compiled_or_numpy, requested_kernel
from .shared_module import shared_name, try_load_shared

if TYPE_CHECKING:  # what an FMU's source closure follows: the kernel module is loaded by load_shared
    from . import compiled_kernel  # noqa: F401

#: project modules the kernel imports (their sources are part of its shared name)
KERNEL_DEPENDENCIES = ("integrators.py", "kernel_layout.py", "numba_cache.py")
_SOURCE = Path(__file__).with_name("compiled_kernel.py")

__all__ = ["ENVIRONMENT_VARIABLE", "KERNELS", "aot_kernel", "choose_kernel", "compiled_module", "jit_module",
           "requested_kernel"]


def jit_module() -> tuple[ModuleType | None, str | None]:
    """The just-in-time kernel module (numba), or None and the reason it cannot be used (tried once per process).

    Loaded by :func:`~components.model.shared_module.load_shared`: every copy of the same kernel
    sources (the host's, each FMU build's) gets one module, compiled and cached once per machine.
    """
    return try_load_shared(_SOURCE, __package__, KERNEL_DEPENDENCIES)


def _jit_kernel_module() -> ModuleType:
    """The ahead-of-time builder's provider: :func:`jit_module` or its ImportError."""
    return required(jit_module)


@lru_cache(maxsize=None)  # once per source file: an FMU's extracted copy may be gone by its next instance
def aot_kernel(source: Path = _SOURCE) -> AotKernel:
    """The gearbox kernel as :mod:`components.model.aot` builds and finds it (``source``: a copy of its file)."""
    return AotKernel(shared_name(source, KERNEL_DEPENDENCIES), f"{__name__}:_jit_kernel_module", source)


def compiled_module() -> tuple[ModuleType | None, str | None]:
    """The compiled kernel: its ahead-of-time module where built, else :func:`jit_module`.

    The ahead-of-time form (:func:`components.model.aot.facade`) has the stepping entry points
    (``gearbox_step``, ``outputs``) and :mod:`~components.model.kernel_layout`; any other name
    (the monolithic reference's functions) comes from the just-in-time module on first use.
    """
    return compiled_or_jit(aot_kernel(), jit_module, kernel_layout, lambda module: {
        "ensure_compiled": lambda: None, "step_entry_point": lambda: module.gearbox_step})


def choose_kernel(kernel: str | None = None) -> tuple[str, str | None]:
    """Resolve the kernel to ``"compiled"`` or ``"numpy"``.

    Returns
    -------
    kernel : str
        ``"compiled"`` or ``"numpy"``.
    fallback_reason : str or None
        Why the compiled kernel was wanted (``auto``) but is not used; None otherwise.

    Raises
    ------
    ParameterError
        Unknown name, or ``compiled`` requested where it cannot be imported.
    """
    module, note = compiled_or_numpy(kernel, compiled_module, "compiled gearbox kernel")
    return ("compiled" if module is not None else "numpy"), note
