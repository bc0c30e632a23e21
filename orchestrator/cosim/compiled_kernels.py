"""The kernels a run steps, compiled ahead of time once per machine: the Gearbox's, the wind source's, the loop's.

:mod:`components.compile.aot` compiles each kernel's entry points into an extension module
that imports without numba, so a run's process (host and in-process FMUs) carries no numba
and llvmlite (~75 MB less resident memory, ~0.5 s less start-up: ``bench_long_run.py``).
:func:`ensure_compiled_kernels` builds the missing ones in a child process; ``dtcosim
build`` and ``dtcosim run`` (whenever it may build FMUs) call it. Where it cannot build (no
numba, no C compiler) it says so once and the kernels run just in time, as before.
"""

from __future__ import annotations

from typing import Callable

from components.compile.aot import AotKernel, aot_directory, build_in_subprocess, enabled, failed_before, missing
from components.model.kernel import AHEAD_OF_TIME

from .stepping.compiled_loop import aot_loop_kernel


def aot_kernels() -> tuple[AotKernel, ...]:
    """Every kernel compiled ahead of time, keyed by the installed sources."""
    return (*(AotKernel.of(source) for source in AHEAD_OF_TIME), aot_loop_kernel())


def ensure_compiled_kernels(report: Callable[[str], None] | None = None, retry: bool = False) -> str | None:
    """Build the kernels missing in :func:`~components.compile.aot.aot_directory`.

    A kernel version whose build failed on this machine before (no C compiler, say) is not
    retried on every run, only with ``retry`` (``dtcosim build``) or once its sources change.

    Returns
    -------
    str or None
        None when every kernel is there (or ``DTCOSIM_AOT=0``); else why they could not be built
        (also given to ``report``; the run goes on with numba's just-in-time kernels).
    """
    if not enabled():
        return None
    todo = missing(aot_kernels())
    if not retry:
        earlier = [(k, failed_before(k)) for k in todo]
        earlier = [(k, reason) for k, reason in earlier if reason is not None]
        if earlier:
            todo = [k for k in todo if k not in dict(earlier)]
            if not todo:
                problem = earlier[0][1]
                if report:
                    report(f"kernels not compiled ahead of time on this machine ({problem}); numba compiles them "
                           "just in time (`dtcosim build` tries again)")
                return problem
    if not todo:
        return None
    if report:
        report(f"compiling {len(todo)} kernel(s) ahead of time into {aot_directory()} (once per machine and "
               "version, ~15 s) ...")
    problem = build_in_subprocess(todo)
    if problem and report:
        report(f"kernels not compiled ahead of time ({problem}); numba compiles them just in time instead")
    return problem
