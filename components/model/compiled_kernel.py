"""Compiled (numba) twin of the gearbox hot path: contact law, accelerations, Jacobian, Rosenbrock step.

The equations are those of the numpy path, which stays the single source of
truth: :mod:`components.model.contact` (eq. 1-4, flank-consistent clipping),
:class:`components.model.assembly.Assembly` (deflections ``d = A q``,
accelerations through the folded ``_fast_matrix``, Jacobian ``-M^-1 (B^T diag(dF/dd)
A + S^T k S)``), :class:`components.model.mesh_stiffness.MeshPhasing` (stiffness
factor and slope) and :class:`components.model.integrators.Rosenbrock23` (the
ROS2(3) W-method, step control and Jacobian reuse, line for line). Every
constant matrix is taken from the :class:`~components.model.assembly.Assembly`
(see :mod:`components.model.gearbox_kernel`), so the kernel is generic over any
stage sequence, planet count, contact law and stiffness option; the tests
compare it with the numpy path to 1e-9 on every preset and variant.

Only numbers cross the boundary: one call of :func:`advance` integrates a whole
communication step. This module imports numba; :mod:`components.model.kernel`
decides whether it is used.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit  # optional requirement: the compiled gearbox kernel; without it the numpy path runs

from .integrators import OBSERVED_ORDER_MAX, OBSERVED_ORDER_MIN
from .kernel_layout import (  # noqa: F401 - re-exported: the module is the kernel's whole interface
    K0, EXPONENT, DAMPING, LAMBDA, HALF_JT, IMPACT, DMAX, CMAX, DEEP, N_CONTACT_COLUMNS, H_NEXT, ACCEPTED, REJECTED,
    JACOBIANS, AGE, HD, BASIS_VALID, ALPHA_OUT_MAX, HD_PREV, BASIS_PREV_VALID, ACTIVE, N_ISTATE, RTOL, ATOL_Q,
    ATOL_V, H_MIN, MAX_STEPS, JAC_MAX_AGE, OUT_KINEMATIC, OUT_RATE_INDEX, OK, STEP_TOO_SMALL, TOO_MANY_STEPS, SLOTS,
    A_T, A_PORT, FAST, CONTACT, FORCE_W, DEFL_W, ACC_W, BT, STKS, STCS, STKS_PORT, STCS_PORT, INV_M, FD_W, FV_W,
    PHASING, KAPPA, FORCE_ROWS, FACTOR_W, SLOPE_W, SENS_W, F0, F1, FN, K1, K2, K3, Y1, YN, RHS, W_HDT, DA, NZ_INDEX,
    NZ_VALUE, COS_ALPHA, CONTROL, ISTATE, DQ, DV, WINV, W_BASIS, PORT_JAC, LAST_ACC, LAST_FORCE, LAST_DEFL, Y,
    BACKUP, DRIVER, PORT, SCALARS, TWIST_Q, OUTPUT_MATRIX, OUTPUTS, ANCHOR, STATE_FIRST, STATE_LAST, SCALAR_NAMES, S_TIME,
    S_DRIVER_ANGLE, S_DRIVER_SPEED, S_DRIVER_ACCEL, S_PORT_ANGLE, S_PORT_SPEED, S_LAST_STEP, S_LAST_OMEGA_ROTOR,
    S_LAST_OMEGA_GEN, S_SHAFT_TORQUE_AVG, S_OUTPUT_TWIST, S_ALPHA_OUT_AVG, S_ANGLE0, S_LAST_ALPHA, S_KX,
    S_TWIST_PORT, S_SHAFT_K, S_SHAFT_C, D_N, D_M, D_TVS, D_SQRT_CFS, D_EXTRAPOLATE, D_END_TORQUE, D_GEN_DOF,
    D_ROTOR_DERIVATIVES, N_DIMS, NON_FINITE_INPUT,
)
from .numba_cache import enable_stable_cache

#: small helpers are inlined into their callers at numba's IR level (``inline="always"``): the same
#: operations in the same order (results unchanged bit for bit), without a call boundary and its array
#: reference counting per call (~8 % of a communication step of the Table 6 gearbox)
_INLINE = "always"

_D = 1.0 / (2.0 + math.sqrt(2.0))
_E32 = 6.0 + math.sqrt(2.0)
ORDER_MIN, ORDER_MAX = OBSERVED_ORDER_MIN, OBSERVED_ORDER_MAX


@njit(cache=False, inline=_INLINE)
def _sign(x):
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


@njit(cache=False, inline=_INLINE)
def contact_force(d, rate, factor, p):
    """Force [N], dF/dd, dF/d(rate) and elastic part of one mesh (``ContactLaw.evaluate``, one element)."""
    k = p[K0] * factor
    e = p[EXPONENT]
    h = p[HALF_JT]
    if p[IMPACT] != 0.0:  # eq. 1: sharp backlash, cubic STEP damping
        if d > h:
            pen = d - h
        elif d < -h:
            pen = d + h
        else:
            pen = 0.0
        abs_p = abs(pen)
        sgn = _sign(pen)
        pow_em1 = math.sqrt(abs_p) if e == 1.5 else abs_p ** (e - 1.0)
        elastic = k * sgn * pow_em1 * abs_p
        s = min(max(abs_p / p[DMAX], 0.0), 1.0)
        step = p[CMAX] * s * s * (3.0 - 2.0 * s)
        d_step = p[CMAX] * 6.0 * s * (1.0 - s) / p[DMAX]
        force = elastic + step * rate
        df_dd = k * e * pow_em1 + d_step * sgn * rate
        df_dv = step
        active = force * sgn > 0.0
    else:  # CFS, eq. 2-4
        abs_d = abs(d)
        if abs_d >= p[DEEP]:  # tanh saturated exactly: d_BL = delta -+ j_t/2
            d_bl = d - _sign(d) * h
            d_bl_p = 1.0
            d_bl_pp = 0.0
        else:
            lam = p[LAMBDA]
            x1 = d - h
            x2 = d + h
            u1 = lam * x1
            u2 = lam * x2
            t1 = math.tanh(u1)
            t2 = math.tanh(u2)
            d_bl = d + 0.5 * (x1 * t1 - x2 * t2)
            s1 = 1.0 - t1 * t1
            s2 = 1.0 - t2 * t2
            d_bl_p = 1.0 + 0.5 * (t1 + u1 * s1 - t2 - u2 * s2)
            d_bl_pp = lam * (s1 * (1.0 - u1 * t1) - s2 * (1.0 - u2 * t2))
        abs_bl = abs(d_bl)
        sgn = _sign(d_bl)
        pow_em1 = math.sqrt(abs_bl) if e == 1.5 else abs_bl ** (e - 1.0)
        elastic = k * sgn * pow_em1 * abs_bl
        c = p[DAMPING]
        rate_bl = d_bl_p * rate
        force = elastic + c * abs_bl * rate_bl
        df_dd = (k * e * pow_em1 + c * sgn * rate_bl) * d_bl_p + c * abs_bl * d_bl_pp * rate
        df_dv = c * abs_bl * d_bl_p
        active = force * _sign(d) > 0.0
    if not active:
        return 0.0, 0.0, 0.0, elastic
    return force, df_dd, df_dv, elastic


@njit(cache=False)
def stiffness_factors(angle, phasing, out_factor, out_slope):
    """``MeshPhasing.factor_and_slope`` at a driver angle; ``phasing`` rows: cycles/rad, cycle0, p/2, 1/w, v, v p, slope scale."""
    m = out_factor.shape[0]
    for i in range(m):
        y = (phasing[1, i] + phasing[0, i] * angle) % 1.0 - 0.5
        s = min(max((phasing[2, i] - abs(y)) * phasing[3, i] + 0.5, 0.0), 1.0)
        s2 = s * s
        out_factor[i] = 1.0 - phasing[5, i] + phasing[4, i] * (s2 * s * (s * (6.0 * s - 15.0) + 10.0))
        u = s - s2
        out_slope[i] = phasing[6, i] * _sign(y) * (u * u)


@njit(cache=False, inline=_INLINE)
def _hermite(c, tau):
    return c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))


@njit(cache=False, inline=_INLINE)
def _hermite_rate(c, tau):
    return c[1] + tau * (2.0 * c[2] + 3.0 * tau * c[3])


@njit(cache=False, inline=_INLINE)
def _hermite_accel(c, tau):
    return 2.0 * c[2] + 6.0 * tau * c[3]


@njit(cache=False, inline=_INLINE)
def deflections(y, n, a_t, a_port, port, port_rate, out):
    """Mesh deflections (row 0) and rates (row 1) of ``[q, v]`` plus the port (``Assembly._mesh_deflections``)."""
    m = a_t.shape[1]
    for i in range(m):
        d = 0.0
        r = 0.0
        for j in range(n):
            d += y[j] * a_t[j, i]
            r += y[n + j] * a_t[j, i]
        out[0, i] = d + a_port[i] * port
        out[1, i] = r + a_port[i] * port_rate


@njit(cache=False, inline=_INLINE)
def acceleration(y, port, port_rate, alpha, factor, a_t, a_port, fast, contact, force, defl, acc):
    """Deviation accelerations ``[force, y, port, port_rate, alpha] @ _fast_matrix`` (``Assembly.fast_acceleration``).

    Writes the forces and deflections into ``force`` and ``defl`` and returns ``acc``.
    """
    n = acc.shape[0]
    m = force.shape[0]
    deflections(y, n, a_t, a_port, port, port_rate, defl)
    for i in range(m):
        force[i] = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])[0]
    for j in range(n):
        s = 0.0
        for i in range(m):
            s += force[i] * fast[i, j]
        for i in range(2 * n):
            s += y[i] * fast[m + i, j]
        s += port * fast[m + 2 * n, j] + port_rate * fast[m + 2 * n + 1, j] + alpha * fast[m + 2 * n + 2, j]
        acc[j] = s
    return acc


@njit(cache=False)
def jacobian(y, port, port_rate, factor, a_t, a_port, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs,
             stks_port, stcs_port, inv_m, fd, fv, dq, dv, port_jac):
    """``Assembly.acceleration_jacobian``: dq, dv (n x n) and the port columns (rows of ``port_jac``).

    ``dq = -M^-1 (sum_i cos(alpha_i) dF_i/dd a_i a_i^T + S^T k S)`` summed over the few bodies each
    mesh row ``a_i`` touches (``nz_index``, ``nz_value``: its nonzero columns and entries, index < 0
    for padding); ``dv`` likewise with dF/d(rate) and ``S^T c S``.
    """
    n = dq.shape[0]
    m = fd.shape[0]
    width = nz_index.shape[1]
    deflections(y, n, a_t, a_port, port, port_rate, defl)
    for i in range(m):
        _, fd[i], fv[i], _ = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])
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


@njit(cache=False)
def _invert(g, out):
    """``out = g^-1`` by Gauss-Jordan elimination with partial pivoting (``g`` is overwritten).

    Written out rather than ``np.linalg.inv`` so the kernel needs no LAPACK (numba's LAPACK
    binding goes through SciPy's Fortran runtime, which is also loaded inside FMUs).
    """
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


@njit(cache=False)
def _factor(hd, dq, dv, winv):
    """``Rosenbrock23._factor``: W^-1 = (I - hd J)^-1 through the n x n Schur complement."""
    n = dq.shape[0]
    g = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            g[i, j] = -hd * dv[i, j] - (hd * hd) * dq[i, j]
        g[i, i] += 1.0
    ginv = np.empty((n, n))
    _invert(g, ginv)
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += ginv[i, k] * dq[k, j]
            winv[i, j] = (hd * hd) * s
            winv[i, n + j] = hd * ginv[i, j]
            winv[n + i, j] = hd * s
            winv[n + i, n + j] = ginv[i, j]
        winv[i, i] += 1.0


@njit(cache=False, inline=_INLINE)
def _copy(src, dst):
    """``dst[:] = src`` for two 1-D float arrays of one length, as a plain loop (numba's slice assignment
    checks and broadcasts: 4 x slower for the ~1500 numbers of the state saved at every step)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=False, inline=_INLINE)
def _matvec(w, x, out):
    n2 = x.shape[0]
    for i in range(n2):
        s = 0.0
        for j in range(n2):
            s += w[i, j] * x[j]
        out[i] = s


@njit(cache=False)
def _stiffness_sensitivity(defl, factor, contact, sqrt_cfs, out):
    """``ContactLaw.stiffness_sensitivity``: dF / d(stiffness factor) of every mesh."""
    m = out.shape[0]
    for i in range(m):
        p = contact[i]
        d = defl[0, i]
        rate = defl[1, i]
        if sqrt_cfs:
            abs_d = abs(d)
            h = p[HALF_JT]
            if abs_d >= p[DEEP]:
                d_bl = d - _sign(d) * h
                d_bl_p = 1.0
            else:
                lam = p[LAMBDA]
                x1 = d - h
                x2 = d + h
                t1 = math.tanh(lam * x1)
                t2 = math.tanh(lam * x2)
                d_bl = d + 0.5 * (x1 * t1 - x2 * t2)
                d_bl_p = 1.0 + 0.5 * (lam * x1 * (1.0 - t1 * t1) + t1 - lam * x2 * (1.0 - t2 * t2) - t2)
            abs_bl = abs(d_bl)
            elastic = p[K0] * _sign(d_bl) * abs_bl * math.sqrt(abs_bl)
            active = _sign(d) * (elastic * factor[i] + p[DAMPING] * abs_bl * d_bl_p * rate) > 0.0
            out[i] = elastic if active else 0.0
        else:
            force, _, _, elastic = contact_force(d, rate, factor[i], p)
            out[i] = elastic / factor[i] if force != 0.0 else 0.0


@njit(cache=False)
def _use_factorisation(hd, dq, dv, winvs, istate):
    """Make ``W^-1`` for ``hd`` the active one of the two kept (``winvs``: both stacked, (4n, 2n)).

    ``Rosenbrock23._step`` with its one-entry cache: the slot not in use holds the factorisation
    of the step size used before (same Jacobian), so a step that returns to it (the first step of
    a communication step after a shortened last one) switches slots instead of factorising again.
    Returns the active slot.
    """
    other = 1 - int(istate[ACTIVE])
    n2 = 2 * dq.shape[0]
    if hd == istate[HD_PREV]:
        istate[HD_PREV] = istate[HD]
        valid = istate[BASIS_VALID]
        istate[BASIS_VALID] = istate[BASIS_PREV_VALID]
        istate[BASIS_PREV_VALID] = valid
    else:
        istate[HD_PREV] = istate[HD]
        istate[BASIS_PREV_VALID] = istate[BASIS_VALID]
        _factor(hd, dq, dv, winvs[other * n2:(other + 1) * n2])
        istate[BASIS_VALID] = 0.0
    istate[HD] = hd
    istate[ACTIVE] = float(other)
    return other


@njit(cache=False, inline=_INLINE)
def _twist_and_rate(twist_q, y, n, twist_port, port, tau):
    """Output-shaft twist [rad] and its rate [rad/s] at ``tau``: the weights on ``q`` and on ``v``, plus the port's."""
    twist = twist_port * _hermite(port, tau)
    rate = twist_port * _hermite_rate(port, tau)
    for i in range(n):
        twist += twist_q[i] * y[i]
        rate += twist_q[i] * y[n + i]
    return twist, rate


@njit(cache=False)
def advance(y, t_end, alpha_shift, driver, port, angle0, k, istate, control, dq, dv, winvs, w_bases, port_jac,
            last_acc, last_force, last_defl, state, backup, twist_q, twist_port):
    """Integrate one communication step ``[0, t_end]`` (``Rosenbrock23.advance`` with ``_StepSystem``).

    Parameters
    ----------
    y : ndarray (2n,)
        State ``[q, v]`` at tau = 0; overwritten with the state at ``t_end`` on success.
    alpha_shift : float
        Driver acceleration of the last evaluation minus the driver acceleration at tau = 0: the
        acceleration at tau = 0 is ``last_acc + kappa alpha_shift`` (the prescribed motions are C1).
    driver, port : ndarray (4,)
        Hermite coefficients of the driver angle (relative to ``angle0``) and of the port angle.
    k : tuple
        Constant matrices and work arrays (:class:`components.model.gearbox_kernel.GearboxKernel`).
    istate : ndarray (N_ISTATE,)
        Step-size memory, counters, Jacobian age, factorised ``h d``, basis flag, eq. 11 maximum.
    control : ndarray
        Tolerances and output-member constants (see the module constants).
    dq, dv, winvs, w_bases, port_jac : ndarray
        Jacobian blocks; the two kept ``W^-1`` (stacked, (4n, 2n); ``istate[ACTIVE]`` says which is in
        use) and ``W^-1`` applied to the time-derivative basis for each (stacked, (4n, 3)); port Jacobian rows.
    last_acc, last_force, last_defl : ndarray
        Loads of the last evaluation (written at the end state on success).
    state, backup : ndarray
        The contiguous region of the buffer holding all of the above state, and room for a copy of it
        (restored on failure).
    twist_q : ndarray (2n,), twist_port : float
        Weights of the output-shaft twist on ``[q, 0]`` and on the port angle (its rate: the same weights on
        the speeds ``v`` and on the port speed).

    Returns
    -------
    status, time, step, error, twist_integral : (int, float, float, float, float)
        ``OK`` or the failure code with the local time, step size and error norm at the failure; the
        integral of the output-shaft twist over ``[0, t_end]`` [rad s] (Hermite-corrected trapezoid per
        accepted step, as ``GearboxModel._on_accept``; 0 on failure).
    """
    n = dq.shape[0]
    n2 = 2 * n
    m = last_force.shape[0]
    tvs = k[15]
    phasing, kappa, force_rows, sqrt_cfs = k[16], k[17], k[18], k[19]
    factor, slope, sens = k[20], k[21], k[22]
    f0 = k[23]
    f1 = k[24]
    fn = k[25]
    k1 = k[26]
    k2 = k[27]
    k3 = k[28]
    y1 = k[29]
    yn = k[30]
    rhs = k[31]
    w_hdt = k[32]
    da = k[33]
    # save the state for a failure
    _copy(state, backup)

    rtol = control[RTOL]
    atol_q = control[ATOL_Q]
    atol_v = control[ATOL_V]
    h_min = control[H_MIN]
    max_steps = control[MAX_STEPS]
    max_age = control[JAC_MAX_AGE]
    out_kin = control[OUT_KINEMATIC]
    out_idx = int(control[OUT_RATE_INDEX])
    for i in range(m):
        factor[i] = 1.0
    active = int(istate[ACTIVE])
    winv = winvs[active * n2:(active + 1) * n2]
    w_basis = w_bases[active * n2:(active + 1) * n2]
    t = 0.0
    h = istate[H_NEXT] if istate[H_NEXT] > 0.0 else t_end - t
    for i in range(n):
        f0[i] = y[n + i]
        f0[n + i] = last_acc[i] + kappa[i] * alpha_shift
    # time, output-shaft twist and its rate at the last accepted internal step, and the twist's integral so far
    twist_t = 0.0
    twist_a, twist_r = _twist_and_rate(twist_q, y, n, twist_port, port, 0.0)
    twist_integral = 0.0
    steps = 0
    prev_h = -1.0  # (h, err) of a rejected attempt at this t with a fresh Jacobian (prev_h < 0: none)
    prev_err = 0.0
    while t < t_end:
        remaining = t_end - t
        last = h >= remaining * (1.0 - 1e-12)
        if last:
            h = remaining
        if istate[AGE] < 0.0 or istate[AGE] >= max_age:  # refresh the Jacobian
            if tvs:
                stiffness_factors(angle0 + _hermite(driver, t), phasing, factor, slope)
            jacobian(y, _hermite(port, t), _hermite_rate(port, t), factor, k[0], k[1], k[3], k[5], k[34], k[35], k[36],
                     k[8], k[9], k[10], k[11], k[12], k[13], k[14], dq, dv, port_jac)
            istate[AGE] = 0.0
            istate[HD] = -1.0
            istate[HD_PREV] = -1.0
            istate[JACOBIANS] += 1.0
        # ---- one step (Rosenbrock23._step)
        hd = h * _D
        if hd != istate[HD]:
            active = _use_factorisation(hd, dq, dv, winvs, istate)
            winv = winvs[active * n2:(active + 1) * n2]
            w_basis = w_bases[active * n2:(active + 1) * n2]
        if not tvs:  # W^-1 [0, h d a_t] with a_t = [port speed, port accel, jerk] @ [pj0; pj1; -kappa]
            if istate[BASIS_VALID] == 0.0:
                for i in range(n2):
                    s0 = 0.0
                    s1 = 0.0
                    s2 = 0.0
                    for j in range(n):
                        w = winv[i, n + j]
                        s0 += w * port_jac[0, j]
                        s1 += w * port_jac[1, j]
                        s2 += w * (-kappa[j])
                    w_basis[i, 0] = s0
                    w_basis[i, 1] = s1
                    w_basis[i, 2] = s2
                istate[BASIS_VALID] = 1.0
            c0 = hd * _hermite_rate(port, t)
            c1 = hd * _hermite_accel(port, t)
            c2 = hd * (6.0 * driver[3])
            for i in range(n2):
                w_hdt[i] = w_basis[i, 0] * c0 + w_basis[i, 1] * c1 + w_basis[i, 2] * c2
        else:
            pr = _hermite_rate(port, t)
            pa = _hermite_accel(port, t)
            jerk = 6.0 * driver[3]
            for j in range(n):
                da[j] = port_jac[0, j] * pr + port_jac[1, j] * pa - kappa[j] * jerk
            stiffness_factors(angle0 + _hermite(driver, t), phasing, factor, slope)
            deflections(y, n, k[0], k[1], _hermite(port, t), pr, k[5])
            _stiffness_sensitivity(k[5], factor, k[3], sqrt_cfs, sens)
            rate = _hermite_rate(driver, t)
            for j in range(n):
                s = 0.0
                for i in range(m):
                    s += sens[i] * (slope[i] * rate) * force_rows[i, j]
                da[j] += s
            for i in range(n2):
                s = 0.0
                for j in range(n):
                    s += winv[i, n + j] * (hd * da[j])
                w_hdt[i] = s
        _matvec(winv, f0, k1)
        for i in range(n2):
            k1[i] += w_hdt[i]
            y1[i] = y[i] + (0.5 * h) * k1[i]
        tau = t + 0.5 * h
        if tvs:
            stiffness_factors(angle0 + _hermite(driver, tau), phasing, factor, slope)
        acc = acceleration(y1, _hermite(port, tau), _hermite_rate(port, tau), _hermite_accel(driver, tau), factor,
                           k[0], k[1], k[2], k[3], k[4], k[5], k[6])
        for i in range(n):
            f1[i] = y1[n + i]
            f1[n + i] = acc[i]
        for i in range(n2):
            rhs[i] = f1[i] - k1[i]
        _matvec(winv, rhs, k2)
        for i in range(n2):
            k2[i] += k1[i]
            yn[i] = y[i] + h * k2[i]
        tau = t + h
        if tvs:
            stiffness_factors(angle0 + _hermite(driver, tau), phasing, factor, slope)
        alpha_n = _hermite_accel(driver, tau)
        acc = acceleration(yn, _hermite(port, tau), _hermite_rate(port, tau), alpha_n, factor,
                           k[0], k[1], k[2], k[3], k[4], k[5], k[6])
        for i in range(n):
            fn[i] = yn[n + i]
            fn[n + i] = acc[i]
        for i in range(n2):
            rhs[i] = fn[i] - _E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i])
        _matvec(winv, rhs, k3)
        err = 0.0
        for i in range(n2):
            k3[i] += w_hdt[i]
            atol = atol_q if i < n else atol_v
            scale = atol + rtol * max(abs(y[i]), abs(yn[i]))
            e = abs(k1[i] + k3[i] - 2.0 * k2[i]) / scale
            if e > err or e != e:
                err = e
        err = (h / 6.0) * err
        if not math.isfinite(err):
            err = math.inf
        # ---- step control (Rosenbrock23.advance)
        steps += 1
        if err <= 1.0:
            prev_h = -1.0
            istate[ACCEPTED] += 1.0
            istate[AGE] += 1.0
            t = t_end if last else t + h
            for i in range(n2):
                y[i] = yn[i]
                f0[i] = fn[i]
            for i in range(n):
                last_acc[i] = fn[n + i]
            for i in range(m):
                last_force[i] = k[4][i]
                last_defl[0, i] = k[5][0, i]
                last_defl[1, i] = k[5][1, i]
            alpha_out = abs(out_kin * _hermite_accel(driver, t) + f0[out_idx])
            if alpha_out > istate[ALPHA_OUT_MAX]:
                istate[ALPHA_OUT_MAX] = alpha_out
            twist_b, rate_b = _twist_and_rate(twist_q, y, n, twist_port, port, t)
            dt = t - twist_t
            twist_integral += 0.5 * dt * (twist_a + twist_b) + dt * dt * (twist_r - rate_b) / 12.0
            twist_t = t
            twist_a = twist_b
            twist_r = rate_b
            fac = 5.0 if err == 0.0 else min(5.0, 0.9 * err ** (-1.0 / 3.0))
            fac = 1.0 if 1.0 <= fac <= 2.0 else fac
            if not last or fac < 1.0:
                istate[H_NEXT] = h * fac
            else:
                istate[H_NEXT] = max(istate[H_NEXT], h * fac)
            h = istate[H_NEXT]
        else:
            istate[REJECTED] += 1.0
            if istate[AGE] > 0.0:
                if tvs:
                    stiffness_factors(angle0 + _hermite(driver, t), phasing, factor, slope)
                jacobian(y, _hermite(port, t), _hermite_rate(port, t), factor, k[0], k[1], k[3], k[5], k[34], k[35], k[36],
                     k[8], k[9], k[10], k[11], k[12], k[13], k[14], dq, dv, port_jac)
                istate[AGE] = 0.0
                istate[HD] = -1.0
                istate[HD_PREV] = -1.0
                istate[JACOBIANS] += 1.0
                h *= max(0.5, min(1.0, 0.9 * err ** (-1.0 / 3.0))) if math.isfinite(err) else 0.1
                prev_h = -1.0
            else:  # integrators.shrink_after_rejection
                if not math.isfinite(err):
                    fac = 0.1
                elif prev_h > 0.0 and err < prev_err and h < prev_h:
                    order = math.log(prev_err / err) / math.log(prev_h / h)
                    order = min(ORDER_MAX, max(ORDER_MIN, order))
                    fac = max(0.1, (0.9 / err) ** (1.0 / order))
                else:
                    fac = max(0.1, 0.9 * err ** (-1.0 / 3.0))
                if math.isfinite(err):
                    prev_h = h
                    prev_err = err
                else:
                    prev_h = -1.0
                h *= fac
            istate[H_NEXT] = h
            if h < h_min:
                _copy(backup, state)
                return STEP_TOO_SMALL, t, h, err, 0.0
        if steps > max_steps:
            _copy(backup, state)
            return TOO_MANY_STEPS, t, h, err, 0.0
    return OK, t, h, 0.0, twist_integral


# ---------------------------------------------------------------- one communication step


@njit(cache=False, inline=_INLINE)
def _vec(buf, lay, slot):
    return buf[lay[slot]:lay[slot + 1]]


@njit(cache=False, inline=_INLINE)
def _mat(buf, lay, slot, rows):
    v = buf[lay[slot]:lay[slot + 1]]
    return v.reshape((rows, v.shape[0] // rows))


@njit(cache=False, inline=_INLINE)
def _fit(c, h, x0, dx0, x1, dx1):
    """``gearbox_model._Hermite.fit``: cubic with value and slope at both ends of [0, h]."""
    delta = (x1 - x0) / h
    c[0] = x0
    c[1] = dx0
    c[2] = (3.0 * delta - 2.0 * dx0 - dx1) / h
    c[3] = (dx0 + dx1 - 2.0 * delta) / (h * h)


@njit(cache=False)
def _constants(buf, lay, dims):
    n = dims[D_N]
    m = dims[D_M]
    n2 = 2 * n
    return (
        _mat(buf, lay, A_T, n), _vec(buf, lay, A_PORT), _mat(buf, lay, FAST, m + n2 + 3), _mat(buf, lay, CONTACT, m),
        _vec(buf, lay, FORCE_W), _mat(buf, lay, DEFL_W, 2), _vec(buf, lay, ACC_W), _mat(buf, lay, BT, n),
        _mat(buf, lay, STKS, n), _mat(buf, lay, STCS, n), _vec(buf, lay, STKS_PORT), _vec(buf, lay, STCS_PORT),
        _vec(buf, lay, INV_M), _vec(buf, lay, FD_W), _vec(buf, lay, FV_W), dims[D_TVS] != 0,
        _mat(buf, lay, PHASING, 7), _vec(buf, lay, KAPPA), _mat(buf, lay, FORCE_ROWS, m), dims[D_SQRT_CFS] != 0,
        _vec(buf, lay, FACTOR_W), _vec(buf, lay, SLOPE_W), _vec(buf, lay, SENS_W),
        _vec(buf, lay, F0), _vec(buf, lay, F1), _vec(buf, lay, FN), _vec(buf, lay, K1), _vec(buf, lay, K2),
        _vec(buf, lay, K3), _vec(buf, lay, Y1), _vec(buf, lay, YN), _vec(buf, lay, RHS), _vec(buf, lay, W_HDT),
        _vec(buf, lay, DA), _mat(buf, lay, NZ_INDEX, m), _mat(buf, lay, NZ_VALUE, m), _vec(buf, lay, COS_ALPHA),
    )


@njit(cache=False)
def outputs(buf, lay, dims):
    """``GearboxModel.output_vector`` into the ``outputs`` slot."""
    n = dims[D_N]
    m = dims[D_M]
    sc = _vec(buf, lay, SCALARS)
    y = _vec(buf, lay, Y)
    force = _vec(buf, lay, LAST_FORCE)
    om = _mat(buf, lay, OUTPUT_MATRIX, m + 2 * n + 4)
    out = _vec(buf, lay, OUTPUTS)
    ist = _vec(buf, lay, ISTATE)
    cols = om.shape[1]
    for col in range(cols):
        s = 0.0
        for i in range(m):
            s += force[i] * om[i, col]
        for i in range(2 * n):
            s += y[i] * om[m + i, col]
        s += (sc[S_PORT_ANGLE] * om[m + 2 * n, col] + sc[S_PORT_SPEED] * om[m + 2 * n + 1, col]
              + sc[S_DRIVER_SPEED] * om[m + 2 * n + 2, col] + sc[S_DRIVER_ACCEL] * om[m + 2 * n + 3, col])
        out[2 + col] = s
    avg = sc[S_SHAFT_TORQUE_AVG]
    out[0] = out[2] if dims[D_END_TORQUE] != 0 else avg
    out[1] = avg
    out[2 + cols] = sc[S_ALPHA_OUT_AVG]
    out[3 + cols] = ist[ALPHA_OUT_MAX]


@njit(cache=False)
def gearbox_step(buf, lay, dims, t, h, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque, alpha_rotor,
                 jerk_rotor):
    """``GearboxModel.step`` from ``t`` to ``t + h`` on the state in ``buf``; outputs into the ``outputs`` slot.

    Returns ``(status, local time, step size, error norm)`` as :func:`advance`, or ``NON_FINITE_INPUT``;
    on failure the buffer is as it was at ``t``.
    """
    n = dims[D_N]
    m = dims[D_M]
    gdof = dims[D_GEN_DOF]
    sc = _vec(buf, lay, SCALARS)
    y = _vec(buf, lay, Y)
    control = _vec(buf, lay, CONTROL)
    out_kin = control[OUT_KINEMATIC]
    out_idx = int(control[OUT_RATE_INDEX])
    extrapolate = dims[D_EXTRAPOLATE] != 0 and sc[S_LAST_STEP] > 0.0
    alpha_gen = (omega_gen - sc[S_LAST_OMEGA_GEN]) / sc[S_LAST_STEP] if extrapolate and gdof < 0 else 0.0
    if dims[D_ROTOR_DERIVATIVES] != 0:
        angle1 = phi_rotor + h * (omega_rotor + h * (0.5 * alpha_rotor + h * (jerk_rotor / 6.0)))
        speed1 = omega_rotor + h * (alpha_rotor + h * (0.5 * jerk_rotor))
    else:
        alpha = (omega_rotor - sc[S_LAST_OMEGA_ROTOR]) / sc[S_LAST_STEP] if extrapolate else 0.0
        angle1 = phi_rotor + h * (omega_rotor + 0.5 * h * alpha)
        speed1 = omega_rotor + h * alpha
    kx = sc[S_KX]
    dv = 0.0
    if gdof >= 0:  # inertia interface: the port input is the held counter torque
        port0 = counter_torque
        port_speed0 = 0.0
        port1 = port0
        port_speed1 = 0.0
        dv = omega_gen - kx * sc[S_DRIVER_SPEED] - y[n + gdof]
        if not math.isfinite(dv + port0):
            return NON_FINITE_INPUT, 0.0, h, 0.0
    else:
        port0 = sc[S_PORT_ANGLE]
        port_speed0 = sc[S_PORT_SPEED]
        port1 = phi_gen + h * (omega_gen + 0.5 * h * alpha_gen) - kx * angle1
        port_speed1 = omega_gen + h * alpha_gen - kx * speed1
    if not math.isfinite(angle1 + speed1 + port1 + port_speed1):
        return NON_FINITE_INPUT, 0.0, h, 0.0
    driver = _vec(buf, lay, DRIVER)
    port = _vec(buf, lay, PORT)
    sc[S_ANGLE0] = sc[S_DRIVER_ANGLE]
    _fit(driver, h, 0.0, sc[S_DRIVER_SPEED], angle1 - sc[S_DRIVER_ANGLE], speed1)
    _fit(port, h, port0, port_speed0, port1, port_speed1)
    last_acc = _vec(buf, lay, LAST_ACC)
    anchor = _vec(buf, lay, ANCHOR)
    if gdof >= 0:  # re-anchor the generator speed; the loads follow linearly (the generator is in no mesh)
        fast = _mat(buf, lay, FAST, m + 2 * n + 3)
        d_torque = port0 - sc[S_PORT_ANGLE]
        anchor[0] = y[n + gdof]
        y[n + gdof] += dv
        for j in range(n):
            anchor[1 + j] = last_acc[j]
            last_acc[j] += dv * fast[m + n + gdof, j] + d_torque * fast[m + 2 * n, j]
    twist_start = sc[S_OUTPUT_TWIST]
    speed_start = out_kin * sc[S_DRIVER_SPEED] + y[out_idx]
    twist_q = _vec(buf, lay, TWIST_Q)
    status, tau, h_fail, err, twist_integral = advance(
        y, h, sc[S_LAST_ALPHA] - _hermite_accel(driver, 0.0), driver, port, sc[S_ANGLE0], _constants(buf, lay, dims),
        _vec(buf, lay, ISTATE), control, _mat(buf, lay, DQ, n), _mat(buf, lay, DV, n), _mat(buf, lay, WINV, 4 * n),
        _mat(buf, lay, W_BASIS, 4 * n), _mat(buf, lay, PORT_JAC, 2), _vec(buf, lay, LAST_ACC),
        _vec(buf, lay, LAST_FORCE), _mat(buf, lay, LAST_DEFL, 2), buf[lay[STATE_FIRST]:lay[STATE_LAST + 1]],
        _vec(buf, lay, BACKUP), twist_q, sc[S_TWIST_PORT],
    )
    if status != OK:
        if gdof >= 0:  # undo the re-anchoring (advance restored the state it was given)
            y[n + gdof] = anchor[0]
            for j in range(n):
                last_acc[j] = anchor[1 + j]
        return status, tau, h_fail, err
    sc[S_TIME] = t + h
    sc[S_DRIVER_ANGLE] = angle1
    sc[S_DRIVER_SPEED] = speed1
    sc[S_DRIVER_ACCEL] = _hermite_accel(driver, h)
    sc[S_LAST_ALPHA] = sc[S_DRIVER_ACCEL]
    sc[S_PORT_ANGLE] = port1
    sc[S_PORT_SPEED] = port_speed1
    sc[S_LAST_OMEGA_ROTOR] = omega_rotor
    sc[S_LAST_OMEGA_GEN] = omega_gen
    sc[S_LAST_STEP] = h
    twist_end = 0.0
    for i in range(2 * n):
        twist_end += twist_q[i] * y[i]
    twist_end += sc[S_TWIST_PORT] * port1
    sc[S_OUTPUT_TWIST] = twist_end
    sc[S_SHAFT_TORQUE_AVG] = sc[S_SHAFT_K] * twist_integral / h + sc[S_SHAFT_C] * (twist_end - twist_start) / h
    sc[S_ALPHA_OUT_AVG] = (out_kin * speed1 + y[out_idx] - speed_start) / h
    outputs(buf, lay, dims)
    return OK, tau, h, 0.0


# ---------------------------------------------------------------- monolithic reference
@njit(cache=False)
def monolithic_rhs(y, omega, alpha, factor, load, out_dof, kappa_out, inertia_in, a_t, a_port, fast, contact, s_mat,
                   shaft_k, shaft_c, bt_driver, s_driver, cos_alpha, inv_m, force, elastic, defl, acc, out):
    """``MonolithicSystem.rhs``: ``[v, q_ddot, rotor power, output power, dissipated power]`` into ``out``.

    The accelerations through the Assembly's folded matrix (no port), the counter torque on the
    output body, rotor torque ``I_in alpha + cos(alpha) a_in . F + s_in . T``, and the dissipation
    ``((F - F_el) d_dot) . cos(alpha) + sum c s_dot^2`` (``Assembly.dissipation_power``).
    """
    n = inv_m.shape[0]
    m = force.shape[0]
    deflections(y, n, a_t, a_port, 0.0, 0.0, defl)
    for i in range(m):
        f, _, _, el = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])
        force[i] = f
        elastic[i] = el
    for j in range(n):
        s = 0.0
        for i in range(m):
            s += force[i] * fast[i, j]
        for i in range(2 * n):
            s += y[i] * fast[m + i, j]
        acc[j] = s + alpha * fast[m + 2 * n + 2, j]
    acc[out_dof] -= inv_m[out_dof] * load
    rotor = inertia_in * alpha
    dissipation = 0.0
    for i in range(m):
        rotor += force[i] * bt_driver[i]
        dissipation += (force[i] - elastic[i]) * defl[1, i] * cos_alpha[i]
    for r in range(shaft_k.shape[0]):
        tw = 0.0
        rate = 0.0
        for j in range(n):
            tw += s_mat[r, j] * y[j]
            rate += s_mat[r, j] * y[n + j]
        rotor += (shaft_k[r] * tw + shaft_c[r] * rate) * s_driver[r]
        dissipation += shaft_c[r] * rate * rate
    for j in range(n):
        out[j] = y[n + j]
        out[n + j] = acc[j]
    out[2 * n] = rotor * omega
    out[2 * n + 1] = load * (kappa_out * omega + y[n + out_dof])
    out[2 * n + 2] = dissipation


@njit(cache=False)
def monolithic_jacobian(y, factor, a_t, a_port, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs, stks_port,
                        stcs_port, inv_m, fd, fv, dq, dv, port_jac, jac):
    """``MonolithicSystem.jacobian``: the acceleration rows of ``jac`` (the rest is fixed)."""
    n = inv_m.shape[0]
    jacobian(y, 0.0, 0.0, factor, a_t, a_port, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs, stks_port,
             stcs_port, inv_m, fd, fv, dq, dv, port_jac)
    for i in range(n):
        for j in range(n):
            jac[n + i, j] = dq[i, j]
            jac[n + i, n + j] = dv[i, j]


def _step_signature() -> tuple:
    from numba import types  # optional requirement: the compiled gearbox kernel

    vector, index = types.float64[::1], types.int64[::1]
    return (vector, index, index) + (types.float64,) * 9


def ensure_compiled() -> None:
    """Compile (or load from the disk cache) the entry points for the argument types they are called with.

    Called when a model is built, so that the one-off cost (first run on a machine: tens of
    seconds; later: a cache load) is paid there and not inside a stepping loop.
    """
    from numba import types  # optional requirement: the compiled gearbox kernel

    vector, index = types.float64[::1], types.int64[::1]
    gearbox_step.compile(_step_signature())
    outputs.compile((vector, index, index))


def step_entry_point():
    """:func:`gearbox_step` for its one signature, without the dispatcher's per-call type resolution.

    The compiled overload's own entry point (numba's ``overloads[signature].entry_point``) takes
    the same arguments (a float64 buffer, two int64 index arrays, nine floats) and saves ~0.2 us
    per call. Falls back to the dispatcher itself if that attribute is not there (numba internals).
    """
    ensure_compiled()
    try:
        return gearbox_step.overloads[_step_signature()].entry_point
    except Exception:  # noqa: BLE001 - numba internals changed: the dispatcher is always correct
        return gearbox_step


DISPATCHERS = (_sign, contact_force, stiffness_factors, _hermite, _hermite_rate, _hermite_accel, _twist_and_rate,
               deflections, acceleration, jacobian, _invert, _factor, _copy, _matvec, _stiffness_sensitivity, advance,
               _vec, _mat, _fit, _constants, outputs, gearbox_step, monolithic_rhs, monolithic_jacobian)
#: entry points of the ahead-of-time compiled module (:mod:`components.model.aot`) and their signatures:
#: what a communication step calls (the monolithic reference's functions stay JIT-compiled)
AOT_EXPORTS = {
    "gearbox_step": "Tuple((i8, f8, f8, f8))(f8[::1], i8[::1], i8[::1], f8, f8, f8, f8, f8, f8, f8, f8, f8)",
    "outputs": "void(f8[::1], i8[::1], i8[::1])",
}
#: True when the machine code is cached on disk (see :mod:`components.model.numba_cache`)
DISK_CACHE = enable_stable_cache(DISPATCHERS, __file__, __name__)
