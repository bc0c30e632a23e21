"""The drivetrain's equations, written once: plain Python functions on floats and arrays.

Every equation the co-simulation gearbox, the monolithic reference and the analyses evaluate
exists here and nowhere else; the same files run compiled (numba just in time, or ahead of time
without numba) or interpreted (numpy alone), as :mod:`components.compile` arranges.

Modules (each imports only :mod:`math`, numpy and its siblings)
----------------------------------------------------------------
contact      the contact laws of one mesh: CFS (eq. 2-4), impact (eq. 1), flank-consistent clipping
stiffness    time-varying mesh stiffness multiplier and slope
motion       the input motion over a communication step (Taylor targets, cubic Hermite curves)
dynamics     deflections, accelerations and Jacobian from the assembled matrices
integrator   the ROS2(3) W-method with step control and Jacobian reuse
step         one communication step of the gearbox and its outputs (entry: ``gearbox``)
monolithic   the monolithic right-hand side and Jacobian, loads of many states (entry: ``monolithic``)
wind         the rotor-speed process's phasor step (entry: ``wind``)
linalg       linear-algebra primitives (numpy forms, and the loops numba compiles)
layout       the gearbox buffer's slots and indices

:func:`gearbox`, :func:`monolithic` and :func:`wind` return the form of their kernel to run.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

from ...compile.choice import ENVIRONMENT_VARIABLE, kernel_module
from ...compile.jit import entry_point, load_compiled
from ...compile.sources import KernelSource
from . import monolithic as _monolithic
from . import step as _step
from . import wind as _wind

_HERE = Path(__file__).resolve().parent
#: the gearbox's communication step (compiled ahead of time)
GEARBOX = KernelSource("gearbox", _HERE / "step.py")
#: the monolithic reference's right-hand side and the loads of many states (just in time)
MONOLITHIC = KernelSource("monolithic", _HERE / "monolithic.py")
#: the rotor-speed process's phasor step (compiled ahead of time)
WIND = KernelSource("wind", _HERE / "wind.py")

#: at most this many evaluations of a mesh (contact law, stiffness) are brief (:func:`monolithic`): interpreted they
#: cost ~50 ms, less than importing numba and loading the compiled form from its cache (~0.25 s)
BRIEF_EVALUATIONS = 10_000

#: the kernels compiled ahead of time (an FMU carries their modules beside its copy of the sources)
AHEAD_OF_TIME = (GEARBOX, WIND)
#: every kernel
KERNELS = (GEARBOX, MONOLITHIC, WIND)

__all__ = ["AHEAD_OF_TIME", "BRIEF_EVALUATIONS", "ENVIRONMENT_VARIABLE", "GEARBOX", "KERNELS", "MONOLITHIC", "WIND", "choose_kernel",
           "gearbox", "jit_gearbox", "monolithic", "wind"]


def gearbox(kernel: str | None = None) -> tuple[ModuleType, str, str | None]:
    """The gearbox kernel's entry module to run, ``"compiled"`` or ``"numpy"``, and why a wanted compiled form is not used.

    See :func:`components.compile.choice.kernel_module`.
    """
    return kernel_module(GEARBOX, _step, kernel, "compiled gearbox kernel")


def monolithic(kernel: str | None = None, brief: bool = False) -> tuple[ModuleType, str, str | None]:
    """The monolithic kernel's entry module to run (numba's just-in-time form, or interpreted).

    ``brief``: a short evaluation, interpreted unless numba's form is loaded already
    (:func:`components.compile.choice.kernel_module`).
    """
    return kernel_module(MONOLITHIC, _monolithic, kernel, "compiled monolithic kernel", ahead_of_time=False,
                         brief=brief)


def wind(kernel: str | None = None) -> tuple[ModuleType, str, str | None]:
    """The wind kernel's entry module to run."""
    return kernel_module(WIND, _wind, kernel, "compiled wind step")


def choose_kernel(kernel: str | None = None) -> tuple[str, str | None]:
    """The gearbox kernel's form, ``"compiled"`` or ``"numpy"``, and why a wanted compiled form is not used."""
    _, form, note = gearbox(kernel)
    return form, note


def jit_gearbox() -> ModuleType:
    """The gearbox kernel compiled just in time by numba, its step compiled now (or loaded from numba's disk cache).

    What the ahead-of-time builder compiles, and the benchmark of numba's import and cache load.
    """
    module = load_compiled(GEARBOX)
    entry_point(module.gearbox_step, ("float64[::1]", "int64[::1]", "int64[::1]") + ("float64",) * 9)
    return module
