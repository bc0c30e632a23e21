"""One communication step of the gearbox (the co-simulation cut at the generator) and its outputs.

:func:`gearbox_step` advances the state held in the model's buffer (:mod:`.layout`) from ``t``
to ``t + h`` with the inputs received at ``t``; :func:`outputs` writes every output. The inputs
are interpreted as described in :mod:`.motion`: the driver (rotor) follows a cubic from the
motion it had to the target extrapolated from the rotor inputs (linear acceleration estimate, or
the source's acceleration and jerk with ``rotor_derivatives``); the port is either the
generator end of the output shaft following its own curve (``motion`` interface) or the
counter torque held over the step with the generator rotor a degree of freedom whose speed is
re-anchored at every communication point: on the generator-speed input (``inertia`` interface), or on the
gearbox's own impulse balance of the generator, ``I_g (w_n+1 - w_n) = h (mean shaft torque - counter torque)``
(``inertia_own``: what the generator component computes from the same torques, for hosts that exchange values
after all components stepped, Jacobi).

This is the gearbox kernel's entry module: run interpreted, compiled by numba, or ahead of time
(``AOT_EXPORTS``) - see :mod:`components.compile`.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .dynamics import acceleration, external_terms
from .integrator import advance
from .layout import (
    A_PORT, A_T, ACC, ANCHOR, BACKUP, CONTACT, CONTROL, COS_ALPHA, D_END_TORQUE, D_EXT, D_EXTRAPOLATE, D_GEN_DOF, D_M,
    D_MAGNITUDES, D_N, D_OWN_GEN_SPEED, D_ROTOR_DERIVATIVES, D_TVS, DA, DEFL, DQ, DRIVER, DV, F0, F1, FAST, FAST_INDEX,
    FAST_VALUE, FD, FN, FACTOR, FORCE_ROWS, FV, INV_M, ISTATE, JAC_INDEX, K1, K2, K3, KAPPA, LAST_ACC, LAST_DEFL,
    LAST_FORCE, LOAD_RATES, MAGNITUDES, NON_FINITE_INPUT, N_SLOTS, NZ_INDEX, NZ_VALUE, OFFSET, OK, PIVOTS, OUT_INDEX,
    OUT_KINEMATIC, OUT_RATE_INDEX, OUT_VALUE, OUTPUTS, PHASING, PORT, PORT_JAC, RHS, S_ALPHA_OUT_AVG, S_DRIVER_ACCEL,
    S_DRIVER_ANGLE, S_DRIVER_SPEED, S_GEN_SPEED, S_KX, S_LAST_ALPHA, S_LAST_OMEGA_GEN, S_LAST_OMEGA_ROTOR, S_LAST_STEP,
    S_OUTPUT_TWIST, S_PORT_ANGLE, S_PORT_OFFSET, S_PORT_SPEED, S_SHAFT_C, S_SHAFT_K, S_SHAFT_TORQUE_AVG, S_TIME,
    S_TWIST_PORT, SCALARS, SENS, SLOPE, SOL, STATE_FIRST, STATE_LAST, STCS, STCS_PORT, STKS, STKS_PORT, TWIST_Q, W_BASES,
    W_EXT, W_HDT, WINVS, Y, Y1, YN, Z, ALPHA_OUT_MAX,
)
from .linalg import axpy2, copy, dot, sparse_vecmat
from .motion import accel, fit, linear_target, taylor_target
from .statics import static_deflection
from .stiffness import stiffness_factors

#: everything :func:`~.integrator.advance` reads and writes: views of the buffer
Gearbox = namedtuple("Gearbox", (
    "a_t", "a_port", "fast", "contact", "stks", "stcs", "stks_port", "stcs_port", "inv_m", "phasing", "kappa",
    "force_rows", "nz_index", "nz_value", "cos_alpha", "control", "offset", "load_rates", "fast_index", "fast_value",
    "jac_index",
    "z", "defl", "acc", "fd", "fv", "factor", "slope", "sens", "f0", "f1", "fn", "k1", "k2", "k3", "y1", "yn", "rhs",
    "w_hdt", "da", "w_ext", "sol",
    "istate", "dq", "dv", "winvs", "pivots", "w_bases", "port_jac", "last_acc", "last_force", "last_defl", "state", "backup",
    "tvs", "n_ext",
))


def vector(buf, lay, slot):
    """The slot as a 1-D view of the buffer."""
    return buf[lay[slot]:lay[slot + 1]]


def matrix(buf, lay, slot, rows):
    """The slot as a 2-D view with ``rows`` rows."""
    v = buf[lay[slot]:lay[slot + 1]]
    return v.reshape((rows, v.shape[0] // rows))


#: buffers whose views the interpreted :func:`views` keeps, at most (all are dropped when one more is asked for)
KEPT_VIEWS = 8
_kept_views: dict = {}


def views(buf, lay, dims):
    """The :class:`Gearbox` views of a buffer.

    The numpy form keeps the views it made for up to :data:`KEPT_VIEWS` buffers, by the identity of the
    buffer and its offset and size tables (a model steps one buffer with the same tables every time: making
    the ~60 views costs ~15 us, 4 % of an interpreted step). A kept entry holds those objects, so the identity
    of no other can be mistaken for theirs; the tables are never changed in place. Its dict operations are each
    atomic, so FMUs stepped in threads of one process (a host's) may share it.
    """
    key = (id(buf), id(lay), id(dims))
    kept = _kept_views.get(key)
    if kept is None:
        if len(_kept_views) >= KEPT_VIEWS:
            _kept_views.clear()
        kept = _kept_views[key] = (buf, lay, dims, _views_loop(buf, lay, dims))
    return kept[3]


def _views_loop(buf, lay, dims):
    n = dims[D_N]
    m = dims[D_M]
    n2 = 2 * n
    winvs = vector(buf, lay, WINVS).reshape((N_SLOTS, n, n))
    w_bases = vector(buf, lay, W_BASES).reshape((N_SLOTS, 3 + dims[D_EXT], n2))
    return Gearbox(
        matrix(buf, lay, A_T, n), vector(buf, lay, A_PORT), matrix(buf, lay, FAST, m + n2 + 3 + dims[D_EXT]),
        matrix(buf, lay, CONTACT, m), matrix(buf, lay, STKS, n), matrix(buf, lay, STCS, n),
        vector(buf, lay, STKS_PORT), vector(buf, lay, STCS_PORT), vector(buf, lay, INV_M),
        matrix(buf, lay, PHASING, 7), vector(buf, lay, KAPPA), matrix(buf, lay, FORCE_ROWS, m),
        matrix(buf, lay, NZ_INDEX, m), matrix(buf, lay, NZ_VALUE, m), vector(buf, lay, COS_ALPHA),
        vector(buf, lay, CONTROL), vector(buf, lay, OFFSET), vector(buf, lay, LOAD_RATES),
        matrix(buf, lay, FAST_INDEX, n), matrix(buf, lay, FAST_VALUE, n), matrix(buf, lay, JAC_INDEX, n),
        vector(buf, lay, Z), matrix(buf, lay, DEFL, 2), vector(buf, lay, ACC), vector(buf, lay, FD),
        vector(buf, lay, FV), vector(buf, lay, FACTOR), vector(buf, lay, SLOPE), vector(buf, lay, SENS),
        vector(buf, lay, F0), vector(buf, lay, F1), vector(buf, lay, FN), vector(buf, lay, K1), vector(buf, lay, K2),
        vector(buf, lay, K3), vector(buf, lay, Y1), vector(buf, lay, YN), vector(buf, lay, RHS),
        vector(buf, lay, W_HDT), vector(buf, lay, DA), vector(buf, lay, W_EXT), vector(buf, lay, SOL),
        vector(buf, lay, ISTATE), matrix(buf, lay, DQ, n), matrix(buf, lay, DV, n), winvs,
        vector(buf, lay, PIVOTS).reshape((N_SLOTS, 2 * n + 1, n)), w_bases,
        matrix(buf, lay, PORT_JAC, 2), vector(buf, lay, LAST_ACC), vector(buf, lay, LAST_FORCE),
        matrix(buf, lay, LAST_DEFL, 2), buf[lay[STATE_FIRST]:lay[STATE_LAST + 1]], vector(buf, lay, BACKUP),
        dims[D_TVS] != 0, dims[D_EXT],
    )


def outputs(buf, lay, dims):
    """Every output at the current time into the ``outputs`` slot.

    ``[shaft torque (average or end), average, then the linear outputs, the magnitudes, alpha_out average,
    alpha_out max, generator speed]``; the linear outputs are ``[F, q, v, port angle, port speed, driver speed,
    driver accel] @ output matrix`` (held by columns, its nonzero rows only: ``out_index``, ``out_value``), the
    magnitudes ``hypot`` of two linear outputs each (the bearing forces; the rows of the ``magnitudes`` slot index
    the linear outputs, -1 for none).
    """
    n = dims[D_N]
    m = dims[D_M]
    sc = vector(buf, lay, SCALARS)
    out = vector(buf, lay, OUTPUTS)
    z = vector(buf, lay, Z)
    y = vector(buf, lay, Y)
    force = vector(buf, lay, LAST_FORCE)
    copy(force, z[:m])
    copy(y, z[m:m + 2 * n])
    z[m + 2 * n] = sc[S_PORT_ANGLE]
    z[m + 2 * n + 1] = sc[S_PORT_SPEED]
    z[m + 2 * n + 2] = sc[S_DRIVER_SPEED]
    z[m + 2 * n + 3] = sc[S_DRIVER_ACCEL]
    n_mag = dims[D_MAGNITUDES]
    cols = out.shape[0] - 5 - n_mag
    sparse_vecmat(z, matrix(buf, lay, OUT_INDEX, cols), matrix(buf, lay, OUT_VALUE, cols), out[2:2 + cols])
    avg = sc[S_SHAFT_TORQUE_AVG]
    out[0] = out[2] if dims[D_END_TORQUE] != 0 else avg
    out[1] = avg
    if n_mag:
        pairs = matrix(buf, lay, MAGNITUDES, n_mag)
        for j in range(n_mag):
            a = out[2 + int(pairs[j, 0])]
            b = out[2 + int(pairs[j, 1])] if pairs[j, 1] >= 0.0 else 0.0
            out[2 + cols + j] = math.sqrt(a * a + b * b)
    out[2 + cols + n_mag] = sc[S_ALPHA_OUT_AVG]
    out[3 + cols + n_mag] = vector(buf, lay, ISTATE)[ALPHA_OUT_MAX]
    out[4 + cols + n_mag] = sc[S_GEN_SPEED]


def external(k, sc):
    """The external terms at the current driver angle and speed into ``k.z`` (:func:`.dynamics.external_terms`)."""
    first = k.fast.shape[0] - k.n_ext
    external_terms(sc[S_DRIVER_ANGLE], sc[S_DRIVER_SPEED], k.load_rates, k.z[first:first + k.n_ext])


def current_loads(buf, lay, dims):
    """The accelerations, forces and deflections at the current state and inputs (the start of the next step),
    then every output. Called after the state was set from outside (initialisation)."""
    k = views(buf, lay, dims)
    sc = vector(buf, lay, SCALARS)
    m = dims[D_M]
    if k.tvs:
        stiffness_factors(sc[S_DRIVER_ANGLE], k.phasing, k.factor, k.slope)
    else:
        k.factor[:] = 1.0
    external(k, sc)
    acceleration(vector(buf, lay, Y), sc[S_PORT_ANGLE], sc[S_PORT_SPEED], sc[S_LAST_ALPHA], k.factor, k.nz_index,
                 k.nz_value, k.a_port, k.offset, k.fast_index, k.fast_value, k.contact, k.z, k.defl, k.acc)
    copy(k.acc, k.last_acc)
    copy(k.z[:m], k.last_force)
    copy(k.defl[0], k.last_defl[0])
    copy(k.defl[1], k.last_defl[1])
    outputs(buf, lay, dims)


def settle(buf, lay, dims, flank, rtol, max_iterations):
    """Replace the deviation angles by the static deflection at the current port input (speeds kept), then
    evaluate the loads there (:func:`current_loads`).

    Returns ``(status, iterations, imbalance)`` of :func:`.statics.static_deflection`.
    """
    k = views(buf, lay, dims)
    sc = vector(buf, lay, SCALARS)
    n = dims[D_N]
    m = dims[D_M]
    if k.tvs:
        stiffness_factors(sc[S_DRIVER_ANGLE], k.phasing, k.factor, k.slope)
    else:
        k.factor[:] = 1.0
    external(k, sc)
    y = vector(buf, lay, Y)
    status, iterations, imbalance = static_deflection(
        y, n, sc[S_PORT_ANGLE], k.factor, flank, k.a_t, k.a_port, k.offset, k.fast, k.fast_index, k.fast_value,
        k.contact, k.nz_index, k.nz_value,
        k.cos_alpha, k.stks, k.stcs, k.stks_port, k.stcs_port, k.inv_m, k.z, k.defl, k.acc, k.fd, k.fv, k.dq, k.dv,
        k.port_jac, np.empty((n, n)), np.empty((n, n)), np.empty(n), np.empty(n), np.empty(m), np.empty(2 * n), rtol,
        max_iterations)
    current_loads(buf, lay, dims)
    return status, iterations, imbalance


def gearbox_step(buf, lay, dims, t, h, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque, alpha_rotor,
                 jerk_rotor):
    """Advance the state in ``buf`` from ``t`` to ``t + h`` [s] with the inputs received at ``t``; outputs into the buffer.

    Returns ``(status, local time, step size, error norm)`` (:func:`~.integrator.advance`), or
    ``NON_FINITE_INPUT``; on failure the buffer is as it was at ``t``.
    """
    n = dims[D_N]
    m = dims[D_M]
    gdof = dims[D_GEN_DOF]
    k = views(buf, lay, dims)
    sc = vector(buf, lay, SCALARS)
    y = vector(buf, lay, Y)
    out_kin = k.control[OUT_KINEMATIC]
    out_idx = int(k.control[OUT_RATE_INDEX])
    extrapolate = dims[D_EXTRAPOLATE] != 0 and sc[S_LAST_STEP] > 0.0
    alpha_gen = (omega_gen - sc[S_LAST_OMEGA_GEN]) / sc[S_LAST_STEP] if extrapolate and gdof < 0 else 0.0
    if dims[D_ROTOR_DERIVATIVES] != 0:  # third-order Taylor from the source's derivatives
        angle1, speed1 = taylor_target(h, phi_rotor, omega_rotor, alpha_rotor, jerk_rotor)
    else:  # the acceleration estimated from the last two speed inputs
        alpha = (omega_rotor - sc[S_LAST_OMEGA_ROTOR]) / sc[S_LAST_STEP] if extrapolate else 0.0
        angle1, speed1 = linear_target(h, phi_rotor, omega_rotor, alpha)
    kx = sc[S_KX]
    dv = 0.0
    gen_speed = omega_gen  # the generator speed the step starts from (inertia interfaces)
    if gdof >= 0:  # inertia interface: the port input is the held counter torque
        port0 = counter_torque
        port_speed0 = 0.0
        port1 = port0
        port_speed1 = 0.0
        if dims[D_OWN_GEN_SPEED] != 0:
            gen_speed = sc[S_GEN_SPEED]
        dv = gen_speed - kx * sc[S_DRIVER_SPEED] - y[n + gdof]
        if not math.isfinite(dv + port0):
            return NON_FINITE_INPUT, 0.0, h, 0.0
    else:  # motion interface: the port is the generator end's deviation from the kinematic motion (its angle
        # input read relative to the static twist it had at initialisation: the port offset)
        port0 = sc[S_PORT_ANGLE]
        port_speed0 = sc[S_PORT_SPEED]
        gen_angle1, gen_speed1 = linear_target(h, phi_gen, omega_gen, alpha_gen)
        port1 = gen_angle1 - kx * angle1 + sc[S_PORT_OFFSET]
        port_speed1 = gen_speed1 - kx * speed1
    if not math.isfinite(angle1 + speed1 + port1 + port_speed1):
        return NON_FINITE_INPUT, 0.0, h, 0.0
    driver = vector(buf, lay, DRIVER)
    port = vector(buf, lay, PORT)
    angle0 = sc[S_DRIVER_ANGLE]
    fit(driver, h, 0.0, sc[S_DRIVER_SPEED], angle1 - sc[S_DRIVER_ANGLE], speed1)
    fit(port, h, port0, port_speed0, port1, port_speed1)
    anchor = vector(buf, lay, ANCHOR)
    last_acc = k.last_acc
    if gdof >= 0:  # re-anchor the generator speed; the loads follow linearly (the generator is in no mesh)
        d_torque = port0 - sc[S_PORT_ANGLE]
        anchor[0] = y[n + gdof]
        y[n + gdof] += dv
        copy(last_acc, anchor[1:])
        axpy2(dv, k.fast[m + n + gdof], d_torque, k.fast[m + 2 * n], last_acc)
    twist_start = sc[S_OUTPUT_TWIST]
    speed_start = out_kin * sc[S_DRIVER_SPEED] + y[out_idx]
    twist_q = vector(buf, lay, TWIST_Q)
    status, tau, h_fail, err, twist_integral = advance(
        k, y, h, sc[S_LAST_ALPHA] - accel(driver, 0.0), driver, port, angle0, twist_q, sc[S_TWIST_PORT])
    if status != OK:
        if gdof >= 0:  # undo the re-anchoring (advance restored the state it was given)
            y[n + gdof] = anchor[0]
            copy(anchor[1:], last_acc)
        return status, tau, h_fail, err
    sc[S_TIME] = t + h
    sc[S_DRIVER_ANGLE] = angle1
    sc[S_DRIVER_SPEED] = speed1
    sc[S_DRIVER_ACCEL] = accel(driver, h)
    sc[S_LAST_ALPHA] = sc[S_DRIVER_ACCEL]
    sc[S_PORT_ANGLE] = port1
    sc[S_PORT_SPEED] = port_speed1
    sc[S_LAST_OMEGA_ROTOR] = omega_rotor
    sc[S_LAST_OMEGA_GEN] = omega_gen
    sc[S_LAST_STEP] = h
    twist_end = dot(twist_q, y) + sc[S_TWIST_PORT] * port1
    sc[S_OUTPUT_TWIST] = twist_end
    # (1/h) int T dt = k mean(twist) + c (twist_end - twist_start) / h: conserves the exchanged impulse
    sc[S_SHAFT_TORQUE_AVG] = sc[S_SHAFT_K] * twist_integral / h + sc[S_SHAFT_C] * (twist_end - twist_start) / h
    sc[S_ALPHA_OUT_AVG] = (out_kin * speed1 + y[out_idx] - speed_start) / h
    if gdof >= 0:  # the generator's impulse balance over the step (the generator component's own equation)
        sc[S_GEN_SPEED] = gen_speed + (sc[S_SHAFT_TORQUE_AVG] - port0) * h * k.inv_m[gdof]
    else:
        sc[S_GEN_SPEED] = kx * speed1 + port_speed1
    outputs(buf, lay, dims)
    return OK, tau, h, 0.0


#: the loop numba compiles in place of the numpy form (see :mod:`components.compile.jit`)
COMPILED = {"views": _views_loop}
INLINE = ("vector", "matrix", "views", "external")
#: entry points of the ahead-of-time compiled module (:mod:`components.compile.aot`) and their signatures
AOT_EXPORTS = {
    "gearbox_step": "Tuple((i8, f8, f8, f8))(f8[::1], i8[::1], i8[::1], f8, f8, f8, f8, f8, f8, f8, f8, f8)",
    "outputs": "void(f8[::1], i8[::1], i8[::1])",
    "current_loads": "void(f8[::1], i8[::1], i8[::1])",
    "settle": "Tuple((i8, i8, f8))(f8[::1], i8[::1], i8[::1], f8, f8, i8)",
}
