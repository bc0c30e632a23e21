"""The gearbox stepped by the compiled kernel: one flat buffer holds its constants, work arrays and state.

:class:`CompiledGearboxModel` is the :class:`~components.model.gearbox_model.GearboxModel`
that :mod:`components.model.kernel` picks when numba imports. It keeps the
numpy model's interface, outputs and state format (a state taken from one can be
restored in the other); only :meth:`~CompiledGearboxModel.step` and
:meth:`~CompiledGearboxModel.output_vector` run in
:func:`components.model.compiled_kernel.gearbox_step`.

Every constant the kernel uses is read from the
:class:`~components.model.assembly.Assembly` (its folded ``_fast_matrix``, ``A``,
``BT``, shaft matrices, inverse inertias, the :class:`~components.model.contact.ContactLaw`
and :class:`~components.model.mesh_stiffness.MeshPhasing` constants) and from the
numpy model (its output matrix), so no equation is written twice outside
:mod:`components.model.compiled_kernel`. The arrays live in one float buffer
(with an offset table) because numba types every argument of every call: one
buffer costs 0.4 us per call, the ~50 separate arrays several microseconds.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError, SolverError
from .assembly import Assembly
from .gearbox_model import GearboxModel, non_finite_input
from .kernel import compiled_module


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
    return np.vstack([ph._cycles_per_rad, ph._cycle0, ph._half_p, ph._inv_w, ph._v, ph._vp, ph._slope_scale])


def mesh_sparsity(assembly: Assembly) -> tuple[np.ndarray, np.ndarray]:
    """Nonzero columns of every mesh row of ``A`` (free bodies) and their entries, padded with -1 / 0.

    Returns
    -------
    index, value : ndarray, shape (n_mesh, width)
        ``width`` is the largest number of free bodies one mesh touches (at least 1).
    """
    rows = [np.flatnonzero(row) for row in assembly.A]
    width = max([1] + [r.size for r in rows])
    index = np.full((assembly.n_mesh, width), -1.0)
    value = np.zeros((assembly.n_mesh, width))
    for i, cols in enumerate(rows):
        index[i, : cols.size] = cols
        value[i, : cols.size] = assembly.A[i, cols]
    return index, value


def slot_shapes(n: int, m: int, n_shaft: int, module, width: int = 3,
                n_speeds: int | None = None) -> dict[str, tuple[int, ...]]:
    """Shape of every slot of the buffer for ``n`` degrees of freedom and ``m`` meshes.

    ``n_speeds``: the body speeds among the outputs (default ``n``; the inertia interface's generator is not one).
    """
    n2 = 2 * n
    n_linear = 3 + m + n_shaft + (n if n_speeds is None else n_speeds)
    shapes = {
        "a_t": (n, m), "a_port": (m,), "fast": (m + n2 + 3, n), "contact": (m, module.N_CONTACT_COLUMNS),
        "force_w": (m,), "defl_w": (2, m), "acc_w": (n,), "bt": (n, m), "stks": (n, n), "stcs": (n, n),
        "stks_port": (n,), "stcs_port": (n,), "inv_m": (n,), "fd_w": (m,), "fv_w": (m,), "phasing": (7, m),
        "kappa": (n,), "force_rows": (m, n), "factor_w": (m,), "slope_w": (m,), "sens_w": (m,),
        **{name: (n2,) for name in ("f0", "f1", "fn", "k1", "k2", "k3", "y1", "yn", "rhs", "w_hdt")},
        "da": (n,), "nz_index": (m, width), "nz_value": (m, width), "cos_alpha": (m,), "control": (8,),
        "istate": (module.N_ISTATE,), "dq": (n, n), "dv": (n, n),
        "winv": (2, n2, n2), "w_basis": (2, n2, 3),  # the active W^-1 and the one kept (istate[ACTIVE])
        "port_jac": (2, n), "last_acc": (n,), "last_force": (m,), "last_defl": (2, m),
        "y": (n2,), "driver": (4,), "port": (4,), "scalars": (len(module.SCALAR_NAMES),), "twist_q": (n2,),
        "output_matrix": (m + n2 + 4, n_linear), "outputs": (n_linear + 4,), "anchor": (n + 1,),
    }
    state = module.SLOTS[module.STATE_FIRST:module.STATE_LAST + 1]
    shapes["backup"] = (sum(int(np.prod(shapes[name])) for name in state),)
    return shapes


class KernelBuffer:
    """One float64 buffer with a view per slot of :data:`components.model.compiled_kernel.SLOTS`.

    Attributes
    ----------
    buffer : ndarray
    offsets : ndarray of int64
        Start of slot ``i`` at ``offsets[i]``, its end at ``offsets[i + 1]``.
    views : dict of str -> ndarray
        Views of the slots with their shapes (writing into them writes into the buffer).
    """

    def __init__(self, shapes: dict[str, tuple[int, ...]], slots: tuple[str, ...]) -> None:
        sizes = [int(np.prod(shapes[name])) for name in slots]
        self.offsets = np.concatenate(([0], np.cumsum(sizes))).astype(np.int64)
        self.buffer = np.zeros(int(self.offsets[-1]))
        self.views = {
            name: self.buffer[self.offsets[i]: self.offsets[i + 1]].reshape(shapes[name]) for i, name in enumerate(slots)
        }


def _buffer_scalar(index: int, doc: str) -> property:
    def get(self) -> float:
        return float(self._scalars[index])

    def set(self, value: float) -> None:
        self._scalars[index] = value

    return property(get, set, doc=doc)


class CompiledGearboxModel(GearboxModel):
    """:class:`~components.model.gearbox_model.GearboxModel` stepped by the compiled kernel.

    Built by ``GearboxModel(...)`` when the kernel resolves to ``compiled``; same
    parameters, interface, outputs and state.
    """

    def _allocate(self) -> None:
        module, reason = compiled_module()
        if module is None:
            raise ParameterError("kernel", "compiled", f"an importable numba ({reason})")
        self._module = module
        module.ensure_compiled()
        a = self.assembly
        self._sparsity = mesh_sparsity(a)
        shapes = slot_shapes(a.n_dof, a.n_mesh, a.n_shaft, module, self._sparsity[0].shape[1], len(self.gearbox_dofs))
        self._kb = KernelBuffer(shapes, module.SLOTS)
        v = self._kb.views
        self._scalars = v["scalars"]
        self._istate = v["istate"]
        self._y_view = v["y"]
        self._outputs_view = v["outputs"]
        self._dims = np.zeros(module.N_DIMS, dtype=np.int64)
        self._kernel_step = module.step_entry_point()
        self._compiled_stale = True

    def _finish_allocation(self) -> None:
        mod = self._module
        a = self.assembly
        v = self._kb.views
        v["a_t"][:] = a._A_T
        v["a_port"][:] = a.port_deflection
        v["fast"][:] = a._fast_matrix
        v["contact"][:] = contact_table(a, mod)
        v["bt"][:] = a.BT
        v["nz_index"][:], v["nz_value"][:] = self._sparsity
        v["cos_alpha"][:] = a.cos_alpha
        v["stks"][:] = a.STkS
        v["stcs"][:] = a.STcS
        v["stks_port"][:] = a.STkS_port[:, 0] if a.ports.size else 0.0
        v["stcs_port"][:] = a.STcS_port[:, 0] if a.ports.size else 0.0
        v["inv_m"][:] = a.inv_inertia
        v["phasing"][:] = phasing_table(a)
        v["kappa"][:] = a.kinematic_ratio
        v["force_rows"][:] = a._force_rows
        v["factor_w"][:] = 1.0
        c = self._integrator.control
        v["control"][:] = (c.rtol, c.atol_q, c.atol_v, c.h_min, float(c.max_steps), float(c.jacobian_max_age),
                           self._out_kinematic, float(self._out_rate_index))
        v["twist_q"][:] = self._twist_q
        v["output_matrix"][:] = self._output_matrix
        sc = self._scalars
        sc[mod.S_KX] = self._kx
        sc[mod.S_TWIST_PORT] = self._twist_port
        sc[mod.S_SHAFT_K] = a.shaft_k[-1]
        sc[mod.S_SHAFT_C] = a.shaft_c[-1]
        law = a.law
        dims = self._dims
        dims[mod.D_N] = a.n_dof
        dims[mod.D_M] = a.n_mesh
        dims[mod.D_TVS] = int(a.time_varying_stiffness)
        dims[mod.D_SQRT_CFS] = int(law._sqrt_law and not law._any_impact)
        dims[mod.D_EXTRAPOLATE] = int(self.extrapolate)
        dims[mod.D_END_TORQUE] = int(self.shaft_torque_mode == "end")
        dims[mod.D_GEN_DOF] = -1 if self.generator_dof is None else self.generator_dof
        dims[mod.D_ROTOR_DERIVATIVES] = int(self.rotor_derivatives)

    # the numpy model's scalar state lives in the buffer
    time_s = _buffer_scalar(0, "Current time [s].")
    driver_angle_rad = _buffer_scalar(1, "Driver (rotor) angle [rad].")
    driver_speed_rad_s = _buffer_scalar(2, "Driver speed [rad/s].")
    driver_accel_rad_s2 = _buffer_scalar(3, "Driver acceleration [rad/s^2].")
    port_angle_rad = _buffer_scalar(4, "Generator-port deviation angle [rad].")
    port_speed_rad_s = _buffer_scalar(5, "Generator-port deviation speed [rad/s].")
    last_step_s = _buffer_scalar(6, "Last communication step [s].")
    last_omega_rotor = _buffer_scalar(7, "Rotor speed input of the last step [rad/s].")
    last_omega_gen = _buffer_scalar(8, "Generator speed input of the last step [rad/s].")
    shaft_torque_average_nm = _buffer_scalar(9, "Shaft-3 torque averaged over the last step [N m].")
    output_twist_rad = _buffer_scalar(10, "Twist of the output shaft [rad].")
    alpha_out_average_rad_s2 = _buffer_scalar(11, "Output-member acceleration averaged over the last step [rad/s^2].")

    @property
    def alpha_out_max_rad_s2(self) -> float:
        """Eq. 11: largest |d omega_out / dt| over every accepted internal step [rad/s^2]."""
        return float(self._istate[self._module.ALPHA_OUT_MAX])

    @alpha_out_max_rad_s2.setter
    def alpha_out_max_rad_s2(self, value: float) -> None:
        self._istate[self._module.ALPHA_OUT_MAX] = value

    @property
    def output_acceleration_rad_s2(self) -> float:
        """Angular acceleration of the last stage's output member at the current time [rad/s^2]."""
        if self._compiled_stale:
            return super().output_acceleration_rad_s2
        alpha = self._scalars[self._module.S_LAST_ALPHA]
        return float(self._out_kinematic * alpha + self._kb.views["last_acc"][self._out_member])

    @property
    def y(self) -> np.ndarray:
        """State ``[q, v]`` (a view of the buffer)."""
        return self._y_view

    @y.setter
    def y(self, value: np.ndarray) -> None:
        self._y_view[:] = value

    # ------------------------------------------------------------ sync with the numpy side
    def _load_compiled(self) -> None:
        """Copy the numpy-side state (integrator, cached loads) into the buffer; the buffer holds it from now on."""
        mod = self._module
        v = self._kb.views
        it = self._integrator
        sysm = self.system
        ist = self._istate
        ist[mod.H_NEXT] = it.h_next
        ist[mod.ACCEPTED] = it.accepted
        ist[mod.REJECTED] = it.rejected
        ist[mod.JACOBIANS] = it.jacobians
        ist[mod.AGE] = it._age
        ist[mod.HD] = it._hd
        ist[mod.BASIS_VALID] = 0.0
        ist[mod.ACTIVE] = 0.0
        ist[mod.HD_PREV] = -1.0  # the numpy side's kept factorisation is not carried over: formed again if needed
        ist[mod.BASIS_PREV_VALID] = 0.0
        v["dq"][:] = it._dq
        v["dv"][:] = it._dv
        v["winv"][0] = it._winv
        v["last_acc"][:] = sysm.last_acceleration
        v["last_force"][:] = sysm.last_force
        v["last_defl"][:] = sysm.last_deflection
        v["port_jac"][:] = sysm.port_jacobian
        self._scalars[mod.S_LAST_ALPHA] = sysm.last_alpha
        self._scalars[mod.S_ANGLE0] = sysm.angle0
        sysm.last_acceleration, sysm.last_force = v["last_acc"], v["last_force"]
        sysm.last_deflection, sysm.port_jacobian = v["last_defl"], v["port_jac"]
        mod.outputs(self._kb.buffer, self._kb.offsets, self._dims)
        self._compiled_stale = False

    def _store_compiled(self) -> None:
        """Hand the buffer's state back to the numpy side (reloaded before the next step)."""
        if self._compiled_stale:
            return
        mod = self._module
        v = self._kb.views
        it = self._integrator
        sysm = self.system
        ist = self._istate
        it.h_next = float(ist[mod.H_NEXT])
        it.accepted = int(ist[mod.ACCEPTED])
        it.rejected = int(ist[mod.REJECTED])
        it.jacobians = int(ist[mod.JACOBIANS])
        it._age = int(ist[mod.AGE])
        it._hd = float(ist[mod.HD])
        it._dq = v["dq"].copy()
        it._dv = v["dv"].copy()
        it._winv = v["winv"][int(ist[mod.ACTIVE])].copy()
        it._winv_v = np.ascontiguousarray(it._winv[:, self.assembly.n_dof:])
        it._w_basis = None
        it._previous = None  # the kept factorisation stays in the buffer (formed again if the numpy side steps)
        sysm.last_acceleration = v["last_acc"].copy()
        sysm.last_force = v["last_force"].copy()
        sysm.last_deflection = v["last_defl"].copy()
        sysm.port_jacobian = v["port_jac"].copy()
        sysm.last_alpha = float(self._scalars[mod.S_LAST_ALPHA])
        sysm.angle0 = float(self._scalars[mod.S_ANGLE0])
        self._compiled_stale = True

    # ------------------------------------------------------------ stepping
    def step(self, t: float, h: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
             counter_torque_nm: float = 0.0, alpha_rotor: float = 0.0, jerk_rotor: float = 0.0) -> None:
        """Advance from ``t`` to ``t + h`` [s] (as :meth:`GearboxModel.step`, in the compiled kernel).

        Hot path (every communication step): one check, one call of the kernel's compiled entry
        point (:func:`~components.model.compiled_kernel.step_entry_point`), one status test. An
        uninitialised model is always stale (:meth:`initialize` and :meth:`set_state` hand the state
        to the numpy side), so the first test covers both.
        """
        if self._compiled_stale:
            if not self.initialized:
                self.initialize(t, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm)
            if not h > 0.0:
                raise ParameterError("step_size", h, "> 0")
            self._load_compiled()
        elif not h > 0.0:
            raise ParameterError("step_size", h, "> 0")
        kb = self._kb
        status, tau, h_fail, err = self._kernel_step(kb.buffer, kb.offsets, self._dims, t, h, omega_rotor, phi_rotor,
                                                     omega_gen, phi_gen, counter_torque_nm, alpha_rotor, jerk_rotor)
        if status:  # OK is 0
            self._step_failed(status, t, tau, h_fail, err, (omega_rotor, phi_rotor, omega_gen, phi_gen,
                                                            counter_torque_nm, alpha_rotor, jerk_rotor))

    def _step_failed(self, status: int, t: float, tau: float, h_fail: float, err: float, inputs: tuple) -> None:
        """Raise the SolverError of a failed kernel step (the buffer is as it was at ``t``)."""
        mod = self._module
        if status != mod.OK:
            c = self._integrator.control
            if status == mod.NON_FINITE_INPUT:
                raise SolverError(non_finite_input(inputs), t)
            if status == mod.STEP_TOO_SMALL:
                message = f"step size {h_fail:.3g} s below h_min {c.h_min:.3g} s (error norm {err:.3g})"
            else:
                message = f"more than {c.max_steps} steps in one advance"
            raise SolverError(message, t + tau)

    def output_vector(self) -> np.ndarray:
        """Every output at the current time, ordered as :attr:`output_names` (computed by the kernel's step)."""
        if self._compiled_stale:
            return super().output_vector()
        return self._outputs_view.copy()

    def _output_array(self) -> np.ndarray:
        return super().output_vector() if self._compiled_stale else self._outputs_view

