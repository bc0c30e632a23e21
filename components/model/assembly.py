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
from .generator import GENERATOR_BODY
from .kernel.stiffness import N_PHASING_ROWS
from .mesh_stiffness import MeshPhasing
from .sparse import column_sparsity, dense_rows
from .stage_rows import CONSTANT, COS, OMEGA2, SIN, Body, Rows, SpringElement, parallel_rows, planetary_rows
from .stages import PlanetaryStage

__all__ = ["Assembly", "Body", "InternalLoads", "Mesh", "ShaftElement", "SpringElement", "column_sparsity"]


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
    #: the deflection [m] (torsional supports: [rad]), its rate and the force [N] ([N m]) of every bearing row,
    #: shape (..., n_spring)
    bearing_deflection_m: np.ndarray | None = None
    bearing_rate_m_s: np.ndarray | None = None
    bearing_force_n: np.ndarray | None = None


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
        rows = Rows()
        shaft_rows: list[tuple[int, int]] = []
        shafts: list[ShaftElement] = []
        bodies = rows.bodies

        def shaft(sh, a: int, b: int) -> None:
            shaft_rows.append((a, b))
            shafts.append(ShaftElement(sh.name, bodies[a].name, bodies[b].name, sh.stiffness_nm_per_rad, sh.damping_nms_per_rad))

        gravity = drivetrain.gravity.in_plane_m_s2 if drivetrain.gravity is not None else 0.0
        previous_output = -1
        stage_members: dict[str, dict[str, int]] = {}
        for k, st in enumerate(drivetrain.stages):
            build = planetary_rows if isinstance(st, PlanetaryStage) else parallel_rows
            members = build(rows, st, gravity, k == 0)
            stage_members[st.name] = members
            if k > 0:
                shaft(drivetrain.shafts[k - 1], previous_output, members["input"])
            previous_output = members["output"]
        generator_index = None
        if drivetrain.generator is not None:
            generator_index = rows.body(GENERATOR_BODY, drivetrain.generator.inertia_kgm2, "generator", "generator")
            shaft(drivetrain.output_shaft, previous_output, generator_index)
        output_index = generator_index if generator_index is not None else previous_output

        nb = len(bodies)
        A = dense_rows(rows.mesh_rows, nb)
        S = np.zeros((len(shaft_rows), nb))
        for i, (a, b) in enumerate(shaft_rows):
            S[i, a] = 1.0
            S[i, b] = -1.0
        B = dense_rows(rows.spring_rows, nb)

        driver = 0
        ports = [generator_index] if cut_at_generator else []
        free = [j for j in range(nb) if j != driver and j not in ports]

        # kinematic ratios: [A; S; B] kappa = 0 with kappa_driver = 1 (exact for consistent geometry)
        G = np.vstack([A, S, B])
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
            for (name, stage, kind, contact, ref, teeth, off) in rows.meshes
        ]
        self.shafts = shafts
        #: the bearings and supports of the lateral-torsional stages (their spring rows: :attr:`B`)
        self.elements: list[SpringElement] = list(rows.elements)
        self.stage_members = {k: {r: bodies[i].name for r, i in v.items()} for k, v in stage_members.items()}
        self.free = np.array(free, dtype=int)
        self.ports = np.array(ports, dtype=int)
        self.driver = driver
        self.n_dof = len(free)
        self.n_mesh = len(rows.mesh_rows)
        self.n_shaft = len(shaft_rows)
        self.n_spring = len(rows.spring_rows)
        self.kinematic_ratio_all = kappa_all
        self.kinematic_ratio = kappa_all[free]
        self.port_ratio = kappa_all[ports]
        self.inertia_all_kgm2 = np.array([b.inertia_kgm2 for b in bodies])
        self.inertia_kgm2 = self.inertia_all_kgm2[free]
        self.inv_inertia = 1.0 / self.inertia_kgm2
        self.driver_inertia_kgm2 = bodies[driver].inertia_kgm2
        self.law = ContactLaw([m.contact for m in self.meshes])
        self.cos_alpha = np.array([math.cos(m.contact.pressure_angle_rad) for m in self.meshes])
        #: constant deflection of every mesh [m] (planet pin position errors): ``d = A q + e``
        self.mesh_offset = np.array(rows.mesh_offsets, dtype=float)
        self.A_all = A
        self.S_all = S
        self.B_all = B
        self.A = np.ascontiguousarray(A[:, free])
        self.A_port = np.ascontiguousarray(A[:, ports])
        self.S = np.ascontiguousarray(S[:, free])
        self.S_port = np.ascontiguousarray(S[:, ports])
        #: the bearing rows of the free bodies, their stiffness [N/m or N m/rad] and damping
        self.B = np.ascontiguousarray(B[:, free])
        self.bearing_k = np.array(rows.spring_k, dtype=float)
        self.bearing_c = np.array(rows.spring_c, dtype=float)
        self.a_driver = A[:, driver].copy()
        self.s_driver = S[:, driver].copy()
        self.b_driver = B[:, driver].copy()
        self.BT = np.ascontiguousarray((self.cos_alpha[:, None] * self.A).T)  # (n_dof, n_mesh)
        self.BT_driver = self.cos_alpha * self.a_driver
        self.shaft_k = np.array([s.stiffness_nm_per_rad for s in shafts])
        self.shaft_c = np.array([s.damping_nms_per_rad for s in shafts])
        #: every spring row of the kernel: the shafts, then the bearings (rows, stiffness, damping, driver column)
        self.springs = np.ascontiguousarray(np.vstack([self.S, self.B]))
        self.springs_k = np.concatenate([self.shaft_k, self.bearing_k])
        self.springs_c = np.concatenate([self.shaft_c, self.bearing_c])
        self.springs_driver = np.concatenate([self.s_driver, self.b_driver])
        springs_port = np.vstack([self.S_port, B[:, ports]])
        self.ST = np.ascontiguousarray(self.S.T)
        self.STkS = self.springs.T @ (self.springs_k[:, None] * self.springs)
        self.STcS = self.springs.T @ (self.springs_c[:, None] * self.springs)
        self.STkS_port = self.springs.T @ (self.springs_k[:, None] * springs_port)
        self.STcS_port = self.springs.T @ (self.springs_c[:, None] * springs_port)
        self._external_loads(rows, kappa_all, free)
        out_free = np.flatnonzero(self.free == output_index)
        self.output_dof = int(out_free[0]) if out_free.size else None  # None when the output is the port
        self.output_body = bodies[output_index].name
        self.time_varying_stiffness = any(m.contact.stiffness_variation > 0.0 for m in self.meshes)
        # matrices for the single-state fast path (mesh forces + shafts folded into constant matrices)
        self.A_T = np.ascontiguousarray(self.A.T)  # (n_dof, n_mesh)
        self._neg_B = np.ascontiguousarray(-(self.cos_alpha[:, None] * self.A))  # (n_mesh, n_dof)
        self._shaft_QY = np.ascontiguousarray(-np.vstack([self.STkS.T, self.STcS.T]))  # y = [q, v] -> spring forces
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
        #: the folded matrix: q_ddot = [force, q, v, u, u_dot, alpha_in, external terms] @ fast_matrix (u, u_dot:
        #: the port input, see above; the external terms: :attr:`load_terms`); what the kernel
        #: (:func:`components.model.kernel.dynamics.acceleration`) evaluates
        scaled = np.vstack([self._neg_B, self._shaft_QY, port_q[None, :], port_v[None, :]]) * self.inv_inertia
        self.fast_matrix = np.ascontiguousarray(
            np.vstack([scaled, -self.kinematic_ratio[None, :], self.load_matrix * self.inv_inertia]))
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
        #: the nonzero columns of every mesh row of ``A`` (free bodies) and their entries: the kernel's Jacobian
        #: sums over these only
        self.nz_index, self.nz_value = column_sparsity(self.A.T)
        #: the folded matrix by columns, its nonzero rows only: what the kernel's accelerations sum
        self.fast_index, self.fast_value = column_sparsity(self.fast_matrix)
        #: the columns each row of the Jacobian blocks dq/dv can hold (shafts, bearings and the bodies of one mesh)
        pattern = (self.STkS != 0.0) | (self.STcS != 0.0) | np.eye(self.n_dof, dtype=bool)
        for row in self.A:
            cols = np.flatnonzero(row)
            pattern[np.ix_(cols, cols)] = True
        self.jacobian_index = column_sparsity(pattern.T.astype(float))[0]

    def _external_loads(self, rows: Rows, kappa_all: np.ndarray, free: list[int]) -> None:
        """:attr:`load_rates` and :attr:`load_matrix` from the stages' loads (none without a lateral stage).

        The external generalised forces are ``terms @ load_matrix`` with ``terms = [omega_in^2, 1, cos(r_1 th_in),
        sin(r_1 th_in), ...]`` (:func:`components.model.kernel.dynamics.external_terms`), ``r_k = load_rates[k]``
        the kinematic ratio of a carrier whose frame gravity turns in.
        """
        frames = list(dict.fromkeys(f for _, term, f, _ in rows.loads if term in (COS, SIN)))
        #: frame rate of each cos/sin pair of the external terms [rad per driver rad]
        self.load_rates = np.array([kappa_all[f] for f in frames], dtype=float)
        n_terms = 2 + 2 * len(frames) if self.drivetrain.lateral else 0
        where = {j: i for i, j in enumerate(free)}
        matrix = np.zeros((n_terms, len(free)))
        for body, term, frame, coefficient in rows.loads:
            if body not in where:
                continue
            if term == OMEGA2:
                matrix[0, where[body]] += coefficient * kappa_all[frame] ** 2
            elif term == CONSTANT:
                matrix[1, where[body]] += coefficient
            else:
                matrix[2 + 2 * frames.index(frame) + (term == SIN), where[body]] += coefficient
        #: external generalised forces per external term, shape (n_terms, n_dof) (0 rows: no lateral stage)
        self.load_matrix = matrix

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
        d = q @ self.A.T + self.mesh_offset
        dd = v @ self.A.T
        s = q @ self.S.T
        sd = v @ self.S.T
        if self.ports.size:
            d = d + q_port @ self.A_port.T
            dd = dd + v_port @ self.A_port.T
            s = s + q_port @ self.S_port.T
            sd = sd + v_port @ self.S_port.T
        torque = self.shaft_k * s + self.shaft_c * sd
        b, bd = q @ self.B.T, v @ self.B.T
        bearing = (b, bd, self.bearing_k * b + self.bearing_c * bd)
        if not derivatives:
            force, elastic = self.law.force_and_elastic(d, dd, stiffness_factor)
            return InternalLoads(d, dd, force, None, None, elastic, s, sd, torque, *bearing)
        cf = self.law.evaluate(d, dd, stiffness_factor)
        return InternalLoads(d, dd, cf.force, cf.d_force_d_deflection, cf.d_force_d_rate, cf.elastic, s, sd, torque,
                             *bearing)

    def generalised_forces(self, loads: InternalLoads) -> np.ndarray:
        """Generalised forces on the free bodies from meshes, shafts and bearings [N m, N], shape (..., n_dof)."""
        return -(loads.contact_force_n @ self.BT.T) - loads.shaft_torque_nm @ self.S - loads.bearing_force_n @ self.B

    def external_terms(self, driver_angle_rad: np.ndarray | float, driver_speed_rad_s: np.ndarray | float) -> np.ndarray:
        """The external terms ``[omega^2, 1, cos(r_k th), sin(r_k th), ...]`` at driver angles and speeds, shape
        (..., n_terms) (none without a lateral stage; the kernel's :func:`~.kernel.dynamics.external_terms`)."""
        angle = np.asarray(driver_angle_rad, dtype=float)
        speed = np.asarray(driver_speed_rad_s, dtype=float)
        shape = np.broadcast(angle, speed).shape
        if not self.load_matrix.shape[0]:
            return np.zeros(shape + (0,))
        phase = np.broadcast_to(angle, shape)[..., None] * self.load_rates
        trig = np.stack([np.cos(phase), np.sin(phase)], axis=-1).reshape(shape + (2 * self.load_rates.size,))
        return np.concatenate([np.broadcast_to(speed, shape)[..., None] ** 2, np.ones(shape + (1,)), trig], axis=-1)

    def external_forces(self, driver_angle_rad: np.ndarray | float, driver_speed_rad_s: np.ndarray | float) -> np.ndarray:
        """Gravity and centrifugal forces on the free bodies [N], shape (..., n_dof) (zero without lateral stages)."""
        terms = self.external_terms(driver_angle_rad, driver_speed_rad_s)
        if not terms.shape[-1]:
            return np.zeros(terms.shape[:-1] + (self.n_dof,))
        return terms @ self.load_matrix

    def driver_torque(self, loads: InternalLoads, driver_acceleration: np.ndarray | float) -> np.ndarray:
        """Torque the kinematic driver applies to the gearbox [N m] (rotor torque).

        ``T_rotor = I_in alpha_in + cos(alpha) a_in . F + s_in . T_shaft + b_in . F_bearing``.
        """
        return (
            self.driver_inertia_kgm2 * driver_acceleration
            + loads.contact_force_n @ self.BT_driver
            + loads.shaft_torque_nm @ self.s_driver
            + loads.bearing_force_n @ self.b_driver
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
        driver_angle_rad: float = 0.0,
        driver_speed_rad_s: float = 0.0,
    ) -> np.ndarray:
        """Deviation accelerations ``q_ddot`` [rad/s^2, m/s^2], shape (n_dof,).

        ``output_torque_nm`` is the counter torque braking the output body (ignored
        when the output is a port); the driver's angle and speed set the external loads.
        """
        loads = self.loads(q, v, q_port, v_port, stiffness_factor)
        Q = self.generalised_forces(loads) + self.external_forces(driver_angle_rad, driver_speed_rad_s)
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
            y, port, port_rate, factor, self.port_deflection, self.mesh_offset, self.law.table,
            np.zeros((2, m)), self.nz_index, self.nz_value, self.cos_alpha, self.STkS, self.STcS, stks_port, stcs_port, self.inv_inertia, np.zeros(m),
            np.zeros(m), dq, dv, port_jac)
        if not self.ports.size:
            return dq, dv, np.zeros((n, 0)), np.zeros((n, 0))
        return dq, dv, port_jac[0][:, None], port_jac[1][:, None]

    def static_deflection(self, load_nm: float, stiffness_factor: np.ndarray | float = 1.0,
                          kernel: str | None = None, rtol: float = 1e-11, max_iterations: int = 60,
                          driver_angle_rad: float = 0.0,
                          driver_speed_rad_s: float = 0.0) -> tuple[np.ndarray, int, float]:
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
        driver_angle_rad, driver_speed_rad_s : float
            Where gravity points and how fast the planets orbit (the external loads of lateral stages).

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
        n_ext = self.load_matrix.shape[0]
        z = np.zeros(m + 2 * n + 4 + n_ext)
        z[m + 2 * n + 3:m + 2 * n + 3 + n_ext] = self.external_terms(driver_angle_rad, driver_speed_rad_s)
        status, iterations, imbalance = model_kernel.monolithic(kernel, brief=True)[0].static_deflection(
            y, n, float(load_nm), factor, math.copysign(1.0, load_nm), self.A_T, self.port_deflection, self.mesh_offset,
            self.fast_matrix, self.fast_index, self.fast_value, self.law.table, self.nz_index, self.nz_value, self.cos_alpha, self.STkS, self.STcS,
            np.zeros(n), np.zeros(n), self.inv_inertia, z, np.zeros((2, m)), np.zeros(n),
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
        """Elastic energy [J] stored in meshes, shafts and bearings at one state."""
        mesh = float(self.cos_alpha @ self.law.potential_energy(loads.deflection_m))
        shafts = float(0.5 * self.shaft_k @ loads.shaft_twist_rad**2)
        return mesh + shafts + float(0.5 * self.bearing_k @ loads.bearing_deflection_m**2)

    def dissipation_power(self, loads: InternalLoads) -> np.ndarray:
        """Power dissipated by mesh, shaft and bearing damping [W], shape (...)."""
        mesh = ((loads.contact_force_n - loads.elastic_force_n) * loads.deflection_rate_m_s) @ self.cos_alpha
        shaft = (self.shaft_c * loads.shaft_twist_rate_rad_s**2).sum(axis=-1)
        return mesh + shaft + (self.bearing_c * loads.bearing_rate_m_s**2).sum(axis=-1)
