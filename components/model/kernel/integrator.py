"""The gearbox's integrator: the ROS2(3) W-method of Shampine and Reichelt (MATLAB's ``ode23s``).

Second order, L-stable, linearly implicit (no Newton iteration), with an embedded third-order
error estimate, for ``q_dot = v, v_dot = a(t, q, v)`` with the analytic Jacobian blocks of
:func:`components.model.kernel.dynamics.jacobian`. One step from ``y`` with ``f0 = f(y)``
and ``W^-1 = (I - h d J)^-1``, ``d = 1 / (2 + sqrt 2)``::

    k1 = W^-1 (f0 + h d f_t)
    k2 = W^-1 (f(y + h k1 / 2) - k1) + k1
    k3 = W^-1 (f(y + h k2) - e32 (k2 - f1) - 2 (k1 - f0) + h d f_t),    e32 = 6 + sqrt 2
    y_new = y + h k2,     err = h / 6 max |k1 - 2 k2 + k3| / (atol + rtol max(|y|, |y_new|))

* ``W^-1`` is applied by blocks through the ``n x n`` Schur complement ``G`` of the ``2n x 2n`` stage
  matrix (:func:`factor`, :func:`solve`), factorised once per Jacobian and step size: as its inverse,
  or as LU factors in large models (more than :data:`LU_ABOVE` degrees of freedom: the
  lateral-torsional gearboxes). Four factorisations are kept (:func:`use_factorisation`, least
  recently used replaced), used again as the step sizes recur.
* **Step sizes that recur**: the rest of a communication step is divided into equal steps of at most
  the proposed size (``H / k`` from a communication point), not the proposal and a last step
  shortened to end on the communication point, whose size differs at every communication step and
  would need a factorisation of its own each time; step sizes whose ``h d`` agree within
  :data:`SAME_HD` (equal steps of a remainder that is itself rounded) share one. Once the first
  internal step of a communication step was rejected (new inputs start a transient there, where the
  proposal from the smooth end of the last step fails two or three times in a lateral-torsional
  gearbox), the next ones start with at most the step their predecessor's first step proposed, while
  that is smaller than the proposal. In the paper's scenario (12 degrees of freedom, H = 20 ms) most
  communication steps then need no factorisation of their own (with the shortened last step nearly
  every one did), for about as many internal steps and fewer rejected ones.
* **Jacobian reuse**: the method is a W-method (second order for any ``W``), so the Jacobian is
  refreshed only when older than ``jacobian_max_age`` accepted steps or after a rejected step;
  a stale Jacobian that hurts accuracy causes a rejection, which forces a refresh.
* **Step control**: ``h_new = h min(5, 0.9 err^(-1/3))``, kept unchanged for factors in [1, 2]
  (the factorisation is reused). After a second rejection at the same time with a fresh Jacobian
  the controller uses the order observed between the two attempts, ``p = log(err1 / err2) /
  log(h1 / h2)`` clipped to [0.2, 3], and proposes ``h (0.9 / err)^(1/p)`` (at least a tenth of
  ``h``): at a communication point the inputs change their acceleration, which starts a fast,
  heavily damped transient of the stiff mesh modes over which the error shrinks only like
  ``h^0.2 .. h^0.5``, and the ``h^3`` rule needed up to ten rejections in a row (H = 20 ms).
* ``f_t``: the prescribed motions' part of the partial time derivative (the port's speed and
  acceleration, the driver's jerk), plus the time-varying mesh stiffness's where it is on.

One-step: it carries no history, so nothing restarts at a communication point.
"""

from __future__ import annotations

import math

import numpy as np

from .dynamics import acceleration, external_term_rates, external_terms, jacobian, stiffness_rate
from .layout import (
    ACCEPTED, ACTIVE, AGE, ALPHA_OUT_MAX, ATOL_Q, ATOL_V, CLOCK, H_FIRST, H_MIN, H_NEXT, HD, N_SLOTS, SLOT_BASIS,
    SLOT_HD, SLOT_USED,
    JAC_MAX_AGE, JACOBIANS, MAX_STEPS, OK, OUT_KINEMATIC, OUT_RATE_INDEX, REJECTED, RTOL, STEP_TOO_SMALL,
    TOO_MANY_STEPS,
)
from .linalg import axpy, copy, invert, lu_factor, lu_pattern, lu_solve, matvec, matvec_pattern, negate, subtract
from .motion import accel, jerk, rate, value
from .stiffness import stiffness_factors

D = 1.0 / (2.0 + math.sqrt(2.0))
#: above this many degrees of freedom (a lateral-torsional gearbox) a factorisation is what a step costs most: ``G`` is
#: kept as its LU factors (n^3/3 operations, not an inverse's n^3); up to it as its inverse (a solve is one product)
LU_ABOVE = 24
E32 = 6.0 + math.sqrt(2.0)
#: two step sizes whose ``h d`` differ by at most this fraction share a factorisation (the step then runs with the
#: kept one's ``h d``: another ``W``, as any in a W-method): the equal steps to a communication point recur up to
#: round-off (``remaining / pieces`` of a remainder itself rounded)
SAME_HD = 1e-12
#: bounds of the error order observed between two rejected attempts
ORDER_MIN, ORDER_MAX = 0.2, 3.0


def factor(hd, dq, dv, ginv, piv):
    """``G = I - hd dv - hd^2 dq``, the Schur complement of ``W = I - hd J``, ``J = [[0, I], [dq, dv]]``, which is
    all :func:`solve` needs of ``W^-1``: kept as ``G^-1`` (up to :data:`LU_ABOVE` degrees of freedom) or as its LU
    factors, pivots and their nonzero pattern ``piv`` (rows: pivots, then per column of ``L`` and of ``U`` its
    nonzero rows, see :func:`.linalg.lu_pattern`)."""
    n = dq.shape[0]
    g = -hd * dv - (hd * hd) * dq
    g.reshape(-1)[::n + 1] += 1.0  # the diagonal
    if n > LU_ABOVE:
        ginv[:, :] = g
        lu_factor(ginv, piv[0])
        lu_pattern(ginv, piv[1:n + 1], piv[n + 1:])
    else:
        invert(g, ginv)


def _factor_loop(hd, dq, dv, ginv, piv):
    """:func:`factor` as loops (the same operations; numba compiles it without temporaries)."""
    n = dq.shape[0]
    g = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            g[i, j] = -hd * dv[i, j] - (hd * hd) * dq[i, j]
        g[i, i] += 1.0
    if n > LU_ABOVE:
        for i in range(n):
            for j in range(n):
                ginv[i, j] = g[i, j]
        lu_factor(ginv, piv[0])
        lu_pattern(ginv, piv[1:n + 1], piv[n + 1:])
    else:
        invert(g, ginv)


def apply_g(ginv, piv, b, out):
    """``out = G^-1 b`` (:func:`factor`'s inverse or LU factors)."""
    n = ginv.shape[0]
    if n > LU_ABOVE:
        lu_solve(ginv, piv[0], piv[1:n + 1], piv[n + 1:], b, out)
    else:
        matvec(ginv, b, out)


def solve(ginv, piv, dq, dq_index, hd, r, out, work):
    """``out = W^-1 r`` by blocks: ``x2 = G^-1 (r2 + hd dq r1)``, ``x1 = r1 + hd x2`` (``work``: n entries;
    ``dq_index``: the columns each row of ``dq`` can hold)."""
    n = dq.shape[0]
    r1 = r[:n]
    x1 = out[:n]
    x2 = out[n:]
    matvec_pattern(dq, dq_index, r1, work)
    work *= hd
    work += r[n:]
    apply_g(ginv, piv, work, x2)
    np.multiply(x2, hd, out=x1)
    x1 += r1


def _solve_loop(ginv, piv, dq, dq_index, hd, r, out, work):
    n = dq.shape[0]
    matvec_pattern(dq, dq_index, r[:n], work)
    for i in range(n):
        work[i] = r[n + i] + hd * work[i]
    apply_g(ginv, piv, work, out[n:])
    for i in range(n):
        out[i] = r[i] + hd * out[n + i]


def solve_lower(ginv, piv, hd, b, out):
    """``out = W^-1 [0, b]`` = ``[hd G^-1 b, G^-1 b]``."""
    n = ginv.shape[0]
    apply_g(ginv, piv, b, out[n:])
    np.multiply(out[n:], hd, out=out[:n])


def _solve_lower_loop(ginv, piv, hd, b, out):
    n = ginv.shape[0]
    apply_g(ginv, piv, b, out[n:])
    for i in range(n):
        out[i] = hd * out[n + i]


def stage(k, w, y, c, out):
    """``k += w``, then the stage's state ``out = y + c k`` (the stages of :func:`advance`)."""
    k += w
    np.multiply(k, c, out=out)
    out += y


def _stage_loop(k, w, y, c, out):
    for i in range(k.shape[0]):
        k[i] += w[i]
        out[i] = y[i] + c * k[i]


def third_rhs(fn, k2, f1, k1, f0, out):
    """The third stage's right-hand side ``out = fn - e32 (k2 - f1) - 2 (k1 - f0)``."""
    np.subtract(fn, E32 * (k2 - f1), out=out)
    out -= 2.0 * (k1 - f0)


def _third_rhs_loop(fn, k2, f1, k1, f0, out):
    for i in range(out.shape[0]):
        out[i] = fn[i] - E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i])


def error_norm(k1, k2, k3, y, yn, n, atol_q, atol_v, rtol):
    """``max |k1 - 2 k2 + k3| / (atol + rtol max(|y|, |yn|))`` (``atol_q`` on the first ``n`` entries, ``atol_v`` on
    the rest); NaN where any entry is NaN."""
    scale = np.abs(y)
    b = np.abs(yn)
    np.copyto(scale, b, where=b > scale)  # Python's max(a, b) (np.maximum differs where one of them is NaN)
    scale *= rtol
    scale[:n] += atol_q
    scale[n:] += atol_v
    e = k1 + k3
    e -= 2.0 * k2
    np.abs(e, out=e)
    e /= scale
    ratios = e.tolist()
    total = sum(ratios)  # of ratios >= 0 or NaN: NaN where one of them is (max skips a NaN after the first entry)
    return max(ratios) if total == total else math.nan


def _error_norm_loop(k1, k2, k3, y, yn, n, atol_q, atol_v, rtol):
    err = 0.0
    for i in range(k1.shape[0]):
        atol = atol_q if i < n else atol_v
        scale = atol + rtol * max(abs(y[i]), abs(yn[i]))
        e = abs(k1[i] + k3[i] - 2.0 * k2[i]) / scale
        if e > err or e != e:
            err = e
    return err


def basis_terms(w_basis, c0, c1, c2, out):
    """``out = c0 w_basis[0] + c1 w_basis[1] + c2 w_basis[2]``: the prescribed motions' part of ``h d W^-1 [0, f_t]``
    from its basis (:func:`time_derivative_term`)."""
    np.multiply(w_basis[0], c0, out=out)
    out += w_basis[1] * c1
    out += w_basis[2] * c2


def _basis_terms_loop(w_basis, c0, c1, c2, out):
    for i in range(out.shape[0]):
        out[i] = w_basis[0, i] * c0 + w_basis[1, i] * c1 + w_basis[2, i] * c2


def motion_terms(port_jac, kappa, port_rate, port_accel, jerk_, out):
    """``out = port_jac[0] port_rate + port_jac[1] port_accel - kappa jerk_``: the prescribed motions' part of ``f_t``
    (accelerations; :func:`time_derivative_term` with a time-varying mesh stiffness)."""
    np.multiply(port_jac[0], port_rate, out=out)
    out += port_jac[1] * port_accel
    out -= kappa * jerk_


def _motion_terms_loop(port_jac, kappa, port_rate, port_accel, jerk_, out):
    for j in range(out.shape[0]):
        out[j] = port_jac[0, j] * port_rate + port_jac[1, j] * port_accel - kappa[j] * jerk_


def use_factorisation(hd, dq, dv, winvs, pivots, istate):
    """Make the factorisation for ``hd`` the active one of the ``N_SLOTS`` kept (same Jacobian), factorising it into
    the least recently used slot where none is kept within :data:`SAME_HD`; returns its slot (its ``h d`` is then
    ``istate[HD]``, the one the step runs with)."""
    istate[CLOCK] += 1.0
    slot = -1
    for s in range(N_SLOTS):
        if abs(istate[SLOT_HD + s] - hd) <= SAME_HD * hd:
            slot = s
            break
    if slot < 0:
        slot = 0
        for s in range(1, N_SLOTS):
            if istate[SLOT_USED + s] < istate[SLOT_USED + slot]:
                slot = s
        factor(hd, dq, dv, winvs[slot], pivots[slot])
        istate[SLOT_HD + slot] = hd
        istate[SLOT_BASIS + slot] = 0.0
    istate[SLOT_USED + slot] = istate[CLOCK]
    istate[HD] = istate[SLOT_HD + slot]
    istate[ACTIVE] = float(slot)
    return slot


def twist_and_rate(twist_q, y, n, twist_port, port, tau):
    """Output-shaft twist [rad] and its rate [rad/s] at ``tau``: the weights on ``q`` and on ``v``, plus the port's.

    The numpy form runs the loop on Python floats (22 products: cheaper than numpy's calls on them)."""
    curve = port.tolist()
    twist = twist_port * value(curve, tau)
    rate_ = twist_port * rate(curve, tau)
    state = y[:2 * n].tolist()
    for w, q, v in zip(twist_q[:n].tolist(), state[:n], state[n:]):  # summed from the port's term on, as the loop
        twist += w * q
        rate_ += w * v
    return twist, rate_


def _twist_and_rate_loop(twist_q, y, n, twist_port, port, tau):
    twist = twist_port * value(port, tau)
    rate_ = twist_port * rate(port, tau)
    for i in range(n):
        twist += twist_q[i] * y[i]
        rate_ += twist_q[i] * y[n + i]
    return twist, rate_


def refresh_jacobian(k, y, t, angle0, driver, port):
    """Evaluate the Jacobian at local time ``t`` and state ``y``; every kept factorisation is void."""
    if k.tvs:
        stiffness_factors(angle0 + value(driver, t), k.phasing, k.factor, k.slope)
    jacobian(y, value(port, t), rate(port, t), k.factor, k.a_port, k.offset, k.contact, k.defl, k.nz_index,
             k.nz_value, k.cos_alpha, k.stks, k.stcs, k.stks_port, k.stcs_port, k.inv_m, k.fd, k.fv, k.dq, k.dv,
             k.port_jac)
    ist = k.istate
    ist[AGE] = 0.0
    ist[HD] = -1.0
    for s in range(N_SLOTS):
        ist[SLOT_HD + s] = -1.0
    ist[JACOBIANS] += 1.0


def time_derivative_term(k, y, t, h, hd, angle0, driver, port, winv, piv, w_basis):
    """``h d W^-1 [0, f_t]`` into ``k.w_hdt``: the prescribed motions' part of the stages at local time ``t``
    (and the external loads', which move with the driver angle and speed)."""
    n = k.dq.shape[0]
    w_hdt = k.w_hdt
    n_ext = k.n_ext
    ext = k.fast[k.fast.shape[0] - n_ext:]  # the external rows (none without external loads)
    rates = k.w_ext[:n_ext]  # the time derivatives of the external terms
    if n_ext:
        external_term_rates(angle0 + value(driver, t), rate(driver, t), accel(driver, t), k.load_rates, rates)
    if not k.tvs:  # f_t = [port speed, port accel, driver jerk, external rates] @ [pj0; pj1; -kappa; external
        # rows]: W^-1 of the rows once per factorisation
        ist = k.istate
        active = int(ist[ACTIVE])
        if ist[SLOT_BASIS + active] == 0.0:
            solve_lower(winv, piv, hd, k.port_jac[0], w_basis[0])
            solve_lower(winv, piv, hd, k.port_jac[1], w_basis[1])
            solve_lower(winv, piv, hd, k.kappa, w_basis[2])
            negate(w_basis[2])
            for r in range(n_ext):
                if r != 1:  # the constant term has no rate
                    solve_lower(winv, piv, hd, ext[r], w_basis[3 + r])
            ist[SLOT_BASIS + active] = 1.0
        basis_terms(w_basis, hd * rate(port, t), hd * accel(port, t), hd * jerk(driver), w_hdt)
        for r in range(n_ext):
            if r != 1:
                axpy(hd * rates[r], w_basis[3 + r], w_hdt)
        return
    pr = rate(port, t)
    pa = accel(port, t)
    jk = jerk(driver)
    da = k.da
    motion_terms(k.port_jac, k.kappa, pr, pa, jk, da)
    stiffness_rate(y, n, angle0 + value(driver, t), rate(driver, t), value(port, t), pr, k.nz_index, k.nz_value,
                   k.a_port, k.offset, k.contact, k.phasing, k.force_rows, k.factor, k.slope, k.defl, k.sens, da)
    for r in range(n_ext):
        axpy(rates[r], ext[r], da)
    da *= hd
    solve_lower(winv, piv, hd, da, w_hdt)


def evaluate(k, y, t, angle0, driver, port, out):
    """``out = [v, a(t, q, v)]`` at local time ``t`` (forces and deflections left in ``k.z``, ``k.defl``)."""
    n = k.dq.shape[0]
    if k.tvs:
        stiffness_factors(angle0 + value(driver, t), k.phasing, k.factor, k.slope)
    if k.n_ext:
        first = k.fast.shape[0] - k.n_ext
        external_terms(angle0 + value(driver, t), rate(driver, t), k.load_rates, k.z[first:first + k.n_ext])
    acceleration(y, value(port, t), rate(port, t), accel(driver, t), k.factor, k.nz_index, k.nz_value, k.a_port,
                 k.offset, k.fast_index, k.fast_value, k.contact, k.z, k.defl, k.acc)
    copy(y[n:], out[:n])
    copy(k.acc, out[n:])


def advance(k, y, t_end, alpha_shift, driver, port, angle0, twist_q, twist_port):
    """Integrate one communication step ``[0, t_end]`` of local time from the state ``y`` (overwritten on success).

    Parameters
    ----------
    k : Gearbox
        Constants, work arrays and state (:class:`components.model.kernel.step.Gearbox`).
    y : ndarray (2n,)
        State ``[q, v]`` at local time 0.
    alpha_shift : float
        Driver acceleration of the last evaluation minus the driver acceleration at local time 0:
        the acceleration there is ``last_acc + kappa alpha_shift`` (the prescribed motions are C1).
    driver, port : ndarray (4,)
        Hermite coefficients of the driver angle (relative to ``angle0``) and of the port input.
    twist_q : ndarray (2n,), twist_port : float
        Weights of the output-shaft twist on ``[q, 0]`` and on the port angle (its rate: the same weights
        on the speeds ``v`` and on the port speed).

    Returns
    -------
    status, time, step, error, twist_integral : (int, float, float, float, float)
        ``OK`` or the failure code with the local time, step size and error norm at the failure;
        the integral of the output-shaft twist over ``[0, t_end]`` [rad s] (Hermite-corrected
        trapezoid per accepted step; 0 on failure). On failure the state is as it was.
    """
    n = k.dq.shape[0]
    m = k.last_force.shape[0]
    ist = k.istate
    control = k.control
    f0, f1, fn, k1, k2, k3, y1, yn, rhs, w_hdt = k.f0, k.f1, k.fn, k.k1, k.k2, k.k3, k.y1, k.yn, k.rhs, k.w_hdt
    dq, jac_index, sol = k.dq, k.jac_index, k.sol
    last_acc, forces, last_force = k.last_acc, k.z[:m], k.last_force  # what an accepted step keeps
    defl0, defl1, last_defl0, last_defl1 = k.defl[0], k.defl[1], k.last_defl[0], k.last_defl[1]
    fn_acc = fn[n:]
    copy(k.state, k.backup)  # restored on failure
    rtol = control[RTOL]
    atol_q = control[ATOL_Q]
    atol_v = control[ATOL_V]
    h_min = control[H_MIN]
    max_steps = control[MAX_STEPS]
    max_age = control[JAC_MAX_AGE]
    out_kin = control[OUT_KINEMATIC]
    out_idx = int(control[OUT_RATE_INDEX])
    k.factor[:] = 1.0
    active = int(ist[ACTIVE])
    winv = k.winvs[active]
    piv = k.pivots[active]
    w_basis = k.w_bases[active]
    t = 0.0
    h = ist[H_NEXT] if ist[H_NEXT] > 0.0 else t_end - t
    if 0.0 < ist[H_FIRST] < h:  # the transient the new inputs start at a communication point: the first
        h = ist[H_FIRST]  # step the last one allowed (else the proposal from the smooth end of the step is rejected)
    first_rejected = False
    copy(y[n:], f0[:n])
    copy(k.last_acc, f0[n:])
    axpy(alpha_shift, k.kappa, f0[n:])
    # time, output-shaft twist and its rate at the last accepted internal step, and the twist's integral so far
    twist_t = 0.0
    twist_a, twist_r = twist_and_rate(twist_q, y, n, twist_port, port, 0.0)
    twist_integral = 0.0
    steps = 0
    prev_h = -1.0  # (h, err) of a rejected attempt at this t with a fresh Jacobian (prev_h < 0: none)
    prev_err = 0.0
    while t < t_end:
        remaining = t_end - t
        last = h >= remaining * (1.0 - 1e-12)
        if last:
            h = remaining
        else:  # equal steps to the communication point: their sizes recur, and so do their factorisations
            pieces = math.ceil(remaining / h * (1.0 - 1e-12))
            h = remaining / pieces
        if ist[AGE] < 0.0 or ist[AGE] >= max_age:
            refresh_jacobian(k, y, t, angle0, driver, port)
        # ---- one step
        hd = h * D
        if abs(hd - ist[HD]) > SAME_HD * hd:
            active = use_factorisation(hd, dq, k.dv, k.winvs, k.pivots, ist)
            winv = k.winvs[active]
            piv = k.pivots[active]
            w_basis = k.w_bases[active]
        hd = ist[HD]  # the active factorisation's (the step's h d up to round-off)
        time_derivative_term(k, y, t, h, hd, angle0, driver, port, winv, piv, w_basis)
        solve(winv, piv, dq, jac_index, hd, f0, k1, sol)
        stage(k1, w_hdt, y, 0.5 * h, y1)
        evaluate(k, y1, t + 0.5 * h, angle0, driver, port, f1)
        subtract(f1, k1, rhs)
        solve(winv, piv, dq, jac_index, hd, rhs, k2, sol)
        stage(k2, k1, y, h, yn)
        evaluate(k, yn, t + h, angle0, driver, port, fn)
        third_rhs(fn, k2, f1, k1, f0, rhs)
        solve(winv, piv, dq, jac_index, hd, rhs, k3, sol)
        axpy(1.0, w_hdt, k3)
        err = (h / 6.0) * error_norm(k1, k2, k3, y, yn, n, atol_q, atol_v, rtol)
        if not math.isfinite(err):
            err = math.inf
        # ---- step control
        steps += 1
        if err <= 1.0:
            prev_h = -1.0
            ist[ACCEPTED] += 1.0
            ist[AGE] += 1.0
            first = t == 0.0
            t = t_end if last else t + h
            copy(yn, y)
            copy(fn, f0)
            copy(fn_acc, last_acc)
            copy(forces, last_force)
            copy(defl0, last_defl0)
            copy(defl1, last_defl1)
            alpha_out = abs(out_kin * accel(driver, t) + f0[out_idx])
            if alpha_out > ist[ALPHA_OUT_MAX]:  # eq. 11's running maximum
                ist[ALPHA_OUT_MAX] = alpha_out
            twist_b, rate_b = twist_and_rate(twist_q, y, n, twist_port, port, t)
            dt = t - twist_t
            twist_integral += 0.5 * dt * (twist_a + twist_b) + dt * dt * (twist_r - rate_b) / 12.0
            twist_t = t
            twist_a = twist_b
            twist_r = rate_b
            fac = 5.0 if err == 0.0 else min(5.0, 0.9 * err ** (-1.0 / 3.0))
            fac = 1.0 if 1.0 <= fac <= 2.0 else fac  # keep the step (and the factorisation)
            if first:  # keep the first step's own proposal for the next communication point while it binds
                ist[H_FIRST] = h * fac if first_rejected or (0.0 < ist[H_FIRST] and h * fac < ist[H_NEXT]) else 0.0
            if not last or fac < 1.0:
                ist[H_NEXT] = h * fac
            else:  # a step shortened to hit t_end must not shrink the proposal
                ist[H_NEXT] = max(ist[H_NEXT], h * fac)
            h = ist[H_NEXT]
        else:
            ist[REJECTED] += 1.0
            first_rejected = first_rejected or t == 0.0
            if ist[AGE] > 0.0:  # retry with a fresh Jacobian before shrinking the step much
                refresh_jacobian(k, y, t, angle0, driver, port)
                h *= max(0.5, min(1.0, 0.9 * err ** (-1.0 / 3.0))) if math.isfinite(err) else 0.1
                prev_h = -1.0
            else:
                if not math.isfinite(err):
                    fac = 0.1
                elif prev_h > 0.0 and err < prev_err and h < prev_h:  # the order observed between two attempts
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
            ist[H_NEXT] = h
            if h < h_min:
                copy(k.backup, k.state)
                return STEP_TOO_SMALL, t, h, err, 0.0
        if steps > max_steps:
            copy(k.backup, k.state)
            return TOO_MANY_STEPS, t, h, err, 0.0
    return OK, t, h, 0.0, twist_integral


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"factor": _factor_loop, "solve": _solve_loop, "solve_lower": _solve_lower_loop,
            "twist_and_rate": _twist_and_rate_loop, "stage": _stage_loop, "third_rhs": _third_rhs_loop,
            "error_norm": _error_norm_loop, "basis_terms": _basis_terms_loop, "motion_terms": _motion_terms_loop}
INLINE = ("twist_and_rate", "evaluate", "time_derivative_term", "refresh_jacobian", "advance", "stage", "third_rhs",
          "error_norm", "basis_terms", "motion_terms")
