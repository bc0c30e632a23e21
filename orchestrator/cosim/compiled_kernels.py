"""The kernels a run steps, compiled ahead of time once per machine: the Gearbox's, the wind source's, the loop's.

:mod:`components.compile.aot` compiles each kernel's entry points into an extension module
that imports without numba, so a run's process (host and in-process FMUs) carries no numba
and llvmlite (~75 MB less resident memory, ~0.5 s less start-up: ``bench_long_run.py``).
:func:`ensure_compiled_kernels` builds the missing ones: ``dtcosim build`` waits for them;
``dtcosim run`` (whenever it may build FMUs) starts their build in the background and steps
this run's kernels interpreted meanwhile (compiling them just in time would cost as much as
the build), so that the first run of a machine does not wait for a compiler. Where they
cannot be built (no C compiler) numba compiles them just in time into its cache instead, in the
same way (in the background for a run, meanwhile interpreted; waited for by builds and studies),
and later runs load its machine code; without numba the kernels run interpreted.
"""

from __future__ import annotations

import importlib.util
import os
import time
from typing import Callable

from components.compile.aot import (
    AotKernel,
    aot_directory,
    background_builder,
    build_in_background,
    build_in_subprocess,
    build_lock,
    build_log,
    enabled,
    failed_before,
    is_warm,
    missing,
)
from components.compile.jit import JIT_OFF_REASON_VARIABLE, JIT_VARIABLE, jit_enabled
from components.compile.user_cache import CACHE_VARIABLE, user_cache_root
from components.errors import os_error_text
from components.model.kernel import AHEAD_OF_TIME

from .stepping.compiled_loop import aot_loop_kernel

#: how long a build waits for another process's build of the kernels to end [s]
WAIT_FOR_BACKGROUND_S = 900.0


def aot_kernels() -> tuple[AotKernel, ...]:
    """Every kernel compiled ahead of time, keyed by the installed sources."""
    return (*(AotKernel.of(source) for source in AHEAD_OF_TIME), aot_loop_kernel())


def ensure_compiled_kernels(report: Callable[[str], None] | None = None, retry: bool = False,
                            background: bool = False) -> str | None:
    """Build the kernels missing in :func:`~components.compile.aot.aot_directory`.

    A kernel version whose build failed on this machine before (no C compiler, say) is not
    retried on every run, only with ``retry`` (``dtcosim build``) or once its sources change;
    numba compiles it just in time into its cache instead, once, in the same way as the build
    (in the background, or now).

    Parameters
    ----------
    report : callable(str), optional
        Receives what happens, in one line each.
    retry : bool
        Build also the kernels whose build failed before.
    background : bool
        Start the build in a detached process (:func:`~components.compile.aot.build_in_background`;
        one already running is not started again) and return at once; until the modules are there,
        this process compiles nothing just in time (``DTCOSIM_JIT=0`` for it and its FMUs and
        workers): its kernels run interpreted. False: build now (after a build in the background,
        if one runs) and return when done.

    Returns
    -------
    str or None
        None when every kernel is there (or ``DTCOSIM_AOT=0``); else why they are not (being built
        in the background, or could not be built: the run goes on with numba's just-in-time kernels,
        or interpreted while those are compiled in the background; the per-user cache cannot be
        written: the kernels run interpreted, ``DTCOSIM_JIT=0``).
    """
    if not enabled():
        return None
    todo = missing(aot_kernels())
    unwritable = _unwritable_cache() if todo else None
    if unwritable is not None:
        return _interpreted(unwritable, report)
    if not retry:
        earlier = [(k, failed_before(k)) for k in todo]
        earlier = [(k, reason) for k, reason in earlier if reason is not None]
        if earlier:
            todo = [k for k in todo if k not in dict(earlier)]
            if not todo:
                return _just_in_time([k for k, _ in earlier], earlier[0][1], report, background)
    if not todo:
        return None
    if background:
        return _in_background(todo, report)
    running = background_builder()
    if running is not None and report:
        report(f"waiting for the kernels being compiled ahead of time by another process (pid {running}) ...")
    try:
        with build_lock(WAIT_FOR_BACKGROUND_S):  # one builder at a time: what another built is not built again
            todo = [k for k in missing(aot_kernels()) if retry or failed_before(k) is None]
            if not todo:
                return None
            if report:
                report(f"compiling {len(todo)} kernel(s) ahead of time into {aot_directory()} (once per machine and "
                       "version) ...")
            start = time.perf_counter()
            problem = build_in_subprocess(todo)
    except (OSError, TimeoutError) as exc:  # an unwritable cache, a builder that never ends: just in time instead
        problem = f"{type(exc).__name__}: {exc}"
    if problem:
        return _just_in_time(todo, problem, report, background=False)
    if report:
        report(f"compiled {len(todo)} kernel(s) ahead of time in {time.perf_counter() - start:.0f} s")
    return None


def _just_in_time(kernels: list[AotKernel], problem: str, report: Callable[[str], None] | None,
                  background: bool) -> str:
    """The kernels could not be compiled ahead of time (``problem``): numba compiles them just in time instead, once
    per machine into its cache (:func:`~components.compile.aot.warm_just_in_time`), so that no run waits for it
    unannounced (~35 s of CPU for the gearbox kernel). ``background``: in the detached builder, this process's
    kernels interpreted meanwhile; else now, waiting."""
    numba = importlib.util.find_spec("numba") is not None
    cold = [k for k in kernels if not is_warm(k)] if numba and jit_enabled() else []
    if cold and background:
        running = background_builder()
        pid = running if running is not None else build_in_background(cold, after=os.getpid())
        if pid is not None:
            os.environ[JIT_VARIABLE] = "0"
            os.environ[JIT_OFF_REASON_VARIABLE] = f"being compiled just in time in the background for later runs " \
                                                  f"(pid {pid})"
            if report:
                report(f"kernels not compiled ahead of time on this machine ({problem}): numba compiles them just in "
                       f"time in the background for later runs instead (pid {pid}, log {build_log()}); until then, "
                       "runs step them interpreted, which takes longer (`dtcosim build` tries the ahead-of-time "
                       "build again)")
            return problem
    elif cold:
        said = _compile_just_in_time_now(cold, problem, report)
        if said is not None:
            if report:
                report(said)
            return problem
    if report:
        report(f"kernels not compiled ahead of time on this machine ({problem}); numba runs them compiled just in "
               "time (`dtcosim build` tries the ahead-of-time build again)")
    return problem


def _compile_just_in_time_now(cold: list[AotKernel], problem: str, report: Callable[[str], None] | None) -> str | None:
    """Compile ``cold`` just in time into numba's cache now, after a builder in progress; what came of it, or None
    where that builder compiled them all."""
    running = background_builder()
    if running is not None and report:
        report(f"waiting for the kernels being compiled in the background by another process (pid {running}) ...")
    try:
        with build_lock(WAIT_FOR_BACKGROUND_S):  # one builder at a time: what another compiled is not compiled again
            cold = [k for k in cold if not is_warm(k)]
            if not cold:
                return None
            if report:
                report(f"kernels not compiled ahead of time ({problem}): numba compiles them just in time into its "
                       "cache instead (once per machine and version) ...")
            start = time.perf_counter()
            not_warm = build_in_subprocess(cold, just_in_time=True)
    except (OSError, TimeoutError) as exc:
        not_warm = f"{type(exc).__name__}: {exc}"
    if not_warm:
        return f"not compiled just in time either ({not_warm}): each process compiles them itself"
    return f"compiled {len(cold)} kernel(s) just in time in {time.perf_counter() - start:.0f} s"


def _interpreted(unwritable: str, report: Callable[[str], None] | None) -> str:
    """Nothing compiled: without a cache to keep them in, kernels compiled just in time would be compiled anew by
    every process (~35 s each), so this one and its FMUs and workers run them interpreted."""
    problem = f"the per-user cache cannot be written: {unwritable}"
    os.environ[JIT_VARIABLE] = "0"
    os.environ[JIT_OFF_REASON_VARIABLE] = problem
    if report:
        report(f"the per-user cache {user_cache_root()} cannot be written ({unwritable}): the kernels are not "
               f"compiled, and runs step them interpreted, which takes longer ({CACHE_VARIABLE} chooses a "
               "writable folder)")
    return problem


def _unwritable_cache() -> str | None:
    """Why the compiled kernels' folder of the per-user cache cannot be created (None: it can)."""
    try:
        aot_directory().mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        return os_error_text(exc)
    return None


def _in_background(todo: list[AotKernel], report: Callable[[str], None] | None) -> str:
    """The build of ``todo`` in the background (started, or already running), and this process's kernels interpreted."""
    running = background_builder()
    # compiling once this command has ended (or after a while): a short first run has the machine to itself
    pid = running if running is not None else build_in_background(todo, after=os.getpid())
    if pid is None:  # numba missing: the kernels run interpreted (each FMU says so)
        return "the kernels could not be compiled in the background"
    os.environ[JIT_VARIABLE] = "0"  # compiling them just in time now would cost as much as the build
    os.environ[JIT_OFF_REASON_VARIABLE] = f"being compiled in the background for later runs (pid {pid})"
    if report:
        what = (f"the kernels are still being compiled in the background (pid {pid}" if running is not None
                else f"compiling {len(todo)} kernel(s) ahead of time in the background for later runs (pid {pid}")
        report(f"{what}, log {build_log()}); until they are built, runs step them interpreted, which takes longer")
    return f"being compiled in the background (pid {pid})"
