"""Assembly of a drivetrain into matrices: bodies, mesh rows and shaft rows.

Coordinates
-----------
Every body has an absolute rotation angle (planets too: relative coordinates
would make the mass matrix non-diagonal). The stage-1 input member is driven
kinematically with angle ``theta_in(t)``; with ``cut_at_generator=True`` the
generator is a second prescribed *port* whose motion comes from outside (the
co-simulation cut). Each deflection is linear in the angles,

    d = A theta,    shaft twist  s = S theta,

with, for a planetary stage (pitch radii, ring fixed; eq. 8 and 10 in
absolute angles, signed so that normal power flow compresses positively)

    d_sp,i = -r_s (th_s - th_c) - r_p (th_p,i - th_c)
    d_rp,i =  r_p (th_p,i - th_c) + r_r th_c

and for a parallel stage (external mesh; the driven gear's angle is counted
positive in *its* direction of normal rotation, opposite to the drive gear)

    d = r_1 th_1 - r_2 th_2.

The state is integrated in *deviation coordinates* ``q = theta - kappa
theta_in`` where ``kappa`` are the kinematic speed ratios (``A kappa = 0``,
``S kappa = 0``). Deflections and twists depend on ``q`` only, the state stays
bounded over long runs, and the equations of motion read

    M (q_ddot + kappa alpha_in) = -cos(alpha) A^T F(d, d_dot) - S^T T(s, s_dot) + tau_ext

where ``alpha_in`` is the driver acceleration and the moment arm of a mesh force
is the base radius ``r cos(alpha)`` (eq. 5-7). The Jacobian is assembled
analytically from the same matrices: ``dQ/dq = -cos(alpha) A^T diag(dF/dd) A -
S^T diag(k) S``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SolverError
from . import kernel as model_kernel
from .contact import ContactLaw, MeshContact
from .drivetrain import Drivetrain
from .kernel.stiffness import N_PHASING_ROWS
from .mesh_stiffness import MeshPhasing
from .stages import PlanetaryStage


@dataclass(frozen=True)
class Body:
    """A rigid rotating body.

    Attributes
    ----------
    name : str
        e.g. ``"stage1.planet[2]"``, ``"generator"``.
    inertia_kgm2 : float
        Polar inertia [kg m^2] (a carrier includes the planets' orbital inertia).
    stage : str
        Stage name, or ``"generator"``.
    role : str
        ``carrier``, ``sun``, ``planet``, ``drive``, ``driven`` or ``generator``.
    """

    name: str
    inertia_kgm2: float
    stage: str
    role: str


@dataclass(frozen=True)
class Mesh:
    """A gear mesh of the assembly.

    Attributes
    ----------
    name : str
        Force name as in the FMU interface, e.g. ``"stage1.F_sp[1]"``, ``"stage3.F_mesh"``.
    stage : str
        Stage name.
    kind : str
        ``sun_planet``, ``ring_planet`` or ``parallel``.
    contact : MeshContact
        Contact parameters.
    teeth_per_driver_rad : float
        Mesh-cycle phase advance per radian of driver (rotor) rotation [rad/rad], i.e.
        tooth pairs passing per rotor *revolution*: mesh frequency [Hz] = this x rotor
        speed [rad/s] / (2 pi). ``Z_ring kappa_carrier`` (planetary, ring fixed),
        ``Z_drive kappa_drive`` (parallel).
    phase_offset_rad : float
        Mesh-cycle phase of this mesh at theta_in = 0 [rad] (sequential planet phasing:
        ``-Z_sun psi_i`` sun-planet, ``+Z_ring psi_i`` ring-planet, planet i at carrier
        angle ``psi_i``; see :mod:`components.model.mesh_stiffness`).
    """

    name: str
    stage: str
    kind: str
    contact: MeshContact
    teeth_per_driver_rad: float
    phase_offset_rad: float


@dataclass(frozen=True)
class ShaftElement:
    """A shaft of the assembly: ``T = k (th_a - th_b) + c (om_a - om_b)``.

    Attributes
    ----------
    name : str
        e.g. ``"shaft1"``.
    upstream, downstream : str
        Body names (``upstream`` is on the rotor side).
    stiffness_nm_per_rad, damping_nms_per_rad : float
        Torsional stiffness [N m/rad] and damping [N m s/rad].
    """

    name: str
    upstream: str
    downstream: str
    stiffness_nm_per_rad: float
    damping_nms_per_rad: float


@dataclass(frozen=True)
class InternalLoads:
    """Mesh and shaft loads at one or many states; arrays shaped ``(..., n_mesh)`` / ``(..., n_shaft)``.

    ``d_force_d_deflection`` and ``d_force_d_rate`` are None when the loads were
    evaluated without derivatives (``Assembly.loads(..., derivatives=False)``).
    """

    deflection_m: np.ndarray
    deflection_rate_m_s: np.ndarray
    contact_force_n: np.ndarray
    d_force_d_deflection: np.ndarray
    d_force_d_rate: np.ndarray
    elastic_force_n: np.ndarray
    shaft_twist_rad: np.ndarray
    shaft_twist_rate_rad_s: np.ndarray
    shaft_torque_nm: np.ndarray


class Assembly:
    """The matrices of a drivetrain (the kernel's constants) and their evaluation over arrays of states.

    Parameters
    ----------
    drivetrain : Drivetrain
        Topology and parameters.
    cut_at_generator : bool
        If True the generator is not a degree of freedom but a prescribed port
        (the gearbox side of the co-simulation cut: shaft 3 stays in the gearbox).

    Attributes
    ----------
    bodies : list of Body
        All bodies; ``free`` indexes the degrees of freedom.
    meshes : list of Mesh
    shafts : list of ShaftElement
    n_dof : int
        Number of degrees of freedom.
    inertia_kgm2 : ndarray, shape (n_dof,)
    kinematic_ratio : ndarray, shape (n_dof,)
        kappa: speed of each free body per unit driver speed.
    """

    def __init__(self, drivetrain: Drivetrain, cut_at_generator: bool = False) -> None:
        if not isinstance(drivetrain, Drivetrain):
            raise ParameterError("drivetrain", drivetrain, "a Drivetrain")
        if cut_at_generator and drivetrain.generator is None:
            raise ParameterError("cut_at_generator", True, "a drivetrain with a generator to cut at")
        self.drivetrain = drivetrain
        self.cut_at_generator = cut_at_generator
        bodies: list[Body] = []
        mesh_rows: list[dict[int, float]] = []
        meshes: list[tuple[str, str, str, MeshContact, int, float, float]] = []
        shaft_rows: list[tuple[int, int]] = []
        shafts: list[ShaftElement] = []

        def body(name: str, inertia: float, stage: str, role: str) -> int:
            bodies.append(Body(name, float(inertia), stage, role))
            return len(bodies) - 1

        def shaft(sh, a: int, b: int) -> None:
            shaft_rows.append((a, b))
            shafts.append(ShaftElement(sh.name, bodies[a].name, bodies[b].name, sh.stiffness_nm_per_rad, sh.damping_nms_per_rad))

        previous_output = -1
        stage_members: dict[str, dict[str, int]] = {}
        for k, st in enumerate(drivetrain.stages):
            n = st.name
            if isinstance(st, PlanetaryStage):
                r_s, r_p, r_r = st.sun_radius_m, st.planet_radius_m, st.ring_radius_m
                c = body(f"{n}.carrier", st.carrier_total_inertia_kgm2, n, "carrier")
                s = body(f"{n}.sun", st.sun_inertia_kgm2, n, "sun")
                planets = [body(f"{n}.planet[{i + 1}]", st.planet_inertia_kgm2, n, "planet") for i in range(st.n_planets)]
                z_s = 2.0 * r_s / st.module_m
                z_r = 2.0 * r_r / st.module_m
                positions = st.planet_positions_rad  # psi_i: given, or equally spaced
                for i, p in enumerate(planets):  # eq. 8
                    psi = positions[i]
                    mesh_rows.append({s: -r_s, p: -r_p, c: r_s + r_p})
                    meshes.append((f"{n}.F_sp[{i + 1}]", n, "sun_planet", st.sun_mesh, c, z_r, -z_s * psi))
                for i, p in enumerate(planets):  # eq. 10, ring fixed
                    psi = positions[i]
                    mesh_rows.append({p: r_p, c: r_r - r_p})
                    meshes.append((f"{n}.F_rp[{i + 1}]", n, "ring_planet", st.ring_mesh, c, z_r, z_r * psi))
                members = {"input": c, "output": s}
            else:
                d1 = body(f"{n}.drive", st.drive_inertia_kgm2, n, "drive")
                d2 = body(f"{n}.driven", st.driven_inertia_kgm2, n, "driven")
                mesh_rows.append({d1: st.drive_radius_m, d2: -st.driven_radius_m})
                meshes.append((f"{n}.F_mesh", n, "parallel", st.mesh, d1, st.drive_teeth, 0.0))
                members = {"input": d1, "output": d2}
            stage_members[n] = members
            if k > 0:
                shaft(drivetrain.shafts[k - 1], previous_output, members["input"])
            previous_output = members["output"]
        generator_index = None
        if drivetrain.generator is not None:
            generator_index = body("generator", drivetrain.generator.inertia_kgm2, "generator", "generator")
            shaft(drivetrain.output_shaft, previous_output, generator_index)
        output_index = generator_index if generator_index is not None else previous_output

        nb = len(bodies)
        A = np.zeros((len(mesh_rows), nb))
        for i, row in enumerate(mesh_rows):
            for j, coef in row.items():
                A[i, j] = coef
        S = np.zeros((len(shaft_rows), nb))
        for i, (a, b) in enumerate(shaft_rows):
            S[i, a] = 1.0
            S[i, b] = -1.0

        driver = 0
        ports = [generator_index] if cut_at_generator else []
        free = [j for j in range(nb) if j != driver and j not in ports]

        # kinematic ratios: [A; S] kappa = 0 with kappa_driver = 1 (exact for consistent geometry)
        G = np.vstack([A, S])
        rest = [j for j in range(nb) if j != driver]
        kappa_rest, *_ = np.linalg.lstsq(G[:, rest], -G[:, driver], rcond=None)
        kappa_all = np.zeros(nb)
        kappa_all[driver] = 1.0
        kappa_all[rest] = kappa_rest
        residual = np.abs(G @ kappa_all).max() if G.size else 0.0
        if residual > 1e-9 * max(1.0, np.abs(kappa_all).max()):
            raise ParameterError("geometry", residual, "kinematically consistent stages (ring = sun + 2 planet)")

        self.bodies = bodies
        self.meshes = [
            Mesh(name, stage, kind, contact, float(teeth * kappa_all[ref]), float(off))
            for (name, stage, kind, contact, ref, teeth, off) in meshes
        ]
        self.shafts = shafts
        self.stage_members = {k: {r: bodies[i].name for r, i in v.items()} for k, v in stage_members.items()}
        self.free = np.array(free, dtype=int)
        self.ports = np.array(ports, dtype=int)
        self.driver = driver
        self.n_dof = len(free)
        self.n_mesh = len(mesh_rows)
        self.n_shaft = len(shaft_rows)
        self.kinematic_ratio_all = kappa_all
        self.kinematic_ratio = kappa_all[free]
        self.port_ratio = kappa_all[ports]
        self.inertia_all_kgm2 = np.array([b.inertia_kgm2 for b in bodies])
        self.inertia_kgm2 = self.inertia_all_kgm2[free]
        self.inv_inertia = 1.0 / self.inertia_kgm2
        self.driver_inertia_kgm2 = bodies[driver].inertia_kgm2
        self.law = ContactLaw([m.contact for m in self.meshes])
        self.cos_alpha = np.array([math.cos(m.contact.pressure_angle_rad) for m in self.meshes])
        self.A_all = A
        self.S_all = S
        self.A = np.ascontiguousarray(A[:, free])
        self.A_port = np.ascontiguousarray(A[:, ports])
        self.S = np.ascontiguousarray(S[:, free])
        self.S_port = np.ascontiguousarray(S[:, ports])
        self.a_driver = A[:, driver].copy()
        self.s_driver = S[:, driver].copy()
        self.BT = np.ascontiguousarray((self.cos_alpha[:, None] * self.A).T)  # (n_dof, n_mesh)
        self.BT_driver = self.cos_alpha * self.a_driver
        self.shaft_k = np.array([s.stiffness_nm_per_rad for s in shafts])
        self.shaft_c = np.array([s.damping_nms_per_rad for s in shafts])
        self.ST = np.ascontiguousarray(self.S.T)
        self.STkS = self.ST @ (self.shaft_k[:, None] * self.S)
        self.STcS = self.ST @ (self.shaft_c[:, None] * self.S)
        self.STkS_port = self.ST @ (self.shaft_k[:, None] * self.S_port)
        self.STcS_port = self.ST @ (self.shaft_c[:, None] * self.S_port)
        out_free = np.flatnonzero(self.free == output_index)
        self.output_dof = int(out_free[0]) if out_free.size else None  # None when the output is the port
        self.output_body = bodies[output_index].name
        self.time_varying_stiffness = any(m.contact.stiffness_variation > 0.0 for m in self.meshes)
        # matrices for the single-state fast path (mesh forces + shafts folded into constant matrices)
        self.A_T = np.ascontiguousarray(self.A.T)  # (n_dof, n_mesh)
        self._neg_B = np.ascontiguousarray(-(self.cos_alpha[:, None] * self.A))  # (n_mesh, n_dof)
        self._shaft_QY = np.ascontiguousarray(-np.vstack([self.STkS.T, self.STcS.T]))  # y = [q, v] -> shaft torques on dofs
        self._port_Q = -np.stack([self.STkS_port, self.STcS_port])  # (2, n_dof, n_port)
        if self.ports.size > 1:
            raise ParameterError("ports", self.ports.size, "at most one prescribed port")
        if self.ports.size:  # the port input u is the port's deviation angle, u_dot its speed
            port_q, port_v = self._port_Q[0][:, 0], self._port_Q[1][:, 0]
        else:  # u is the counter torque braking the output body (e.g. the generator) [N m]; u_dot unused
            port_q, port_v = np.zeros(self.n_dof), np.zeros(self.n_dof)
            if self.output_dof is not None:
                port_q[self.output_dof] = -1.0
        #: the port input's weights on the mesh deflections and shaft twists (zero without a port)
        self.port_deflection = self.A_port[:, 0].copy() if self.ports.size else np.zeros(self.n_mesh)
        self.port_twist = self.S_port[:, 0].copy() if self.ports.size else np.zeros(self.n_shaft)
        #: the folded matrix: q_ddot = [force, q, v, u, u_dot, alpha_in] @ fast_matrix (u, u_dot: the port input,
        #: see above); what the kernel (:func:`components.model.kernel.dynamics.acceleration`) evaluates
        self.fast_matrix = np.ascontiguousarray(
            np.vstack([self._neg_B, self._shaft_QY, port_q[None, :], port_v[None, :], -self.kinematic_ratio[None, :]])
            * np.append(self.inv_inertia[None, :].repeat(self._neg_B.shape[0] + 2 * self.n_dof + 2, 0), [np.ones(self.n_dof)], 0)
        )
        #: per mesh: mesh-cycle phase per driver radian [rad/rad], its offset [rad], stiffness variation, contact ratio
        self.mesh_phase_rate = np.array([m.teeth_per_driver_rad for m in self.meshes])
        self.mesh_phase_offset = np.array([m.phase_offset_rad for m in self.meshes])
        self.mesh_stiffness_variation = np.array([m.contact.stiffness_variation for m in self.meshes])
        self.mesh_contact_ratio = np.array([m.contact.contact_ratio for m in self.meshes])
        self.phasing = None
        if self.time_varying_stiffness:
            self.phasing = MeshPhasing(self.mesh_phase_rate, self.mesh_phase_offset, self.mesh_contact_ratio, self.mesh_stiffness_variation)
        #: the kernel's phasing table (zeros when the stiffness is constant), shape (7, n_mesh)
        self.phasing_table = self.phasing.table if self.phasing is not None else np.zeros((N_PHASING_ROWS, self.n_mesh))
        #: d q_ddot / d F, shape (n_mesh, n_dof): the force rows of the folded matrix
        self.force_rows = np.ascontiguousarray(self.fast_matrix[: self.n_mesh])
        self.nz_index, self.nz_value = self._mesh_sparsity()

    def _mesh_sparsity(self) -> tuple[np.ndarray, np.ndarray]:
        """Nonzero columns of every mesh row of ``A`` (free bodies) and their entries, padded with -1 / 0.

        Returns
        -------
        index, value : ndarray, shape (n_mesh, width)
            ``width`` is the largest number of free bodies one mesh touches (at least 1); the kernel's
            Jacobian sums over these only.
        """
        rows = [np.flatnonzero(row) for row in self.A]
        width = max([1] + [r.size for r in rows])
        index = np.full((self.n_mesh, width), -1.0)
        value = np.zeros((self.n_mesh, width))
        for i, cols in enumerate(rows):
            index[i, : cols.size] = cols
            value[i, : cols.size] = self.A[i, cols]
        return index, value

    # ------------------------------------------------------------------ names
    @property
    def dof_names(self) -> list[str]:
        """Names of the free bodies, in state order."""
        return [self.bodies[j].name for j in self.free]

    @property
    def mesh_names(self) -> list[str]:
        """Names of the mesh forces, in mesh order."""
        return [m.name for m in self.meshes]

    @property
    def shaft_names(self) -> list[str]:
        """Names of the shafts."""
        return [s.name for s in self.shafts]

    def dof_index(self, body_name: str) -> int:
        """Index of a free body in the state vector."""
        names = self.dof_names
        if body_name not in names:
            raise KeyError(f"{body_name!r} is not a degree of freedom; have {names}")
        return names.index(body_name)

    # ------------------------------------------------------------- stiffness
    def stiffness_factor(self, driver_angle_rad: float | np.ndarray) -> np.ndarray | float:
        """Time-varying mesh-stiffness multiplier at one driver angle (n_mesh,) or many (N, n_mesh); 1 when off.

        See :mod:`components.model.mesh_stiffness`.
        """
        if not self.time_varying_stiffness:
            return 1.0
        if np.ndim(driver_angle_rad) == 0:
            return self.phasing.factor(float(driver_angle_rad))
        angles = np.asarray(driver_angle_rad, dtype=float)
        return self.phasing.factors(angles.ravel())[0].reshape(angles.shape + (self.n_mesh,))

    # ----------------------------------------------------------------- loads
    def loads(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_port: np.ndarray | None = None,
        v_port: np.ndarray | None = None,
        stiffness_factor: np.ndarray | float = 1.0,
        derivatives: bool = True,
    ) -> InternalLoads:
        """Deflections, contact forces and shaft torques.

        Parameters
        ----------
        q, v : ndarray, shape (..., n_dof)
            Deviation angles [rad] and speeds [rad/s] of the free bodies.
        q_port, v_port : ndarray, shape (..., n_port), optional
            Deviation angle [rad] and speed [rad/s] of the prescribed port(s).
        stiffness_factor : ndarray or float
            Mesh stiffness multiplier, shape broadcastable to ``(..., n_mesh)``.
        derivatives : bool
            Also the force derivatives (for a Jacobian); False leaves them None and costs less.
        """
        d = q @ self.A.T
        dd = v @ self.A.T
        s = q @ self.S.T
        sd = v @ self.S.T
        if self.ports.size:
            d = d + q_port @ self.A_port.T
            dd = dd + v_port @ self.A_port.T
            s = s + q_port @ self.S_port.T
            sd = sd + v_port @ self.S_port.T
        torque = self.shaft_k * s + self.shaft_c * sd
        if not derivatives:
            force, elastic = self.law.force_and_elastic(d, dd, stiffness_factor)
            return InternalLoads(d, dd, force, None, None, elastic, s, sd, torque)
        cf = self.law.evaluate(d, dd, stiffness_factor)
        return InternalLoads(d, dd, cf.force, cf.d_force_d_deflection, cf.d_force_d_rate, cf.elastic, s, sd, torque)

    def generalised_forces(self, loads: InternalLoads) -> np.ndarray:
        """Generalised torques on the free bodies from meshes and shafts [N m], shape (..., n_dof)."""
        return -(loads.contact_force_n @ self.BT.T) - loads.shaft_torque_nm @ self.S

    def driver_torque(self, loads: InternalLoads, driver_acceleration: np.ndarray | float) -> np.ndarray:
        """Torque the kinematic driver applies to the gearbox [N m] (rotor torque).

        ``T_rotor = I_in alpha_in + cos(alpha) a_in . F + s_in . T_shaft``.
        """
        return (
            self.driver_inertia_kgm2 * driver_acceleration
            + loads.contact_force_n @ self.BT_driver
            + loads.shaft_torque_nm @ self.s_driver
        )

    # ------------------------------------------------------------- dynamics
    def acceleration(
        self,
        q: np.ndarray,
        v: np.ndarray,
        driver_acceleration: float,
        output_torque_nm: float = 0.0,
        q_port: np.ndarray | None = None,
        v_port: np.ndarray | None = None,
        stiffness_factor: np.ndarray | float = 1.0,
    ) -> np.ndarray:
        """Deviation accelerations ``q_ddot`` [rad/s^2], shape (n_dof,).

        ``output_torque_nm`` is the counter torque braking the output body (ignored
        when the output is a port).
        """
        loads = self.loads(q, v, q_port, v_port, stiffness_factor)
        Q = self.generalised_forces(loads)
        if self.output_dof is not None:
            Q[self.output_dof] -= output_torque_nm
        return self.inv_inertia * Q - self.kinematic_ratio * driver_acceleration

    def acceleration_jacobian(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_port: np.ndarray | None = None,
        v_port: np.ndarray | None = None,
        stiffness_factor: np.ndarray | float = 1.0,
        kernel: str | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Jacobians of ``q_ddot`` at one state (:func:`components.model.kernel.dynamics.jacobian`).

        Parameters
        ----------
        q, v : ndarray, shape (n_dof,)
            Deviation angles [rad] and speeds [rad/s].
        q_port, v_port : ndarray, shape (n_port,), optional
            The port's deviation angle [rad] and speed [rad/s].
        stiffness_factor : ndarray or float
            Mesh stiffness multiplier.
        kernel : {"auto", "numpy", "compiled"}, optional
            Form of the kernel (``auto``: the interpreted one unless numba's is loaded already: a short
            evaluation, :func:`components.model.kernel.monolithic`).

        Returns
        -------
        dA_dq, dA_dv : ndarray, shape (n_dof, n_dof)
            [1/s^2], [1/s].
        dA_dqport, dA_dvport : ndarray, shape (n_dof, n_port)
        """
        n, m = self.n_dof, self.n_mesh
        y = np.ascontiguousarray(np.concatenate((q, v)), dtype=float)
        port = float(q_port[0]) if self.ports.size and q_port is not None else 0.0
        port_rate = float(v_port[0]) if self.ports.size and v_port is not None else 0.0
        factor = np.ascontiguousarray(np.broadcast_to(np.asarray(stiffness_factor, dtype=float), (m,)))
        dq, dv, port_jac = np.zeros((n, n)), np.zeros((n, n)), np.zeros((2, n))
        stks_port = self.STkS_port[:, 0].copy() if self.ports.size else np.zeros(n)
        stcs_port = self.STcS_port[:, 0].copy() if self.ports.size else np.zeros(n)
        model_kernel.monolithic(kernel, brief=True)[0].jacobian(
            y, port, port_rate, factor, self.A_T, self.port_deflection, self.law.table, np.zeros((2, m)), self.nz_index,
            self.nz_value, self.cos_alpha, self.STkS, self.STcS, stks_port, stcs_port, self.inv_inertia, np.zeros(m),
            np.zeros(m), dq, dv, port_jac)
        if not self.ports.size:
            return dq, dv, np.zeros((n, 0)), np.zeros((n, 0))
        return dq, dv, port_jac[0][:, None], port_jac[1][:, None]

    def static_deflection(self, load_nm: float, stiffness_factor: np.ndarray | float = 1.0,
                          kernel: str | None = None, rtol: float = 1e-11,
                          max_iterations: int = 60) -> tuple[np.ndarray, int, float]:
        """Deviation angles at which meshes and shafts carry the counter torque ``load_nm`` at constant speed.

        :func:`components.model.kernel.statics.static_deflection` (Newton from two linear-spring guesses)
        for an uncut assembly, whose output body carries the load.

        Parameters
        ----------
        load_nm : float
            Counter torque on the output body [N m], non-zero (unloaded teeth float in the backlash).
        stiffness_factor : float or ndarray, shape (n_mesh,)
            Mesh stiffness multiplier (time-varying stiffness frozen at one phase); 1 = mean.
        kernel : {"auto", "numpy", "compiled"}, optional
            Form of the kernel (``auto``: the interpreted one unless numba's is loaded already: a short
            evaluation, :func:`components.model.kernel.monolithic`).
        rtol : float
            Converged when the largest generalised-force imbalance is below ``rtol`` times the largest sum of
            generalised-force magnitudes on one body.
        max_iterations : int
            Newton iterations.

        Returns
        -------
        q : ndarray, shape (n_dof,)
            Deviation angles [rad].
        iterations : int
        imbalance : float
            The remaining relative imbalance.

        Raises
        ------
        SolverError
            Not found (no convergence, singular stiffness).
        """
        if self.ports.size or self.output_dof is None:
            raise ParameterError("assembly", "cut at the generator", "an uncut assembly (the output a degree of freedom)")
        if not math.isfinite(load_nm) or load_nm == 0.0:
            raise ParameterError("load_nm", load_nm, "a finite non-zero torque (unloaded teeth float in the backlash)")
        n, m = self.n_dof, self.n_mesh
        y = np.zeros(2 * n)
        factor = np.ascontiguousarray(np.broadcast_to(np.asarray(stiffness_factor, dtype=float), (m,)))
        status, iterations, imbalance = model_kernel.monolithic(kernel, brief=True)[0].static_deflection(
            y, n, float(load_nm), factor, math.copysign(1.0, load_nm), self.A_T, self.port_deflection,
            self.fast_matrix, self.law.table, self.nz_index, self.nz_value, self.cos_alpha, self.STkS, self.STcS,
            np.zeros(n), np.zeros(n), self.inv_inertia, np.zeros(m + 2 * n + 4), np.zeros((2, m)), np.zeros(n),
            np.zeros(m), np.zeros(m), np.zeros((n, n)), np.zeros((n, n)), np.zeros((2, n)), np.zeros((n, n)),
            np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros(m), np.zeros(2 * n), rtol, max_iterations)
        if status != 0:
            what = "a singular stiffness" if status == 2 else f"{iterations} Newton iterations"
            raise SolverError(f"the static deflection at {load_nm:g} N m was not found ({what}, relative imbalance "
                              f"{imbalance:.3g})", 0.0)
        return y[:n].copy(), int(iterations), float(imbalance)

    # -------------------------------------------------------------- energy
    def kinetic_energy(self, speeds_rad_s: np.ndarray, driver_speed_rad_s: np.ndarray | float) -> np.ndarray:
        """Kinetic energy [J] of the free bodies plus the driven input member."""
        return 0.5 * (speeds_rad_s**2 @ self.inertia_kgm2) + 0.5 * self.driver_inertia_kgm2 * np.asarray(driver_speed_rad_s) ** 2

    def potential_energy(self, loads: InternalLoads) -> float:
        """Elastic energy [J] stored in meshes and shafts at one state."""
        mesh = float(self.cos_alpha @ self.law.potential_energy(loads.deflection_m))
        shafts = float(0.5 * self.shaft_k @ loads.shaft_twist_rad**2)
        return mesh + shafts

    def dissipation_power(self, loads: InternalLoads) -> np.ndarray:
        """Power dissipated by mesh and shaft damping [W], shape (...)."""
        mesh = ((loads.contact_force_n - loads.elastic_force_n) * loads.deflection_rate_m_s) @ self.cos_alpha
        shaft = (self.shaft_c * loads.shaft_twist_rate_rad_s**2).sum(axis=-1)
        return mesh + shaft
