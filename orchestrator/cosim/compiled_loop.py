"""The stepping loop compiled with numba: the same FMI calls as the generated loop, without Python per call.

:func:`orchestrator.cosim.master.compile_step_loop` generates a Python loop per
system; every FMI call in it still goes through a ctypes function object
(argument conversion, ~0.4 us) and every coupling is a Python statement. This
module runs the same block of communication steps in one compiled function
(:func:`~orchestrator.cosim.compiled_loop_kernel.run_block`): the FMI functions are called through their addresses
(an indirect call, as a C host makes it), the system's layout is data (:func:`loop_plan`), so the function is
compiled once per machine and kept in numba's disk cache
(:mod:`components.compile.numba_cache`; no per-system compilation).

Same calls, same values, same order, same arithmetic as the generated loop (the
tests compare the recorded values exactly). Used by the master (``step_loop =
"auto"``) when numba imports, every FMU is a PythonFMU (their functions need the
GIL, which compiled code holds; a C FMU keeps the GIL-releasing generated loop),
no FMU has Integer, Boolean or String ports and no profiling timers are asked
for; otherwise the generated loop runs.

Measured (paper-60s, 8 FMI calls per step): the same calls from a compiled loop
take 24.5-26 us per step where the Python loop takes ~32 us.
"""

from __future__ import annotations

import ctypes
from ctypes import c_double
from functools import lru_cache
from pathlib import Path
from types import ModuleType
from typing import Callable

import numpy as np

from components.compile.aot import AotKernel, compiled_or_jit
from components.compile.sources import KernelSource

from .compiled_loop_layout import (
    FUNCTIONS,
    N_PLAN,
    P_COMPONENT,
    P_DO_STEP,
    P_FEED_END,
    P_FEED_FIRST,
    P_GET_REAL,
    P_IN_BUF,
    P_IN_VR,
    P_N_COUPLE,
    P_N_IN,
    P_N_OUT,
    P_OFFSET,
    P_OUT_VR,
    P_SET_REAL,
)

_module = None
_import_error: str | None = None


_SOURCE = Path(__file__).with_name("compiled_loop_kernel.py")


def _jit_kernel_module() -> ModuleType:
    """The numba module of the loop (the ahead-of-time builder's provider; raises without numba)."""
    from . import compiled_loop_kernel  # optional requirement: numba

    return compiled_loop_kernel


@lru_cache(maxsize=None)  # once per source file: an FMU's extracted copy may be gone by its next instance
def aot_loop_kernel() -> AotKernel:
    """The compiled stepping loop as :mod:`components.compile.aot` builds and finds it."""
    return AotKernel(KernelSource("loop", _SOURCE).shared_name, f"{__name__}:_jit_kernel_module", _SOURCE)


def _jit_module() -> tuple[ModuleType | None, str | None]:
    try:
        return _jit_kernel_module(), None
    except Exception as exc:  # noqa: BLE001 - numba missing or broken: the generated loop runs
        return None, f"{type(exc).__name__}: {exc}"


def _load():
    """The compiled part (ahead of time where built, else numba), or None with the reason (once per process)."""
    global _module, _import_error
    if _module is None and _import_error is None:
        _module, _import_error = compiled_or_jit(aot_loop_kernel(), _jit_module)
    return _module


def unavailable_reason(slots, timers) -> str | None:
    """Why the compiled loop cannot run this system (None: it can)."""
    from .fmi_runtime import runs_python

    if timers is not None:
        return "profiling timers need the generated loop"
    if any(s.ports is not None for s in slots):
        return "an FMU has Integer, Boolean or String ports"
    if not all(runs_python(s.inst.interface) for s in slots):
        return "an FMU is not a PythonFMU (its functions are called with the GIL released)"
    if _load() is None:
        return f"numba unavailable ({_import_error})"
    return None


def _address(fn) -> int:
    return ctypes.cast(fn, ctypes.c_void_p).value


def loop_plan(slots, algorithm: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list]:
    """The system's layout as arrays: (plan, feeds, coefficients, input buffer, objects to keep alive).

    All inputs of all slots share one float buffer (slot ``i``'s inputs at ``IN_BUF``); its
    ``fmi2SetReal`` reads from there.
    """
    position = {id(s): i for i, s in enumerate(slots)}
    n_inputs = sum(len(s.in_names) for s in slots)
    in_bufs = np.zeros(max(1, n_inputs))
    plan = np.zeros((len(slots), N_PLAN), dtype=np.int64)
    feeds, coefficients = [], []
    first = 0
    dsize = ctypes.sizeof(c_double)
    for i, s in enumerate(slots):
        inst = s.inst
        p = plan[i]
        p[P_DO_STEP], p[P_SET_REAL], p[P_GET_REAL] = (_address(inst.do_step), _address(inst.set_real),
                                                      _address(inst.get_real))
        p[P_COMPONENT] = int(inst.component)
        p[P_IN_VR], p[P_N_IN] = ctypes.addressof(s.in_vr), len(s.in_names)
        p[P_IN_BUF] = in_bufs.ctypes.data + first * dsize
        p[P_OUT_VR], p[P_N_OUT], p[P_N_COUPLE] = ctypes.addressof(s.out_vr), len(s.out_names), s.n_couple
        p[P_OFFSET] = s.col0 * dsize
        p[P_FEED_FIRST] = len(feeds)
        for j_in, src, col in s.feeds:
            upstream = algorithm == "gauss-seidel" and src < position[id(s)]
            transformed = j_in in s.linear
            feeds.append((first + j_in, col, int(upstream), int(transformed)))
            coefficients.append(s.linear[j_in] if transformed else (1.0, 0.0))
        p[P_FEED_END] = len(feeds)
        first += len(s.in_names)
    feed_table = np.array(feeds, dtype=np.int64).reshape(-1, 4) if feeds else np.zeros((0, 4), dtype=np.int64)
    coefficient_table = np.array(coefficients, dtype=float).reshape(-1, 2) if coefficients else np.zeros((0, 2))
    keep = [s.in_vr for s in slots] + [s.out_vr for s in slots]
    return plan, feed_table, coefficient_table, in_bufs, keep


def compiled_step_loop(slots, algorithm: str, extrapolation: str, stride: int, data: np.ndarray, ring: np.ndarray,
                       stop_type: type, finish_step: Callable) -> Callable:
    """``advance(k_start, k_end, t0, H) -> k_end`` running the compiled block (contract of ``compile_step_loop``).

    Call :func:`unavailable_reason` first. ``stop_type(slot, function, status, k)`` is raised on a
    failing status; ``finish_step`` is attached as ``advance.finish_step``.
    """
    module = _load()
    plan, feeds, coefficients, in_bufs, keep = loop_plan(slots, algorithm)
    status = np.zeros(4, dtype=np.int64)
    base = ring.ctypes.data
    linear = extrapolation == "linear"
    direct = ring is data
    run = module.run_block

    def advance(k_start: int, k_end: int, t0: float, H: float) -> int:
        k = run(k_start, k_end, t0, H, plan, feeds, coefficients, in_bufs, ring, data, base, stride, linear,
                direct, status)
        if k < k_end:
            slot, function, st, k_failed = (int(x) for x in status)
            raise stop_type(slot, FUNCTIONS[function], st, k_failed)
        return k_end

    advance.keep = (keep, in_bufs)  # the arrays the plan holds addresses of
    advance.finish_step = finish_step
    advance.source = f"compiled step loop ({Path(__file__).name}), {len(slots)} FMUs"
    return advance
