"""The stepping plan executed by compiled code: the same FMI calls as the Python loop, without Python per call.

:class:`~orchestrator.cosim.stepping.python_loop.PythonLoop` calls every FMI function
through a ctypes function object (argument conversion, ~0.4 us a call) and computes
every input in Python. This executor runs a whole block of communication steps in one
compiled function (:func:`~orchestrator.cosim.stepping.compiled_block.run_block`): the
FMI functions are called through their addresses (an indirect call, as a C host makes
it) and the plan is data (:func:`plan_arrays`: the same numbers as the
:class:`~orchestrator.cosim.stepping.plan.StepPlan`, as arrays), so the function is
compiled once per machine, ahead of time into the user cache
(:mod:`orchestrator.cosim.compiled_kernels`) or else by numba into its disk cache
(:mod:`components.compile.numba_cache`); there is no per-system compilation.

Same calls, same values, same order, same arithmetic as the Python loop (the tests
compare the recorded values exactly). The master uses it (``step_loop = "auto"``)
when it loads, every FMU is a PythonFMU (their functions need the GIL, which compiled
code holds; a C FMU's calls go through ctypes, which releases it), no FMU has
Integer, Enumeration, Boolean or String ports, no algebraic loop is iterated and no
profile is asked for (:func:`unavailable_reason`); otherwise the Python loop runs.

Measured (``python benchmarks/bench_cosim.py --no-libcosim``; paper-60s, 8 FMI calls
per step): 26.5-33 us per communication step in the stepping loop, most of it the
FMUs' own work; with three trivial FMUs (``python benchmarks/bench_plumbing.py
--repeat 5``) the loop takes 6.1-8.0 us per step, less than the bare ctypes calls of
a hand-written Python loop (15.5 us).
"""

from __future__ import annotations

import ctypes
from functools import lru_cache
from pathlib import Path
from types import ModuleType

import numpy as np

from components.compile.aot import AotKernel, compiled_or_jit
from components.compile.jit import jit_enabled, jit_off_reason
from components.compile.sources import KernelSource

from ..fmi_runtime import runs_python
from ..values import TextStore
from .compiled_layout import (
    F_COLUMN,
    F_INPUT,
    F_TRANSFORMED,
    F_UPSTREAM,
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
from .plan import RowBuffers, StepFailed, StepPlan
from .python_loop import PythonLoop

_module = None
_import_error: str | None = None

_SOURCE = Path(__file__).with_name("compiled_block.py")


def _jit_kernel_module() -> ModuleType:
    """The numba module of the loop (the ahead-of-time builder's provider; raises without numba)."""
    from . import compiled_block  # optional requirement: numba

    return compiled_block


@lru_cache(maxsize=None)  # once per source file: an FMU's extracted copy may be gone by its next instance
def aot_loop_kernel() -> AotKernel:
    """The compiled stepping loop as :mod:`components.compile.aot` builds and finds it."""
    return AotKernel(KernelSource("loop", _SOURCE).shared_name, f"{__name__}:_jit_kernel_module", _SOURCE)


def _jit_module() -> tuple[ModuleType | None, str | None]:
    if not jit_enabled():
        return None, jit_off_reason()
    try:
        return _jit_kernel_module(), None
    except Exception as exc:  # noqa: BLE001 - numba missing or broken: the Python loop runs
        return None, f"{type(exc).__name__}: {exc}"


def _load():
    """The compiled part (ahead of time where built, else numba), or None with the reason (once per process)."""
    global _module, _import_error
    if _module is None and _import_error is None:
        _module, _import_error = compiled_or_jit(aot_loop_kernel(), _jit_module)
    return _module


def unavailable_reason(plan: StepPlan, profiling: bool = False, iterating_loops: bool = False) -> str | None:
    """Why the compiled loop cannot run this plan (None: it can)."""
    if profiling:
        return "profiling timers need the Python loop"
    if iterating_loops:
        return "algebraic loops are iterated by the Python loop"
    if any(fmu.ports is not None for fmu in plan.fmus):
        return "an FMU has Integer, Enumeration, Boolean or String ports"
    if not all(runs_python(fmu.instance.interface) for fmu in plan.fmus):
        return "an FMU is not a PythonFMU (its functions are called with the GIL released)"
    if _load() is None:
        return f"the compiled loop is unavailable ({_import_error})"
    return None


def _address(fn) -> int:
    return ctypes.cast(fn, ctypes.c_void_p).value


def plan_arrays(plan: StepPlan) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The plan as the compiled block reads it: ``(fmus, feeds, coefficients)``.

    ``fmus`` (int64, one row per FMU, columns ``P_*`` of :mod:`.compiled_layout`): the
    FMI function addresses, the component, the value-reference and buffer addresses and
    counts, the output columns' byte offset and the FMU's range of rows in ``feeds``.
    ``feeds`` (int64, columns ``F_*``): input index, source column, upstream, transformed;
    ``coefficients`` (float): each feed's ``(factor, offset)``.
    """
    fmus = np.zeros((len(plan.fmus), N_PLAN), dtype=np.int64)
    feeds = np.zeros((sum(len(f.feeds) for f in plan.fmus), 4), dtype=np.int64)
    coefficients = np.zeros((len(feeds), 2))
    n = 0
    for fmu in plan.fmus:
        inst = fmu.instance
        row = fmus[fmu.slot]
        row[P_DO_STEP], row[P_SET_REAL], row[P_GET_REAL] = (_address(inst.do_step), _address(inst.set_real),
                                                            _address(inst.get_real))
        row[P_COMPONENT] = int(inst.component)
        row[P_IN_VR], row[P_N_IN], row[P_IN_BUF] = fmu.input_vr_address, fmu.n_inputs, fmu.input_address
        row[P_OUT_VR], row[P_N_OUT], row[P_N_COUPLE] = fmu.output_vr_address, fmu.n_outputs, fmu.n_coupling
        row[P_OFFSET] = fmu.output_offset
        row[P_FEED_FIRST] = n
        for feed in fmu.feeds:
            feeds[n, F_INPUT], feeds[n, F_COLUMN] = feed.input, feed.column
            feeds[n, F_UPSTREAM], feeds[n, F_TRANSFORMED] = feed.upstream, feed.transformed
            coefficients[n] = feed.factor, feed.offset
            n += 1
        row[P_FEED_END] = n
    return fmus, feeds, coefficients


class CompiledLoop:
    """Executes a :class:`StepPlan` block by block in compiled code (contract of
    :class:`~orchestrator.cosim.stepping.python_loop.PythonLoop`; call :func:`unavailable_reason` first).

    The rare completion of a step after an FMU ended the run (:meth:`finish_step`) runs
    in the Python loop over the same plan and buffers.
    """

    loop_solver = None

    def __init__(self, plan: StepPlan, buffers: RowBuffers, text: TextStore) -> None:
        self.plan = plan  # holds the buffers and value references whose addresses the arrays carry
        self.buffers = buffers
        self._run_block = _load().run_block
        self._fmus, self._feeds, self._coefficients = plan_arrays(plan)
        self._status = np.zeros(4, dtype=np.int64)
        self._python = PythonLoop(plan, buffers, text)

    def advance(self, k_start: int, k_end: int, t0: float, H: float) -> int:
        """Steps ``k_start <= k < k_end``; returns ``k_end`` (raises StepFailed on a failing status)."""
        b = self.buffers
        k = self._run_block(k_start, k_end, t0, H, self._fmus, self._feeds, self._coefficients,
                            self.plan.input_values, b.ring, b.block, b.address, self.plan.stride, self.plan.linear,
                            b.direct, self._status)
        if k < k_end:
            slot, function, status, k_failed = (int(x) for x in self._status)
            raise StepFailed(slot, FUNCTIONS[function], status, k_failed)
        return k_end

    def finish_step(self, k: int, first: int, t0: float, H: float, k_start: int) -> int:
        """See :meth:`PythonLoop.finish_step`."""
        return self._python.finish_step(k, first, t0, H, k_start)
