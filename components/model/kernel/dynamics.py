"""The drivetrain's equations of motion from its assembled matrices: deflections, accelerations, Jacobian.

The stage kinds are assembled into constant matrices once
(:class:`components.model.assembly.Assembly`): mesh deflections ``d = A q + a_port u + e`` (eq. 8,
10 and the parallel mesh in deviation coordinates; ``e`` the constant offsets of planet pin
position errors), shaft and bearing rows ``S q``, and the folded matrix ``fast`` with
``q_ddot = [F, q, v, u, u_dot, alpha_in, w] @ fast``, which holds the inverse inertias, the
mesh moment arms ``-r_b = -r cos(alpha)`` (eq. 5-7), the shafts and bearings, the port input
``u``, the driver acceleration and the external loads (gravity, centrifugal force) per external
term ``w = [omega_in^2, 1, cos(r_k th_in), sin(r_k th_in), ...]`` (:func:`external_terms`; none
without a lateral-torsional stage). Here they are evaluated for one state ``y = [q, v]``.
"""

from __future__ import annotations

import math

import numpy as np

from .contact import force_slopes, forces, stiffness_force_rates
from .linalg import copy, sparse_vecmat, sums, vecmat_add
from .stiffness import stiffness_factors


def deflections(y, n, nz_index, nz_value, a_port, offset, port, port_rate, out):
    """Mesh deflections [m] (row 0) and their rates [m/s] (row 1) of ``y = [q, v, ...]``, the port input and
    the constant offsets; every mesh row ``A`` through its nonzero columns (``nz_index``, ``nz_value``).

    The numpy form sums each mesh's terms, its port term and its offset as one row of terms, in the loop's order: the
    terms on ``x = [q, v, port, port_rate, 1, 0]`` of the pattern extended by those columns (:func:`extended_pattern`).
    """
    index, value = extended_pattern(n, nz_index, nz_value, a_port, offset)
    x = np.empty(2 * n + 4)
    x[:2 * n] = y[:2 * n]
    x[2 * n:] = port, port_rate, 1.0, 0.0
    terms = x.take(index)
    terms *= value  # the padding's terms 0 * 0, the (finite) offset's on the rates offset * 0: zeros
    sums(terms, out)  # (+ 0.0: the loop's sums start from 0.0, never -0.0)


#: mesh patterns whose extended form :func:`extended_pattern` keeps, at most (all dropped when one more is asked for)
KEPT_PATTERNS = 8
_kept_patterns: dict = {}


def extended_pattern(n, nz_index, nz_value, a_port, offset):
    """The terms of :func:`deflections`' numpy form: the entries of ``x = [q, v, port, port_rate, 1, 0]`` (``intp``,
    shape (2, meshes, width + 2): deflections, then rates) and the weights (meshes, width + 2) of every mesh's row:
    its nonzero columns, the padding pointed at the last entry (0) with weight 0, then the port with ``a_port`` and the
    constant (1 for the deflections, 0 for the rates) with ``offset``.

    Kept by the identity of the four tables: a model's are written once, when its buffer is made, never changed in
    place, and passed as the same objects at every evaluation (the kept views of
    :func:`components.model.kernel.step.views`). A kept entry holds them, so no other object can take their
    identity; dict operations are atomic, so threads stepping models of one process may share it.
    """
    kept = _kept_patterns.get(id(nz_index))
    if (kept is not None and kept[0] is nz_index and kept[1] is nz_value and kept[2] is a_port and kept[3] is offset
            and kept[4] == n):
        return kept[5]
    m = nz_index.shape[0]
    valid = nz_index >= 0.0
    index = np.stack([np.concatenate((np.where(valid, nz_index + first, 2 * n + 3.0), np.full((m, 1), port_entry),
                                      np.full((m, 1), constant)), 1)
                      for first, port_entry, constant in ((0, 2 * n, 2 * n + 2), (n, 2 * n + 1, 2 * n + 3))])
    index = index.astype(np.intp)
    value = np.concatenate((np.where(valid, nz_value, 0.0), a_port[:, None], offset[:, None]), axis=1)
    if len(_kept_patterns) >= KEPT_PATTERNS:
        _kept_patterns.clear()
    pattern = index, value
    _kept_patterns[id(nz_index)] = (nz_index, nz_value, a_port, offset, n, pattern)
    return pattern


def _deflections_loop(y, n, nz_index, nz_value, a_port, offset, port, port_rate, out):
    """:func:`deflections` in one pass over the nonzero columns (the same sums in the same order)."""
    for i in range(nz_index.shape[0]):
        d = 0.0
        r = 0.0
        for p in range(nz_index.shape[1]):
            j = int(nz_index[i, p])
            if j < 0:
                break
            d += y[j] * nz_value[i, p]
            r += y[n + j] * nz_value[i, p]
        out[0, i] = d + port * a_port[i] + offset[i]
        out[1, i] = r + port_rate * a_port[i]


def external_terms(angle, speed, rates, out):
    """The external terms ``w = [omega^2, 1, cos(r_1 th), sin(r_1 th), ...]`` at the driver angle ``th`` [rad] and
    speed ``omega`` [rad/s] into ``out`` (its length: ``2 + 2 len(rates)``, or 0 without external loads)."""
    if out.shape[0] == 0:
        return
    out[0] = speed * speed
    out[1] = 1.0
    for k in range(rates.shape[0]):
        out[2 + 2 * k] = math.cos(rates[k] * angle)
        out[3 + 2 * k] = math.sin(rates[k] * angle)


def external_term_rates(angle, speed, accel, rates, out):
    """The time derivatives of :func:`external_terms` at the driver angle, speed and acceleration ``accel``
    [rad/s^2] into ``out``: ``[2 omega alpha, 0, -r omega sin(r th), r omega cos(r th), ...]``."""
    if out.shape[0] == 0:
        return
    out[0] = 2.0 * speed * accel
    out[1] = 0.0
    for k in range(rates.shape[0]):
        w = rates[k] * speed
        out[2 + 2 * k] = -w * math.sin(rates[k] * angle)
        out[3 + 2 * k] = w * math.cos(rates[k] * angle)


def acceleration(y, port, port_rate, alpha, factor, nz_index, nz_value, a_port, offset, fast_index, fast_value, contact,
                 z, defl, acc):
    """Deviation accelerations ``q_ddot`` [rad/s^2] into ``acc``: ``z @ fast`` with the folded matrix held by
    columns, its nonzero rows only (``fast_index``, ``fast_value``).

    Writes the deflections into ``defl``, the forces [N] into ``z[:n_mesh]``, ``y`` after them and ``u, u_dot,
    alpha_in`` after ``n_mesh + 2 n`` entries of ``z``; the external terms after them must be set
    (:func:`external_terms`) where ``fast`` has external rows.
    """
    m = defl.shape[1]
    n2 = y.shape[0]
    deflections(y, n2 // 2, nz_index, nz_value, a_port, offset, port, port_rate, defl)
    forces(defl, factor, contact, z[:m])
    copy(y, z[m:m + n2])
    z[m + n2] = port
    z[m + n2 + 1] = port_rate
    z[m + n2 + 2] = alpha
    sparse_vecmat(z, fast_index, fast_value, acc)


def jacobian(y, port, port_rate, factor, a_port, offset, contact, defl, nz_index, nz_value, cos_alpha, stks,
             stcs, stks_port, stcs_port, inv_m, fd, fv, dq, dv, port_jac):
    """Jacobian blocks of ``q_ddot``: ``dq``, ``dv`` (n x n) and the port columns (rows of ``port_jac``).

    ``dq = -M^-1 (sum_i cos(alpha_i) dF_i/dd a_i a_i^T + S^T k S)`` summed over the few bodies each
    mesh row ``a_i`` touches (``nz_index``, ``nz_value``: its nonzero columns and entries, index < 0
    for padding); ``dv`` likewise with dF/d(rate) and ``S^T c S``.
    """
    n = dq.shape[0]
    deflections(y, n, nz_index, nz_value, a_port, offset, port, port_rate, defl)
    force_slopes(defl, factor, contact, fd, fv)
    assemble_jacobian(fd, fv, nz_index, nz_value, a_port, cos_alpha, stks, stcs, stks_port, stcs_port, inv_m, dq, dv,
                      port_jac)


def assemble_jacobian(fd, fv, nz_index, nz_value, a_port, cos_alpha, stks, stcs, stks_port, stcs_port, inv_m, dq, dv,
                      port_jac):
    """:func:`jacobian`'s blocks from the meshes' dF/dd ``fd`` and dF/d(rate) ``fv``: every entry the springs' term
    plus the meshes' in their order, times ``-1 / m`` of its row."""
    dq[:, :] = stks
    dv[:, :] = stcs
    port_jac[0] = stks_port
    port_jac[1] = stcs_port
    valid = nz_index >= 0.0  # a mesh's bodies (padding at the end of its row)
    pairs = valid[:, :, None] & valid[:, None, :]
    index = nz_index.astype(np.intp)
    rows = np.broadcast_to(index[:, :, None], pairs.shape)[pairs]  # in the loop's order: mesh, body, body
    cols = np.broadcast_to(index[:, None, :], pairs.shape)[pairs]
    bodies = index[valid]
    for c, block, port_row in ((cos_alpha * fd, dq, port_jac[0]), (cos_alpha * fv, dv, port_jac[1])):
        b = c[:, None] * nz_value
        np.add.at(block, (rows, cols), (b[:, :, None] * nz_value[:, None, :])[pairs])  # in order, repeats too
        np.add.at(port_row, bodies, (b * a_port[:, None])[valid])
    s = -inv_m
    dq *= s[:, None]
    dv *= s[:, None]
    port_jac *= s


def _assemble_jacobian_loop(fd, fv, nz_index, nz_value, a_port, cos_alpha, stks, stcs, stks_port, stcs_port, inv_m, dq,
                            dv, port_jac):
    n = dq.shape[0]
    m = fd.shape[0]
    width = nz_index.shape[1]
    for j in range(n):
        for col in range(n):
            dq[j, col] = stks[j, col]
            dv[j, col] = stcs[j, col]
        port_jac[0, j] = stks_port[j]
        port_jac[1, j] = stcs_port[j]
    for i in range(m):
        cq = cos_alpha[i] * fd[i]
        cv = cos_alpha[i] * fv[i]
        for p in range(width):
            jp = int(nz_index[i, p])
            if jp < 0:
                break
            bq = cq * nz_value[i, p]
            bv = cv * nz_value[i, p]
            for q in range(width):
                jq = int(nz_index[i, q])
                if jq < 0:
                    break
                dq[jp, jq] += bq * nz_value[i, q]
                dv[jp, jq] += bv * nz_value[i, q]
            port_jac[0, jp] += bq * a_port[i]
            port_jac[1, jp] += bv * a_port[i]
    for j in range(n):
        s = -inv_m[j]
        for col in range(n):
            dq[j, col] *= s
            dv[j, col] *= s
        port_jac[0, j] *= s
        port_jac[1, j] *= s


def stiffness_rate(y, n, angle, speed, port, port_rate, nz_index, nz_value, a_port, offset, contact, phasing,
                   force_rows, factor, slope, defl, sens, out):
    """``out += (dF/df df/dt) @ d q_ddot/dF``: the partial time derivative of ``q_ddot`` that a time-varying
    mesh stiffness adds at driver angle ``angle`` [rad] and speed ``speed`` [rad/s] (its factor ``f`` moves
    with the driver angle). Leaves the factors at ``angle`` in ``factor``."""
    stiffness_factors(angle, phasing, factor, slope)
    deflections(y, n, nz_index, nz_value, a_port, offset, port, port_rate, defl)
    stiffness_force_rates(defl, factor, contact, slope, speed, sens)
    vecmat_add(sens, force_rows, out)


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"deflections": _deflections_loop, "assemble_jacobian": _assemble_jacobian_loop}
#: inlined into their callers by numba (the Jacobian's assembly is compiled once and called)
INLINE = ("deflections", "acceleration")
