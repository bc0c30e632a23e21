"""numba part of :mod:`orchestrator.cosim.stepping.compiled_loop` (imported only where numba is installed).

:func:`run_block` steps a block of communication steps of a system described by
the plan arrays of :func:`orchestrator.cosim.stepping.compiled_loop.plan_arrays`,
calling the FMI functions through their addresses. It is
:meth:`orchestrator.cosim.stepping.python_loop.PythonLoop.advance` for Real-only
systems, statement for statement.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir  # optional requirement (comes with numba)
from numba import njit, types  # optional requirement: without numba the Python loop runs
from numba.extending import intrinsic

from components.compile.numba_cache import enable_stable_cache

from .compiled_layout import (
    F_COLUMN,
    F_INPUT,
    F_TRANSFORMED,
    F_UPSTREAM,
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


i8p = ir.IntType(8).as_pointer()

@intrinsic
def _call_do_step(typingctx, fn, component, t, h, flag):
    """``fmi2DoStep(component, t, h, flag)`` through the function's address."""
    sig = types.int32(types.int64, types.int64, types.float64, types.float64, types.int32)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(32), [i8p, ir.DoubleType(), ir.DoubleType(), ir.IntType(32)])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.inttoptr(args[1], i8p), args[2], args[3], args[4]])

    return sig, codegen

@intrinsic
def _call_values(typingctx, fn, component, vr, n, values):
    """``fmi2GetReal`` / ``fmi2SetReal(component, vr, n, values)`` through the function's address."""
    sig = types.int32(types.int64, types.int64, types.int64, types.int64, types.int64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(32), [i8p, i8p, ir.IntType(64), i8p])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.inttoptr(args[1], i8p), builder.inttoptr(args[2], i8p), args[3],
                                builder.inttoptr(args[4], i8p)])

    return sig, codegen

@njit(cache=False)
def run_block(k_start, k_end, t0, h, plan, feeds, coefficients, in_bufs, ring, data, base, stride, linear,
               direct, status):
    """Steps ``k_start <= k < k_end`` (see :class:`~orchestrator.cosim.stepping.plan.RowBuffers`); returns the
    steps done.

    On a failing status (> fmi2Warning) ``status`` gets (slot, function code, status, k) and the
    step it happened in is returned as done-so-far (the caller raises StepFailed).
    """
    n_cols = ring.shape[1]
    flat = ring.reshape(-1)
    c = 1 - k_start
    r0 = k_start // stride + 1
    for k in range(k_start, k_end):
        t = t0 + k * h
        if direct:
            o0 = (k + c) * n_cols
            o1 = o0 + n_cols
            om = o0 - n_cols
        else:
            o1 = ((k + 1) % 3) * n_cols
            o0 = (k % 3) * n_cols
            om = ((k - 1) % 3) * n_cols
        sample = (k + 1) % stride == 0
        a1 = base + o1 * 8
        for i in range(plan.shape[0]):
            p = plan[i]
            for f in range(p[P_FEED_FIRST], p[P_FEED_END]):
                col = feeds[f, F_COLUMN]
                if feeds[f, F_UPSTREAM] != 0:
                    latest, previous, a = o1, o0, 0.5
                else:
                    latest, previous, a = o0, om, 1.5
                if linear:
                    value = a * flat[latest + col] + (1.0 - a) * flat[previous + col]
                else:
                    value = flat[latest + col]
                if feeds[f, F_TRANSFORMED] != 0:
                    value = coefficients[f, 0] * value + coefficients[f, 1]
                in_bufs[feeds[f, F_INPUT]] = value
            if p[P_N_IN] > 0:
                st = _call_values(p[P_SET_REAL], p[P_COMPONENT], p[P_IN_VR], p[P_N_IN], p[P_IN_BUF])
                if st > 1:
                    status[0], status[1], status[2], status[3] = i, 0, st, k
                    return k
            st = _call_do_step(p[P_DO_STEP], p[P_COMPONENT], t, h, np.int32(1))
            if st > 1:
                status[0], status[1], status[2], status[3] = i, 1, st, k
                return k
            n = p[P_N_OUT] if (stride == 1 or sample) else p[P_N_COUPLE]
            if n > 0:
                st = _call_values(p[P_GET_REAL], p[P_COMPONENT], p[P_OUT_VR], n, a1 + p[P_OFFSET])
                if st > 1:
                    status[0], status[1], status[2], status[3] = i, 2, st, k
                    return k
        if not direct and sample:
            row = (k + 1) // stride - r0
            src = ((k + 1) % 3) * n_cols
            for j in range(n_cols):
                data[row, j] = flat[src + j]
    return k_end

#: entry point of the ahead-of-time compiled module (:mod:`components.compile.aot`) and its signature
AOT_EXPORTS = {
    "run_block": "i8(i8, i8, f8, f8, i8[:, ::1], i8[:, ::1], f8[:, ::1], f8[::1], f8[:, ::1], f8[:, ::1], i8, i8, "
                 "b1, b1, i8[::1])",
}
#: True when the machine code is cached on disk (see :mod:`components.compile.numba_cache`)
DISK_CACHE = enable_stable_cache((run_block,), __file__, __name__)


