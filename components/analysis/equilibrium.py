"""Static equilibrium and linearisation of a drivetrain at an operating point.

:func:`static_equilibrium` solves ``Q(q) = T_out e_out`` (Newton with the analytic
Jacobian) for the deviation angles ``q`` at constant rotor speed: every body turns at
its kinematic speed, the meshes and shafts carry the static load. The operating point
matters because the CFS contact (eq. 2) is nonlinear: the mesh stiffness
``e k0 d_BL^(e - 1)`` (``e = 3/2``) grows with the load and the mesh damping
``c0 |d_BL|`` with the deflection. :func:`linearise` then takes

    K = -M dA/dq,    C = -M dA/dv

from :meth:`Assembly.acceleration_jacobian` at the equilibrium - the same matrices
and Jacobian the simulation integrates.

In a torsional model with a kinematically driven input the linearisation does not
depend on the rotor speed itself (no gyroscopic or centrifugal terms); the speed
enters through the load law of the Campbell diagram (:mod:`components.analysis.campbell`).
The time-varying mesh stiffness option averages to the paper's stiffness over a
mesh cycle; the linearisation uses that mean (factor 1) unless given another factor.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import DtcosimError, ParameterError, SolverError
from ..model.assembly import Assembly
from ..model.drivetrain import Drivetrain
from ..units import rad_per_s_to_rpm, rpm
from ..validation import finite, set_fields


class EquilibriumError(DtcosimError):
    """The static equilibrium could not be found (Newton did not converge)."""


# --------------------------------------------------------------------------- operating point
@dataclass(frozen=True)
class OperatingPoint:
    """Where to linearise: constant rotor speed and output counter torque.

    Parameters
    ----------
    rotor_speed_rad_s : float
        Rotor (stage-1 carrier) speed [rad/s]; sets the excitation frequencies, not the
        linearised matrices of a torsional model.
    output_torque_nm : float
        Counter torque on the output body [N m]: the generator torque with a generator,
        else the torque on the last stage's output member. Must be non-zero: unloaded
        teeth float in the backlash and have no stiffness to linearise.
    """

    rotor_speed_rad_s: float
    output_torque_nm: float

    def __post_init__(self) -> None:
        t = finite("output_torque_nm", self.output_torque_nm)
        if t == 0.0:
            raise ParameterError("output_torque_nm", t, "non-zero (unloaded teeth float in the backlash)")
        set_fields(self, rotor_speed_rad_s=finite("rotor_speed_rad_s", self.rotor_speed_rad_s), output_torque_nm=t)

    @classmethod
    def from_rpm(cls, rotor_speed_rpm: float, output_torque_nm: float) -> "OperatingPoint":
        """Build from the rotor speed in rpm and the torque in N m."""
        return cls(rpm(finite("rotor_speed_rpm", rotor_speed_rpm)), output_torque_nm)

    @classmethod
    def of_drivetrain(cls, drivetrain: Drivetrain, rotor_speed_rad_s: float) -> "OperatingPoint":
        """The drivetrain's own base load (generator counter torque or output torque) at a rotor speed.

        Load events are ignored: this is the operating point before any event.
        """
        if drivetrain.generator is not None:
            torque = drivetrain.generator.counter_torque_nm
        else:
            torque = drivetrain.output_torque_nm
        return cls(rotor_speed_rad_s, torque)

    @property
    def rotor_speed_rpm(self) -> float:
        """Rotor speed [rpm]."""
        return rad_per_s_to_rpm(self.rotor_speed_rad_s)

    def as_dict(self) -> dict[str, float]:
        """Plain dict (JSON-ready)."""
        return {
            "rotor_speed_rad_s": self.rotor_speed_rad_s,
            "rotor_speed_rpm": self.rotor_speed_rpm,
            "output_torque_nm": self.output_torque_nm,
        }


# --------------------------------------------------------------------------- equilibrium
@dataclass(frozen=True)
class StaticEquilibrium:
    """Static equilibrium of a drivetrain at constant rotor speed.

    Attributes
    ----------
    q_rad : ndarray, shape (n_dof,)
        Deviation angles of the free bodies [rad] (speeds are kinematic: ``v = 0``).
    contact_force_n : ndarray, shape (n_mesh,)
        Contact forces [N].
    deflection_m : ndarray, shape (n_mesh,)
        Mesh deflections delta [m].
    mesh_stiffness_n_per_m : ndarray, shape (n_mesh,)
        Tangent mesh stiffness dF/d delta [N/m].
    mesh_damping_ns_per_m : ndarray, shape (n_mesh,)
        Mesh damping dF/d delta_dot = c0 |d_BL| d_BL' [N s/m].
    shaft_torque_nm : ndarray, shape (n_shaft,)
        Shaft torques [N m].
    rotor_torque_nm : float
        Torque the rotor applies to the gearbox [N m].
    iterations : int
        Newton iterations.
    residual_nm : float
        Largest remaining generalised-force imbalance [N m].
    """

    q_rad: np.ndarray
    contact_force_n: np.ndarray
    deflection_m: np.ndarray
    mesh_stiffness_n_per_m: np.ndarray
    mesh_damping_ns_per_m: np.ndarray
    shaft_torque_nm: np.ndarray
    rotor_torque_nm: float
    iterations: int
    residual_nm: float

    @property
    def state(self) -> np.ndarray:
        """``[q, v]`` with ``v = 0``, shape (2 n_dof,): the ``initial_state`` of the monolithic solver."""
        return np.concatenate([self.q_rad, np.zeros_like(self.q_rad)])


def _output_load(assembly: Assembly, torque_nm: float) -> np.ndarray:
    if assembly.output_dof is None:
        raise ParameterError("assembly", "cut at the generator", "an uncut assembly (the generator a degree of freedom)")
    f = np.zeros(assembly.n_dof)
    f[assembly.output_dof] = torque_nm
    return f


def static_equilibrium(
    drivetrain: Drivetrain | Assembly,
    output_torque_nm: float,
    stiffness_factor: np.ndarray | float = 1.0,
    rtol: float = 1e-11,
    max_iterations: int = 60,
    rotor_speed_rad_s: float = 0.0,
) -> StaticEquilibrium:
    """Deviation angles at which meshes and shafts carry a constant output torque.

    Solves ``Q(q, v=0) - T e_out = 0`` (``Q`` from :meth:`Assembly.generalised_forces`,
    ``e_out`` the output body) with the kernel's static solver
    (:meth:`Assembly.static_deflection`: Newton with the analytic stiffness and a backtracking
    line search, started from two linear solves with the meshes as linear springs offset by
    half the backlash on the loaded flank) - the same one that starts every run.

    Parameters
    ----------
    drivetrain : Drivetrain or Assembly
        The drivetrain (an uncut assembly: the generator, if any, is a degree of freedom).
    output_torque_nm : float
        Counter torque on the output body [N m], non-zero.
    stiffness_factor : float or ndarray, shape (n_mesh,)
        Mesh stiffness multiplier (time-varying stiffness frozen at one phase); 1 = mean.
    rtol : float
        Convergence: largest generalised-force imbalance below ``rtol`` x the largest sum
        of generalised-force magnitudes on one body.
    max_iterations : int
        Newton iterations before :class:`EquilibriumError`.
    rotor_speed_rad_s : float
        Rotor speed [rad/s]: the centrifugal force on the planets of lateral-torsional stages (their gravity
        at the rotor angle 0).

    Returns
    -------
    StaticEquilibrium
    """
    a = drivetrain if isinstance(drivetrain, Assembly) else Assembly(drivetrain)
    torque = finite("output_torque_nm", output_torque_nm)
    if torque == 0.0:
        raise ParameterError("output_torque_nm", torque, "non-zero (unloaded teeth float in the backlash)")
    zeros = np.zeros(a.n_dof)
    try:
        q, iterations, _ = a.static_deflection(torque, stiffness_factor, rtol=rtol, max_iterations=max_iterations,
                                               driver_speed_rad_s=rotor_speed_rad_s)
    except SolverError as exc:
        raise EquilibriumError(str(exc).rsplit(" (at t =", 1)[0]) from None
    loads = a.loads(q, zeros, stiffness_factor=stiffness_factor)
    residual = a.generalised_forces(loads) + a.external_forces(0.0, rotor_speed_rad_s) - _output_load(a, torque)
    return StaticEquilibrium(
        q_rad=q,
        contact_force_n=loads.contact_force_n.copy(),
        deflection_m=loads.deflection_m.copy(),
        mesh_stiffness_n_per_m=loads.d_force_d_deflection.copy(),
        mesh_damping_ns_per_m=loads.d_force_d_rate.copy(),
        shaft_torque_nm=loads.shaft_torque_nm.copy(),
        rotor_torque_nm=float(a.driver_torque(loads, 0.0)),
        iterations=iterations,
        residual_nm=float(np.abs(residual).max()),
    )


# --------------------------------------------------------------------------- linear model
@dataclass(frozen=True)
class LinearModel:
    """Linearised drivetrain ``M q'' + C q' + K q = f`` about a static equilibrium.

    Attributes
    ----------
    mass : ndarray, shape (n, n)
        Diagonal inertia matrix [kg m^2].
    damping : ndarray, shape (n, n)
        ``C = -M dA/dv`` [N m s/rad].
    stiffness : ndarray, shape (n, n)
        ``K = -M dA/dq`` [N m/rad].
    dof_names : list of str
        Body names in state order.
    operating_point : OperatingPoint
    equilibrium : StaticEquilibrium
    assembly : Assembly
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    dof_names: list[str]
    operating_point: OperatingPoint
    equilibrium: StaticEquilibrium
    assembly: Assembly = field(repr=False)


def linearise(drivetrain: Drivetrain, operating_point: OperatingPoint, stiffness_factor: np.ndarray | float = 1.0) -> LinearModel:
    """Linearise a drivetrain about its static equilibrium at an operating point.

    Parameters
    ----------
    drivetrain : Drivetrain
    operating_point : OperatingPoint
    stiffness_factor : float or ndarray, shape (n_mesh,)
        Mesh stiffness multiplier (1: the mean stiffness).

    Returns
    -------
    LinearModel
        ``K = -M dA/dq`` and ``C = -M dA/dv`` from :meth:`Assembly.acceleration_jacobian`
        at the equilibrium (symmetric up to round-off; symmetrised).
    """
    if not isinstance(operating_point, OperatingPoint):
        raise ParameterError("operating_point", operating_point, "an OperatingPoint")
    a = Assembly(drivetrain)
    eq = static_equilibrium(a, operating_point.output_torque_nm, stiffness_factor,
                            rotor_speed_rad_s=operating_point.rotor_speed_rad_s)
    dq, dv, _, _ = a.acceleration_jacobian(eq.q_rad, np.zeros(a.n_dof), stiffness_factor=stiffness_factor)
    m = a.inertia_kgm2
    k = -(m[:, None] * dq)
    c = -(m[:, None] * dv)
    return LinearModel(
        mass=np.diag(m),
        damping=0.5 * (c + c.T),
        stiffness=0.5 * (k + k.T),
        dof_names=a.dof_names,
        operating_point=operating_point,
        equilibrium=eq,
        assembly=a,
    )
