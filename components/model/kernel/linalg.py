"""Linear-algebra primitives of the kernels: copy, matrix products, axpy, inversion, LU factorisation and solve.

Each is written once with numpy calls (what the interpreted kernel runs) and once as the loop
numba compiles without BLAS or LAPACK (``COMPILED``; :mod:`components.compile.jit` swaps them
in). Both perform the same floating-point operations in the same order - the products summed
from the first term on, as the loops do (``np.add.accumulate``, not BLAS nor ``np.sum``, whose
blocked or pairwise sums differ in the last bits) - so the interpreted and the compiled kernel
compute the same numbers. A loop's sum starts from ``0.0`` and is never ``-0.0``; the numpy forms
store their sums plus ``0.0`` (:func:`sums`), so an all-zero sum has the loop's sign too. A numpy
form may add terms that the loop skips because they are exactly zero (a product over a pattern
summed densely, the padding of a sparse row): adding ``+-0`` changes a sum at most in the sign of
a zero, which the stored ``+ 0.0`` settles.
"""

from __future__ import annotations

import math

import numpy as np


def copy(src, dst):
    """``dst[:] = src`` (1-D arrays of one length)."""
    dst[:] = src


def sums(terms, out):
    """``out = sum of terms`` along the last axis, from the first term on (numpy's ``add.accumulate`` adds in
    order, unlike ``sum``), stored plus ``0.0``: with the sign a loop's sum has (never ``-0.0``)."""
    np.add(np.add.accumulate(terms, -1)[..., -1], 0.0, out=out)


def matvec(w, x, out):
    """``out = w @ x``."""
    sums(w * x, out)


def vecmat(x, w, out):
    """``out = x @ w``."""
    sums((x[:, None] * w).T, out)


def matmul(a, b, out):
    """``out = a @ b``."""
    sums(a[:, None, :] * b.T[None, :, :], out)


def vecmat_add(x, w, out):
    """``out += x @ w`` (each column's sum from the first term on, then added)."""
    out += np.add.accumulate((x[:, None] * w).T, -1)[..., -1] + 0.0


def vecmat_sum(a, wa, b, wb, tail, wt, out):
    """``out = a @ wa + b @ wb + tail @ wt``: the product of ``[a, b, tail] @ [wa; wb; wt]`` without joining them,
    summed from the first term of ``a`` to the last of ``tail``."""
    sums(np.concatenate((a[:, None] * wa, b[:, None] * wb, tail[:, None] * wt)).T, out)


def axpy(alpha, x, y):
    """``y += alpha x``."""
    y += alpha * x


def axpy2(alpha, x, beta, w, y):
    """``y += alpha x + beta w``."""
    y += alpha * x + beta * w


def dot(x, y):
    """``x . y``, summed from the first term on."""
    if x.shape[0] == 0:
        return 0.0
    return float(np.add.accumulate(x * y)[-1]) + 0.0


def subtract(a, b, out):
    """``out = a - b``."""
    np.subtract(a, b, out=out)


def negate(x):
    """``x = -x``."""
    np.negative(x, out=x)


def matvec_pattern(w, index, x, out):
    """``out = w @ x`` over the nonzero pattern of ``w`` only: ``out[i] = sum_p w[i, index[i, p]] x[index[i, p]]``
    (``index``: ascending, ``< 0`` padding), summed from the first; ``w`` is zero outside the pattern.

    The numpy form sums whole rows (:func:`matvec`) where ``x`` is finite: the terms outside the pattern are zero.
    """
    if all(map(math.isfinite, x.tolist())):
        matvec(w, x, out)
        return
    valid = index >= 0.0
    safe = np.where(valid, index, 0.0).astype(np.intp)
    sums(np.where(valid, np.take_along_axis(w, safe, 1) * x[safe], 0.0), out)


def sparse_vecmat(x, index, value, out):
    """``out = x @ w`` for a sparse ``w`` held by columns: ``out[j] = sum_p x[index[j, p]] value[j, p]`` over the
    nonzero rows of column ``j`` in ascending order (``index < 0``: padding, its ``value`` 0), summed from the
    first.
    """
    terms = x.take(index.astype(np.intp))
    terms *= value  # a padding term is x[-1] * 0: zero where that is finite
    if not math.isfinite(x[-1]):
        terms = np.where(index >= 0.0, terms, 0.0)
    sums(terms, out)


def invert(g, out):
    """``out = g^-1`` by Gauss-Jordan elimination with partial pivoting (``g`` is overwritten).

    The numpy form eliminates on ``[g, I]`` (each row operation once on both halves, the rows whose
    factor is zero left alone, as the loop does).
    """
    n = g.shape[0]
    aug = np.zeros((n, 2 * n))
    aug[:, :n] = g
    aug.reshape(-1)[n::2 * n + 1] = 1.0  # the identity on the right
    for col in range(n):
        f = aug[:, col]
        pivot = col + int(np.abs(f[col:]).argmax())
        if pivot != col:
            aug[[col, pivot]] = aug[[pivot, col]]
        row = aug[col]
        row *= 1.0 / float(row[col])  # a zero pivot raises ZeroDivisionError, as in the compiled form
        rows = f != 0.0
        rows[col] = False
        np.subtract(aug, f[:, None] * row, out=aug, where=rows[:, None])
    g[:] = aug[:, :n]
    out[:] = aug[:, n:]
    return out


def lu_factor(a, piv):
    """LU factorisation with partial pivoting in place: ``P a = L U`` (``L`` unit lower, below the diagonal of
    ``a``; ``U`` on and above it), the row swapped with row ``k`` in ``piv[k]`` (as a float)."""
    n = a.shape[0]
    for k in range(n):
        p = k + int(np.abs(a[k:, k]).argmax())
        piv[k] = p
        if p != k:
            a[[k, p]] = a[[p, k]]
        f = a[k + 1:, k]
        f *= 1.0 / float(a[k, k])  # a zero pivot raises ZeroDivisionError, as in the compiled form
        rest = a[k + 1:, k + 1:]  # the rows whose factor is zero left alone, as the loop does
        np.subtract(rest, f[:, None] * a[k, k + 1:], out=rest, where=(f != 0.0)[:, None])


def lu_pattern(lu, lower, upper):
    """The nonzero rows of every column of ``L`` (below the diagonal, ascending) into ``lower`` and of ``U`` (above
    it, ascending) into ``upper``, padded with -1: what :func:`lu_solve` visits."""
    n = lu.shape[0]
    rows = np.arange(n)
    nonzero = lu.T != 0.0  # [column, row]
    for side, out in ((rows[None, :] > rows[:, None], lower), (rows[None, :] < rows[:, None], upper)):
        found = np.where(nonzero & side, rows[None, :], n)
        found.sort(axis=1)  # each column's rows to the front, ascending; n (none) behind them
        out[:] = np.where(found < n, found, -1)


def lu_solve(lu, piv, lower, upper, b, out):
    """``out = a^-1 b`` from :func:`lu_factor`'s ``lu`` and ``piv``: column-oriented substitutions over the nonzero
    rows of each column (:func:`lu_pattern`'s ``lower`` and ``upper``; the numpy form finds them in ``lu``)."""
    n = lu.shape[0]
    out[:] = b
    for k, p in enumerate(piv.astype(np.intp).tolist()):
        if p != k:
            out[k], out[p] = out[p], out[k]
    for j in range(n - 1):
        column = lu[j + 1:, j]
        below = out[j + 1:]
        np.subtract(below, column * out[j], out=below, where=column != 0.0)
    for j in range(n - 1, -1, -1):
        out[j] = out[j] / lu[j, j]
        column = lu[:j, j]
        above = out[:j]
        np.subtract(above, column * out[j], out=above, where=column != 0.0)


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


def _vecmat_add_loop(x, w, out):
    for j in range(out.shape[0]):
        s = 0.0
        for i in range(x.shape[0]):
            s += x[i] * w[i, j]
        out[j] += s


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


def _axpy2_loop(alpha, x, beta, w, y):
    for i in range(x.shape[0]):
        y[i] += alpha * x[i] + beta * w[i]


def _dot_loop(x, y):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i] * y[i]
    return s


def _subtract_loop(a, b, out):
    for i in range(out.shape[0]):
        out[i] = a[i] - b[i]


def _negate_loop(x):
    for i in range(x.shape[0]):
        x[i] = -x[i]


def _matvec_pattern_loop(w, index, x, out):
    for i in range(index.shape[0]):
        s = 0.0
        for p in range(index.shape[1]):
            j = int(index[i, p])
            if j < 0:
                break
            s += w[i, j] * x[j]
        out[i] = s


def _sparse_vecmat_loop(x, index, value, out):
    for j in range(index.shape[0]):
        s = 0.0
        for p in range(index.shape[1]):
            i = int(index[j, p])
            if i < 0:
                break
            s += x[i] * value[j, p]
        out[j] = s


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


def _lu_factor_loop(a, piv):
    n = a.shape[0]
    for k in range(n):
        p = k
        best = abs(a[k, k])
        for r in range(k + 1, n):
            if abs(a[r, k]) > best:
                best = abs(a[r, k])
                p = r
        piv[k] = p
        if p != k:
            for j in range(n):
                tmp = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = tmp
        inv_p = 1.0 / a[k, k]
        for r in range(k + 1, n):
            a[r, k] *= inv_p
        for r in range(k + 1, n):
            f = a[r, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    a[r, j] -= f * a[k, j]


def _lu_pattern_loop(lu, lower, upper):
    n = lu.shape[0]
    for j in range(n):
        c = 0
        for i in range(j + 1, n):
            if lu[i, j] != 0.0:
                lower[j, c] = i
                c += 1
        for i in range(c, n):
            lower[j, i] = -1.0
        c = 0
        for i in range(j):
            if lu[i, j] != 0.0:
                upper[j, c] = i
                c += 1
        for i in range(c, n):
            upper[j, i] = -1.0


def _lu_solve_loop(lu, piv, lower, upper, b, out):
    n = lu.shape[0]
    for i in range(n):
        out[i] = b[i]
    for k in range(n):
        p = int(piv[k])
        if p != k:
            tmp = out[k]
            out[k] = out[p]
            out[p] = tmp
    for j in range(n):
        x = out[j]
        for c in range(n):
            i = int(lower[j, c])
            if i < 0:
                break
            out[i] -= lu[i, j] * x
    for j in range(n - 1, -1, -1):
        out[j] = out[j] / lu[j, j]
        x = out[j]
        for c in range(n):
            i = int(upper[j, c])
            if i < 0:
                break
            out[i] -= lu[i, j] * x


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"copy": _copy_loop, "matvec": _matvec_loop, "vecmat": _vecmat_loop, "vecmat_add": _vecmat_add_loop,
            "axpy": _axpy_loop, "axpy2": _axpy2_loop, "dot": _dot_loop, "subtract": _subtract_loop,
            "negate": _negate_loop, "vecmat_sum": _vecmat_sum_loop, "matmul": _matmul_loop, "invert": _invert_loop,
            "lu_factor": _lu_factor_loop, "lu_solve": _lu_solve_loop, "lu_pattern": _lu_pattern_loop,
            "sparse_vecmat": _sparse_vecmat_loop, "matvec_pattern": _matvec_pattern_loop}
#: inlined into their callers by numba (no call boundary on the hot path)
INLINE = ("copy", "matvec", "vecmat", "vecmat_add", "vecmat_sum", "axpy", "axpy2", "dot", "subtract", "negate",
          "sparse_vecmat", "matvec_pattern")
