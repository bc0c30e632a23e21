"""Sparse rows and columns of the assembly's matrices: what the kernel's sparse products walk."""

from __future__ import annotations

import numpy as np


def column_sparsity(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nonzero rows of every column of ``w`` and their entries, ascending, padded with -1 / 0.

    Returns
    -------
    index, value : ndarray, shape (n_columns, width)
        ``width`` is the most nonzeros of one column (at least 1); the kernel's sparse products
        (:func:`components.model.kernel.linalg.sparse_vecmat`) stop at the first negative index.
    """
    columns = [np.flatnonzero(w[:, j]) for j in range(w.shape[1])]
    width = max([1] + [c.size for c in columns])
    index = np.full((w.shape[1], width), -1.0)
    value = np.zeros((w.shape[1], width))
    for j, rows in enumerate(columns):
        index[j, : rows.size] = rows
        value[j, : rows.size] = w[rows, j]
    return index, value


def dense_rows(rows: list[dict[int, float]], n_bodies: int) -> np.ndarray:
    """The dense matrix of sparse rows (body index -> coefficient)."""
    out = np.zeros((len(rows), n_bodies))
    for i, row in enumerate(rows):
        for j, coef in row.items():
            out[i, j] = coef
    return out
