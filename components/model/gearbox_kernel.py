"""The compiled kernel's view of a gearbox: constant arrays from the Assembly, work arrays, state arrays.

:class:`GearboxKernel` is built once per :class:`~components.model.gearbox_model.GearboxModel`.
Every constant the kernel uses is read from the
:class:`~components.model.assembly.Assembly` (its folded ``_fast_matrix``, ``A``,
``BT``, shaft matrices, inverse inertias, the contact-law constants of
:class:`~components.model.contact.ContactLaw` and the phasing constants of
:class:`~components.model.mesh_stiffness.MeshPhasing`), so no equation is written
twice outside :mod:`components.model.compiled_kernel`.
"""

from __future__ import annotations

import numpy as np

from .assembly import Assembly
from .integrators import StepControl


def contact_table(assembly: Assembly, module) -> np.ndarray:
    """Per-mesh contact constants, shape (n_mesh, N_CONTACT_COLUMNS) in the kernel's column order."""
    law = assembly.law
    table = np.zeros((assembly.n_mesh, module.N_CONTACT_COLUMNS))
    table[:, module.K0] = law._k
    table[:, module.EXPONENT] = law._e
    table[:, module.DAMPING] = law._c
    table[:, module.LAMBDA] = law._lam
    table[:, module.HALF_JT] = law._half_jt
    table[:, module.IMPACT] = law._impact.astype(float)
    table[:, module.DMAX] = law._dmax
    table[:, module.CMAX] = law._cmax
    table[:, module.DEEP] = law._deep
    return table


def phasing_table(assembly: Assembly) -> np.ndarray:
    """MeshPhasing constants (rows: cycles/rad, cycle0, p/2, 1/w, v, v p, slope scale), shape (7, n_mesh)."""
    ph = assembly.phasing
    if ph is None:
        return np.zeros((7, assembly.n_mesh))
    return np.ascontiguousarray(
        np.vstack([ph._cycles_per_rad, ph._cycle0, ph._half_p, ph._inv_w, ph._v, ph._vp, ph._slope_scale]).astype(float)
    )


def _c(a) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=float))


class GearboxKernel:
    """Arrays of one gearbox for :func:`components.model.compiled_kernel.advance`.

    Parameters
    ----------
    assembly : Assembly
        Cut at the generator (exactly one port).
    control : StepControl
        Integrator tolerances.
    output_kinematic_ratio : float
        Kinematic ratio of the output member (eq. 11 tracking).
    output_rate_index : int
        Index of the output member's speed in ``[q, v]``.
    module : module
        :mod:`components.model.compiled_kernel`.
    """

    def __init__(self, assembly: Assembly, control: StepControl, output_kinematic_ratio: float,
                 output_rate_index: int, module) -> None:
        a = assembly
        n, m = a.n_dof, a.n_mesh
        self.module = module
        port_a = a.A_port[:, 0] if a.ports.size else np.zeros(m)
        law = a.law
        self.consts = (
            _c(a._A_T),  # 0
            _c(port_a),  # 1
            _c(a._fast_matrix),  # 2
            _c(contact_table(a, module)),  # 3
            np.zeros(m),  # 4 force work
            np.zeros((2, m)),  # 5 deflection work
            np.zeros(n),  # 6 acceleration work
            _c(a.BT),  # 7
            _c(a.STkS),  # 8
            _c(a.STcS),  # 9
            _c(a.STkS_port[:, 0] if a.ports.size else np.zeros(n)),  # 10
            _c(a.STcS_port[:, 0] if a.ports.size else np.zeros(n)),  # 11
            _c(a.inv_inertia),  # 12
            np.zeros(m),  # 13 dF/dd work
            np.zeros(m),  # 14 dF/dv work
            bool(a.time_varying_stiffness),  # 15
            phasing_table(a),  # 16
            _c(a.kinematic_ratio),  # 17
            _c(a._force_rows),  # 18
            bool(law._sqrt_law and not law._any_impact),  # 19
            np.ones(m),  # 20 stiffness factor work
            np.zeros(m),  # 21 slope work
            np.zeros(m),  # 22 sensitivity work
            *(np.zeros(2 * n) for _ in range(10)),  # 23-32 f0 f1 fn k1 k2 k3 y1 yn rhs w_hdt
            np.zeros(n),  # 33 da
        )
        self.control = np.array([
            control.rtol, control.atol_q, control.atol_v, control.h_min, float(control.max_steps),
            float(control.jacobian_max_age), float(output_kinematic_ratio), float(output_rate_index),
        ])
        self.istate = np.zeros(module.N_ISTATE)
        self.dq = np.zeros((n, n))
        self.dv = np.zeros((n, n))
        self.winv = np.zeros((2 * n, 2 * n))
        self.w_basis = np.zeros((2 * n, 3))
        self.port_jac = np.zeros((2, n))
        self.last_acc = np.zeros(n)
        self.last_force = np.zeros(m)
        self.last_defl = np.zeros((2, m))
        self.driver = np.zeros(4)
        self.port = np.zeros(4)
        self.backup = (np.zeros(2 * n), np.zeros(module.N_ISTATE), np.zeros((n, n)), np.zeros((n, n)),
                       np.zeros((2 * n, 2 * n)), np.zeros((2 * n, 3)), np.zeros((2, n)), np.zeros(n), np.zeros(m),
                       np.zeros((2, m)))

    def load_integrator(self, integrator) -> None:
        """Copy a :class:`~components.model.integrators.Rosenbrock23`'s state into the kernel arrays."""
        mod = self.module
        ist = self.istate
        ist[mod.H_NEXT] = integrator.h_next
        ist[mod.ACCEPTED] = integrator.accepted
        ist[mod.REJECTED] = integrator.rejected
        ist[mod.JACOBIANS] = integrator.jacobians
        ist[mod.AGE] = integrator._age
        ist[mod.HD] = integrator._hd
        ist[mod.BASIS_VALID] = 0.0
        self.dq[:] = integrator._dq
        self.dv[:] = integrator._dv
        self.winv[:] = integrator._winv

    def store_integrator(self, integrator) -> None:
        """Copy the kernel's integrator state back into a :class:`~components.model.integrators.Rosenbrock23`."""
        mod = self.module
        ist = self.istate
        integrator.h_next = float(ist[mod.H_NEXT])
        integrator.accepted = int(ist[mod.ACCEPTED])
        integrator.rejected = int(ist[mod.REJECTED])
        integrator.jacobians = int(ist[mod.JACOBIANS])
        integrator._age = int(ist[mod.AGE])
        integrator._hd = float(ist[mod.HD])
        integrator._dq = self.dq.copy()
        integrator._dv = self.dv.copy()
        integrator._winv = self.winv.copy()
        integrator._winv_v = np.ascontiguousarray(integrator._winv[:, self.dq.shape[0]:])
        integrator._w_basis = None
