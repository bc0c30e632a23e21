"""The compiled kernels of a test session, compiled once before a parallel run's workers start.

Serially, the first test that needs a compiled kernel compiles it (ahead of time: the session
fixture ``built_fmus``; just in time: the first test that steps numba's form) and every later
one loads it. With pytest-xdist each worker would find the caches cold and compile the same
kernels again, at the same time, and tests would pay numba's just-in-time compile of a kernel
whose ahead-of-time module was still being built. :func:`compile_once` does the work once, in
the controller, before the workers start: the ahead-of-time modules are built in a detached
process while this one compiles numba's forms the tests compare with them, into numba's disk
cache; both land in the user cache the workers use.
"""

from __future__ import annotations


def compile_once() -> None:
    """Build the missing ahead-of-time kernels and fill numba's cache with the just-in-time ones the tests use."""
    from components.compile.aot import build_in_background, build_lock, missing
    from components.compile.choice import requested_kernel
    from orchestrator.cosim.compiled_kernels import aot_kernels, ensure_compiled_kernels

    if requested_kernel() == "numpy":  # the interpreted pass: nothing compiled is stepped
        return
    build_in_background(missing(aot_kernels()))  # in parallel with the just-in-time compiles below
    _jit_forms()
    with build_lock():  # the background build has ended
        pass
    ensure_compiled_kernels()  # what it could not build, if anything (and its failure said once)


def _jit_forms() -> None:
    """numba's forms of the gearbox step, the wind step and the monolithic solver, compiled (or loaded) once."""
    import numpy as np

    from components.compile.jit import load_compiled
    from components.model import kernel
    from components.model.assembly import Assembly
    from components.model.presets import table6_gearbox
    from components.model.wind import ConstantSpeed
    from components.reference.solver import simulate_monolithic

    kernel.jit_gearbox()
    wind = load_compiled(kernel.WIND)
    z = np.ones(4, dtype=complex)
    wind.rotate_and_sum(z, z.copy(), np.ones(4), np.ones(4))
    dt = table6_gearbox()
    simulate_monolithic(dt, ConstantSpeed(1.6), 0.01, kernel="compiled")
    assembly = Assembly(dt)
    many = np.zeros((kernel.BRIEF_EVALUATIONS // assembly.n_mesh + 1, assembly.n_mesh))
    assembly.law.evaluate(many, many)  # the contact law over many states (results, analyses)
