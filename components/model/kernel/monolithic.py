"""The monolithic drivetrain (no co-simulation cut) and the loads of many states, for the reference and the analyses.

:func:`monolithic_rhs` and :func:`monolithic_jacobian` are the right-hand side and Jacobian of
the monolithic ODE that :class:`components.reference.solver.MonolithicSystem` integrates with
LSODA: the same equations (:mod:`.dynamics`) as the co-simulation gearbox, with the generator a
degree of freedom braked by the counter torque, plus three quadratures for the energy balance
(rotor power, output power, dissipated power). :func:`contact_forces_many` and
:func:`stiffness_factors_many` evaluate the contact law and the mesh stiffness over many states
(recorded trajectories, quadrature points), and :func:`.statics.static_deflection` the static
equilibrium of the reference and the analyses. This entry module is run compiled by numba (just
in time) or interpreted.
"""

from __future__ import annotations

from .contact import contact_force, mesh_forces, regularised
from .dynamics import deflections, external_terms, jacobian
from .linalg import copy, vecmat
from .statics import static_deflection  # noqa: F401 - an entry of this module (Assembly.static_deflection)
from .stiffness import stiffness_factors


def monolithic_rhs(y, omega, alpha, angle, factor, load, out_dof, kappa_out, inertia_in, nz_index, nz_value, a_port,
                   offset, fast, contact, load_rates, s_mat, shaft_k, shaft_c, bt_driver, s_driver, cos_alpha, inv_m, force, elastic,
                   defl, z, acc, out):
    """``[v, q_ddot, rotor power, output power, dissipated power]`` into ``out``.

    The accelerations through the folded matrix (no port; the external loads at the driver angle
    ``angle`` and speed ``omega``), the counter torque ``load`` [N m] on the output body, the rotor
    torque ``I_in alpha + cos(alpha) a_in . F + s_in . T`` (``s_mat`` ... ``s_driver``: every spring
    row, shafts and bearings), and the dissipation ``((F - F_el) d_dot) . cos(alpha) + sum c s_dot^2``.
    """
    n = inv_m.shape[0]
    m = force.shape[0]
    n2 = 2 * n
    deflections(y, n, nz_index, nz_value, a_port, offset, 0.0, 0.0, defl)
    mesh_forces(defl, factor, contact, force, elastic)
    copy(force, z[:m])
    copy(y[:n2], z[m:m + n2])
    z[m + n2] = 0.0
    z[m + n2 + 1] = 0.0
    z[m + n2 + 2] = alpha
    external_terms(angle, omega, load_rates, z[m + n2 + 3:fast.shape[0]])
    vecmat(z[:fast.shape[0]], fast, acc)
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
    copy(y[n:n2], out[:n])
    copy(acc, out[n:n2])
    out[n2] = rotor * omega
    out[n2 + 1] = load * (kappa_out * omega + y[n + out_dof])
    out[n2 + 2] = dissipation


def monolithic_jacobian(y, factor, a_port, offset, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs,
                        stks_port, stcs_port, inv_m, fd, fv, dq, dv, port_jac, jac):
    """The acceleration rows of the monolithic Jacobian ``jac`` (the rest is fixed)."""
    n = inv_m.shape[0]
    jacobian(y, 0.0, 0.0, factor, a_port, offset, contact, defl, nz_index, nz_value, cos_alpha, stks, stcs,
             stks_port, stcs_port, inv_m, fd, fv, dq, dv, port_jac)
    jac[n:2 * n, :n] = dq
    jac[n:2 * n, n:2 * n] = dv


def contact_forces_many(d, rate, factor, contact, force, d_force_d_deflection, d_force_d_rate, elastic):
    """The contact law at many states: every argument but ``contact`` of shape (N, n_mesh) (``factor`` too)."""
    for s in range(d.shape[0]):
        for i in range(d.shape[1]):
            f, fd, fv, el = contact_force(d[s, i], rate[s, i], factor[s, i], contact[i])
            force[s, i] = f
            d_force_d_deflection[s, i] = fd
            d_force_d_rate[s, i] = fv
            elastic[s, i] = el


def stiffness_factors_many(angles, phasing, factor, slope):
    """Mesh stiffness multipliers and slopes at many driver angles: ``factor``, ``slope`` of shape (N, n_mesh)."""
    stiffness_factors(angles[:, None], phasing, factor, slope)  # the numpy form, at every angle at once


def _stiffness_factors_many_loop(angles, phasing, factor, slope):
    for s in range(angles.shape[0]):
        stiffness_factors(angles[s], phasing, factor[s], slope[s])


def regularised_many(d, contact, d_bl, d_bl_prime, d_bl_second):
    """The regularised indentation of eq. 3-4 and its two derivatives at many deflections (shape (N, n_mesh))."""
    for s in range(d.shape[0]):
        for i in range(d.shape[1]):
            a, b, c = regularised(d[s, i], contact[i])
            d_bl[s, i] = a
            d_bl_prime[s, i] = b
            d_bl_second[s, i] = c


#: the loop numba compiles in place of the numpy form (see :mod:`components.compile.jit`)
COMPILED = {"stiffness_factors_many": _stiffness_factors_many_loop}
