"""Linear-algebra primitives of the kernels: copy, matrix products, axpy, inversion.

Each is written once with numpy calls (what the interpreted kernel runs) and once as the loop
numba compiles without BLAS or LAPACK (``COMPILED``; :mod:`components.compile.jit` swaps them
in). Both perform the same floating-point operations in the same order - the products summed
from the first term on, as the loops do (``np.cumsum``, not BLAS, whose blocked sums differ in
the last bits) - so the interpreted and the compiled kernel compute the same numbers.
"""

from __future__ import annotations

import numpy as np


def copy(src, dst):
    """``dst[:] = src`` (1-D arrays of one length)."""
    dst[:] = src


def matvec(w, x, out):
    """``out = w @ x``."""
    out[:] = np.cumsum(w * x, axis=1)[:, -1]


def vecmat(x, w, out):
    """``out = x @ w``."""
    out[:] = np.cumsum(x[:, None] * w, axis=0)[-1]


def matmul(a, b, out):
    """``out = a @ b``."""
    out[:] = np.cumsum(a[:, :, None] * b[None, :, :], axis=1)[:, -1, :]


def vecmat_sum(a, wa, b, wb, tail, wt, out):
    """``out = a @ wa + b @ wb + tail @ wt``: the product of ``[a, b, tail] @ [wa; wb; wt]`` without joining them,
    summed from the first term of ``a`` to the last of ``tail``."""
    out[:] = np.cumsum(np.concatenate((a[:, None] * wa, b[:, None] * wb, tail[:, None] * wt)), axis=0)[-1]


def axpy(alpha, x, y):
    """``y += alpha x``."""
    y += alpha * x


def invert(g, out):
    """``out = g^-1`` by Gauss-Jordan elimination with partial pivoting (``g`` is overwritten)."""
    n = g.shape[0]
    out[:] = 0.0
    for i in range(n):
        out[i, i] = 1.0
    for col in range(n):
        pivot = col + int(np.argmax(np.abs(g[col:, col])))
        if pivot != col:
            g[[col, pivot]] = g[[pivot, col]]
            out[[col, pivot]] = out[[pivot, col]]
        inv_p = 1.0 / float(g[col, col])  # a zero pivot raises ZeroDivisionError, as in the compiled form
        g[col] *= inv_p
        out[col] *= inv_p
        f = g[:, col].copy()
        f[col] = 0.0
        rows = np.flatnonzero(f)
        if rows.size:
            g[rows] -= np.outer(f[rows], g[col])
            out[rows] -= np.outer(f[rows], out[col])
    return out


# ---------------------------------------------------------------- the compiled forms
def _copy_loop(src, dst):
    """:func:`copy` as a loop (numba's slice assignment checks and broadcasts: 4 x slower here)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


def _matvec_loop(w, x, out):
    for i in range(w.shape[0]):
        s = 0.0
        for j in range(x.shape[0]):
            s += w[i, j] * x[j]
        out[i] = s


def _vecmat_loop(x, w, out):
    for j in range(w.shape[1]):
        s = 0.0
        for i in range(x.shape[0]):
            s += x[i] * w[i, j]
        out[j] = s


def _matmul_loop(a, b, out):
    for i in range(a.shape[0]):
        for j in range(b.shape[1]):
            s = 0.0
            for k in range(b.shape[0]):
                s += a[i, k] * b[k, j]
            out[i, j] = s


def _vecmat_sum_loop(a, wa, b, wb, tail, wt, out):
    for j in range(out.shape[0]):
        s = 0.0
        for i in range(a.shape[0]):
            s += a[i] * wa[i, j]
        for i in range(b.shape[0]):
            s += b[i] * wb[i, j]
        for i in range(tail.shape[0]):
            s += tail[i] * wt[i, j]
        out[j] = s


def _axpy_loop(alpha, x, y):
    for i in range(x.shape[0]):
        y[i] += alpha * x[i]


def _invert_loop(g, out):
    n = g.shape[0]
    for i in range(n):
        for j in range(n):
            out[i, j] = 1.0 if i == j else 0.0
    for col in range(n):
        pivot = col
        best = abs(g[col, col])
        for r in range(col + 1, n):
            if abs(g[r, col]) > best:
                best = abs(g[r, col])
                pivot = r
        if pivot != col:
            for j in range(n):
                tmp = g[col, j]
                g[col, j] = g[pivot, j]
                g[pivot, j] = tmp
                tmp = out[col, j]
                out[col, j] = out[pivot, j]
                out[pivot, j] = tmp
        inv_p = 1.0 / g[col, col]
        for j in range(n):
            g[col, j] *= inv_p
            out[col, j] *= inv_p
        for r in range(n):
            if r != col:
                f = g[r, col]
                if f != 0.0:
                    for j in range(n):
                        g[r, j] -= f * g[col, j]
                        out[r, j] -= f * out[col, j]
    return out


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"copy": _copy_loop, "matvec": _matvec_loop, "vecmat": _vecmat_loop, "axpy": _axpy_loop,
            "vecmat_sum": _vecmat_sum_loop, "matmul": _matmul_loop, "invert": _invert_loop}
#: inlined into their callers by numba (no call boundary on the hot path)
INLINE = ("copy", "matvec", "vecmat", "vecmat_sum", "axpy")
