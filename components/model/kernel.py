"""Which implementation of the gearbox hot path runs: the compiled kernel or the numpy path.

``DTCOSIM_KERNEL`` (environment) or the ``kernel`` argument of
:class:`~components.model.gearbox_model.GearboxModel` and
:class:`~components.reference.solver.MonolithicSystem` chooses:

* ``auto`` (default): the compiled kernel (:mod:`components.model.compiled_kernel`,
  numba) where numba imports, else the numpy path;
* ``numpy``: always the numpy path (the single source of truth of the equations);
* ``compiled``: the compiled kernel, or a :class:`~components.errors.ParameterError`
  saying why it is unavailable.

Both paths give the same results to round-off (the tests compare them to 1e-9).
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from .kernel_request import ENVIRONMENT_VARIABLE, KERNELS, compiled_or_numpy, requested_kernel
from .shared_module import try_load_shared

if TYPE_CHECKING:  # what an FMU's source closure follows: the kernel module is loaded by load_shared
    from . import compiled_kernel  # noqa: F401

#: project modules the kernel imports (their sources are part of its shared name)
KERNEL_DEPENDENCIES = ("integrators.py", "numba_cache.py")

__all__ = ["ENVIRONMENT_VARIABLE", "KERNELS", "choose_kernel", "compiled_module", "requested_kernel"]

def compiled_module() -> tuple[ModuleType | None, str | None]:
    """The compiled kernel module, or None and the reason it cannot be used (tried once per process).

    Loaded by :func:`~components.model.shared_module.load_shared`: every copy of the same kernel
    sources (the host's, each FMU build's) gets one module, compiled and cached once per machine.
    """
    return try_load_shared(Path(__file__).with_name("compiled_kernel.py"), __package__, KERNEL_DEPENDENCIES)


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
