"""Which implementation a hot path runs, as asked: ``$DTCOSIM_KERNEL`` or a ``kernel`` argument.

* ``auto`` (default): the compiled (numba) path where numba imports, else the numpy path;
* ``numpy``: always the numpy path (the single source of truth of the equations);
* ``compiled``: the compiled path, or a :class:`~components.errors.ParameterError` saying why
  it is unavailable.

The gearbox (:mod:`components.model.kernel`) and the wind's phasor step
(:class:`components.model.wind.PhasorStepper`) each load their own compiled module; this
module imports neither, so an FMU carries only the compiled module its own physics uses.
"""

from __future__ import annotations

import os
from types import ModuleType
from typing import Callable

from ..errors import ParameterError

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
        raise ParameterError("kernel", "compiled", f"an importable numba ({reason})")
    return None, f"{what} unavailable ({reason}); using the numpy path"
