"""Static equilibrium: the deflections at which meshes and shafts carry a constant load at constant speed.

Every body turns at its kinematic speed (deviation speeds ``v = 0``, driver acceleration 0) and
the accelerations of :func:`.dynamics.acceleration` vanish: ``a(q, 0, u) = 0`` for the deviation
angles ``q``, with the port input ``u`` given (the counter torque on the output body, or the
port's deviation angle). Newton's method with the analytic Jacobian ``da/dq`` and a backtracking
line search, started from two linear solves with the meshes as linear springs on the loaded
flank (offset by half the backlash): first with the stiffness at 1 cm penetration (soft, safe),
then with the secant stiffness of the contact law at the forces of the first. Unloaded teeth
float in the backlash and have no static position: the load must not be zero.
"""

from __future__ import annotations

import math

from .contact import EXPONENT, HALF_JT, K0
from .dynamics import acceleration, jacobian
from .linalg import invert, matvec

#: status of :func:`static_deflection`
CONVERGED, NOT_CONVERGED, SINGULAR = range(3)


def _linear_guess(y, n, port, flank, stiffness, a_t, a_port, offset, fast, contact, z, g, ginv, c):
    """``q`` (into ``y[:n]``) of the meshes as linear springs ``F = k (d - flank j_t/2)``: ``G q + c = 0`` (with the
    external loads of the terms in ``z``)."""
    m = contact.shape[0]
    for j in range(n):
        cj = port * fast[m + 2 * n, j]
        for t in range(m + 2 * n + 3, fast.shape[0]):
            cj += z[t] * fast[t, j]
        for i in range(m):
            cj += stiffness[i] * (a_port[i] * port + offset[i] - flank * contact[i, HALF_JT]) * fast[i, j]
        c[j] = cj
        for k in range(n):
            s = fast[m + k, j]
            for i in range(m):
                s += stiffness[i] * a_t[k, i] * fast[i, j]
            g[j, k] = s
    invert(g, ginv)
    matvec(ginv, c, y[:n])
    for j in range(n):
        y[j] = -y[j]


def _imbalance(y, n, port, factor, nz_index, nz_value, a_port, offset, fast, fast_index, fast_value, contact, z, defl,
               acc, inv_m):
    """``(max |M a|, max over bodies of the sum of the magnitudes of its generalised forces)`` at ``y`` [N m]."""
    m = contact.shape[0]
    acceleration(y, port, 0.0, 0.0, factor, nz_index, nz_value, a_port, offset, fast_index, fast_value, contact, z, defl,
                 acc)
    worst = 0.0
    scale = 0.0
    for j in range(n):
        worst = max(worst, abs(acc[j]) / inv_m[j])
        s = 0.0
        for i in range(m):  # the forces, then [q, v], then the port input, its rate and the driver acceleration
            s += abs(z[i] * fast[i, j])
        for i in range(2 * n):
            s += abs(y[i] * fast[m + i, j])
        for i in range(m + 2 * n, fast.shape[0]):  # the port, its rate, the driver acceleration, external loads
            s += abs(z[i] * fast[i, j])
        scale = max(scale, s / inv_m[j])
    return worst, scale


def static_deflection(y, n, port, factor, flank, a_t, a_port, offset, fast, fast_index, fast_value, contact, nz_index,
                      nz_value, cos_alpha,
                      stks, stcs, stks_port, stcs_port, inv_m, z, defl, acc, fd, fv, dq, dv, port_jac, g, ginv, c, step,
                      stiffness, trial, rtol, max_iterations):
    """Solve ``a(q, v, u) = 0`` for ``q = y[:n]`` at the port input ``u = port`` (``v = y[n:]`` kept, normally 0).

    The external loads are those of the external terms already in ``z`` (:func:`.dynamics.external_terms`;
    gravity at one driver angle, the centrifugal force at one speed).

    Parameters
    ----------
    flank : float
        +1 or -1: the flank the load presses (the sign of the counter torque).
    rtol : float
        Converged when the largest generalised-force imbalance is below ``rtol`` times the largest
        sum of generalised-force magnitudes on one body.
    fast, fast_index, fast_value : ndarray
        The folded matrix, and by columns (:func:`.dynamics.acceleration`).
    g, ginv, dq, dv : ndarray (n, n); c, step, acc : ndarray (n,); stiffness : ndarray (n_mesh,);
    trial : ndarray like ``y``; the others as :func:`.dynamics.jacobian`
        Work arrays.

    Returns
    -------
    status, iterations, imbalance : (int, int, float)
        ``CONVERGED``, ``NOT_CONVERGED`` (after ``max_iterations``) or ``SINGULAR``; the Newton iterations;
        the remaining imbalance relative to its scale.
    """
    m = contact.shape[0]
    for i in range(m):  # the stiffness at 1 cm penetration: soft, a safe start
        stiffness[i] = contact[i, K0] * factor[i] * 0.01 ** (contact[i, EXPONENT] - 1.0)
    _linear_guess(y, n, port, flank, stiffness, a_t, a_port, offset, fast, contact, z, g, ginv, c)
    for i in range(m):  # the secant stiffness of the contact law at those forces
        d = port * a_port[i] + offset[i]
        for k in range(n):
            d += y[k] * a_t[k, i]
        force = abs(stiffness[i] * (d - flank * contact[i, HALF_JT]))
        k0 = contact[i, K0] * factor[i]
        e = contact[i, EXPONENT]
        penetration = max((force / k0) ** (1.0 / e), 1e-9)
        stiffness[i] = k0 * penetration ** (e - 1.0)
    _linear_guess(y, n, port, flank, stiffness, a_t, a_port, offset, fast, contact, z, g, ginv, c)
    worst, scale = _imbalance(y, n, port, factor, nz_index, nz_value, a_port, offset, fast, fast_index, fast_value,
                              contact, z, defl, acc, inv_m)
    iterations = 0
    while worst > rtol * scale:
        if iterations >= max_iterations:
            return NOT_CONVERGED, iterations, worst / scale
        iterations += 1
        jacobian(y, port, 0.0, factor, a_port, offset, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs,
                 stks_port, stcs_port, inv_m, fd, fv, dq, dv, port_jac)
        for j in range(n):
            for k in range(n):
                g[j, k] = dq[j, k]
        invert(g, ginv)
        acceleration(y, port, 0.0, 0.0, factor, nz_index, nz_value, a_port, offset, fast_index, fast_value, contact, z,
                     defl, acc)
        matvec(ginv, acc, step)
        for j in range(n):
            if not math.isfinite(step[j]):
                return SINGULAR, iterations, worst / scale
        alpha = 1.0
        while True:  # backtracking: the imbalance must fall
            for j in range(y.shape[0]):
                trial[j] = y[j]
            for j in range(n):
                trial[j] = y[j] - alpha * step[j]
            new_worst, new_scale = _imbalance(trial, n, port, factor, nz_index, nz_value, a_port, offset, fast,
                                              fast_index, fast_value, contact, z, defl, acc, inv_m)
            if new_worst < worst or alpha < 1e-6:
                break
            alpha *= 0.5
        for j in range(n):
            y[j] = trial[j]
        worst, scale = new_worst, new_scale
    return CONVERGED, iterations, worst / scale
