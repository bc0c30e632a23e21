"""Modal analysis: linearisation at an operating point, undamped and damped (complex) modes.

Generic core (any ``M, C, K``)
------------------------------
* :func:`undamped_modes` - the symmetric generalised eigenproblem ``K u = omega^2 M u``.
* :func:`state_space_modes` - eigenvalues ``lambda`` and right/left eigenvectors of the
  first-order system ``x' = [[0, I], [-M^-1 K, -M^-1 C]] x``.
* :func:`modal_analysis` - both, matched mode by mode (mass-weighted MAC between the
  undamped shape and the displacement part of each complex pair), with damping
  ratios, damped frequencies and an overdamped flag per mode.

Drivetrain linearisation
------------------------
:func:`static_equilibrium` solves ``Q(q) = T_out e_out`` (Newton with the analytic
Jacobian) for the deviation angles ``q`` at constant rotor speed: every body turns at
its kinematic speed, the meshes and shafts carry the static load. The operating point
matters because the CFS contact (eq. 2) is nonlinear: the mesh stiffness
``e k0 d_BL^(e - 1)`` (``e = 3/2``) grows with the load and the mesh damping
``c0 |d_BL|`` with the deflection. :func:`linearise` then takes

    K = -M dA/dq,    C = -M dA/dv

from :meth:`Assembly.acceleration_jacobian` at the equilibrium - the same matrices
and Jacobian the simulation integrates - and :func:`drivetrain_modes` reports the
modes with body names, the kinetic-energy share of every body and the strain-energy
share of every mesh group and shaft.

In a torsional model with a kinematically driven input the linearisation does not
depend on the rotor speed itself (no gyroscopic or centrifugal terms); the speed
enters through the load law of the Campbell diagram (:mod:`components.analysis.campbell`).
The time-varying mesh stiffness option averages to the paper's stiffness over a
mesh cycle; the linearisation uses that mean (factor 1) unless given another factor.

Mode kinds: for a purely torsional model with ``n`` equally spaced identical planets
the *planet modes* (only the planets of one stage move, the central members stand
still) have multiplicity ``n - 1``; the other (*rotational*) modes are simple (Lin and
Parker, 1999).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linear_sum_assignment

from ..errors import DtcosimError, ParameterError
from ..model.assembly import Assembly
from ..model.drivetrain import Drivetrain
from ..units import rad_per_s_to_rpm, rpm
from ..validation import finite, set_fields

#: |Im lambda| / |lambda| below which an eigenvalue counts as real (overdamped root).
REAL_EIGENVALUE_TOLERANCE = 1e-7
#: Shape components below this fraction of the largest count as "not moving" (mode kinds).
STILL_TOLERANCE = 1e-6


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
) -> StaticEquilibrium:
    """Deviation angles at which meshes and shafts carry a constant output torque.

    Solves ``Q(q, v=0) - T e_out = 0`` (``Q`` from :meth:`Assembly.generalised_forces`,
    ``e_out`` the output body) by Newton's method with the analytic stiffness
    ``-M dA/dq`` and a backtracking line search. The starting point comes from two
    linear solves with the meshes as linear springs offset by half the backlash on the
    loaded flank (secant stiffness of the Hertzian law at the first solve's forces).

    Parameters
    ----------
    drivetrain : Drivetrain or Assembly
        The drivetrain (an uncut assembly: the generator, if any, is a degree of freedom).
    output_torque_nm : float
        Counter torque on the output body [N m], non-zero.
    stiffness_factor : float or ndarray, shape (n_mesh,)
        Mesh stiffness multiplier (time-varying stiffness frozen at one phase); 1 = mean.
    rtol : float
        Convergence: largest generalised-force imbalance below ``rtol`` x the
        quasi-static rotor torque.
    max_iterations : int
        Newton iterations before :class:`EquilibriumError`.

    Returns
    -------
    StaticEquilibrium
    """
    a = drivetrain if isinstance(drivetrain, Assembly) else Assembly(drivetrain)
    torque = finite("output_torque_nm", output_torque_nm)
    if torque == 0.0:
        raise ParameterError("output_torque_nm", torque, "non-zero (unloaded teeth float in the backlash)")
    n = a.n_dof
    load = _output_load(a, torque)
    zeros = np.zeros(n)
    scale = abs(torque) * max(1.0, abs(float(a.kinematic_ratio_all[a.free[a.output_dof]])))
    flank = math.copysign(1.0, torque)  # normal power flow loads every mesh on the positive flank
    half_jt = np.array([0.5 * m.contact.backlash_circumferential_m for m in a.meshes])
    k0 = np.array([m.contact.stiffness for m in a.meshes]) * stiffness_factor
    expo = np.array([m.contact.exponent for m in a.meshes])

    def linear_guess(k_lin: np.ndarray) -> np.ndarray:
        # meshes as linear springs F = k (d - flank j_t/2):  K q = -T e_out + B^T k flank j_t/2
        kk = a.A.T @ ((a.cos_alpha * k_lin)[:, None] * a.A) + a.STkS
        rhs = -load + a.A.T @ (a.cos_alpha * k_lin * flank * half_jt)
        return np.linalg.solve(kk, rhs)

    q = linear_guess(k0 * 1e-2 ** (expo - 1.0))  # stiffness at 1 cm penetration: soft, safe start
    force = (a.A @ q - flank * half_jt) * k0 * 1e-2 ** (expo - 1.0)
    pen = (np.abs(force) / k0) ** (1.0 / expo)
    q = linear_guess(k0 * np.maximum(pen, 1e-9) ** (expo - 1.0))  # secant stiffness at those forces

    def residual(qq: np.ndarray):
        loads = a.loads(qq, zeros, stiffness_factor=stiffness_factor)
        return a.generalised_forces(loads) - load, loads

    r, loads = residual(q)
    norm = np.abs(r).max()
    it = 0
    while norm > rtol * scale:
        if it >= max_iterations:
            raise EquilibriumError(
                f"static equilibrium not found after {it} Newton iterations (residual {norm:.3g} N m)"
            )
        it += 1
        dq, _, _, _ = a.acceleration_jacobian(loads)
        stiffness = -(a.inertia_kgm2[:, None] * dq)
        try:
            step = np.linalg.solve(stiffness, r)
        except np.linalg.LinAlgError:
            raise EquilibriumError("singular stiffness at the equilibrium iterate (a mesh out of contact?)") from None
        alpha = 1.0
        while True:
            q_new = q + alpha * step
            r_new, loads_new = residual(q_new)
            norm_new = np.abs(r_new).max()
            if norm_new < norm or alpha < 1e-6:
                break
            alpha *= 0.5
        q, r, loads, norm = q_new, r_new, loads_new, norm_new
    return StaticEquilibrium(
        q_rad=q,
        contact_force_n=loads.contact_force_n.copy(),
        deflection_m=loads.deflection_m.copy(),
        mesh_stiffness_n_per_m=loads.d_force_d_deflection.copy(),
        mesh_damping_ns_per_m=loads.d_force_d_rate.copy(),
        shaft_torque_nm=loads.shaft_torque_nm.copy(),
        rotor_torque_nm=float(a.driver_torque(loads, 0.0)),
        iterations=it,
        residual_nm=float(norm),
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
    eq = static_equilibrium(a, operating_point.output_torque_nm, stiffness_factor)
    loads = a.loads(eq.q_rad, np.zeros(a.n_dof), stiffness_factor=stiffness_factor)
    dq, dv, _, _ = a.acceleration_jacobian(loads)
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


# --------------------------------------------------------------------------- generic core
def _as_matrix(name: str, x: np.ndarray, n: int | None = None) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 1:
        arr = np.diag(arr)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or (n is not None and arr.shape[0] != n):
        raise ParameterError(name, arr.shape, f"a square matrix{'' if n is None else f' of size {n}'} (or its diagonal)")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(name, "non-finite entries", "finite values")
    return arr


@dataclass(frozen=True)
class UndampedModes:
    """Solution of ``K u = omega^2 M u``.

    Attributes
    ----------
    omega_rad_s : ndarray, shape (n,)
        Natural angular frequencies [rad/s], ascending (0 for rigid-body modes).
    shapes : ndarray, shape (n, n)
        Mass-normalised mode shapes as columns (``U^T M U = I``).
    """

    omega_rad_s: np.ndarray
    shapes: np.ndarray

    @property
    def frequency_hz(self) -> np.ndarray:
        """Natural frequencies [Hz], shape (n,)."""
        return self.omega_rad_s / (2.0 * math.pi)


def undamped_modes(mass: np.ndarray, stiffness: np.ndarray) -> UndampedModes:
    """Undamped natural frequencies and mass-normalised shapes.

    Parameters
    ----------
    mass : ndarray, shape (n, n) or (n,)
        Symmetric positive definite mass (inertia) matrix, or its diagonal [kg m^2].
    stiffness : ndarray, shape (n, n)
        Symmetric positive semi-definite stiffness matrix [N m/rad].

    Returns
    -------
    UndampedModes

    Raises
    ------
    ParameterError
        If the matrices are not square/symmetric of one size, ``M`` is not positive
        definite or ``K`` has a clearly negative eigenvalue (unstable equilibrium).
    """
    m = _as_matrix("mass", mass)
    k = _as_matrix("stiffness", stiffness, m.shape[0])
    for name, x in (("mass", m), ("stiffness", k)):
        if np.abs(x - x.T).max() > 1e-9 * max(np.abs(x).max(), 1e-300):
            raise ParameterError(name, "asymmetric", "a symmetric matrix")
    try:
        w2, u = sla.eigh(0.5 * (k + k.T), 0.5 * (m + m.T))
    except np.linalg.LinAlgError:
        raise ParameterError("mass", "not positive definite", "a positive definite mass matrix") from None
    tol = 1e-9 * max(abs(w2).max(), 1e-300)
    if w2.min() < -tol:
        raise ParameterError("stiffness", f"eigenvalue {w2.min():.3g}", "a positive semi-definite stiffness (stable equilibrium)")
    w2 = np.where(w2 < tol, 0.0, w2)
    return UndampedModes(np.sqrt(w2), u)


@dataclass(frozen=True)
class StateSpaceModes:
    """Eigen-solution of ``x' = A x``, ``x = [q, q']``, ``A = [[0, I], [-M^-1 K, -M^-1 C]]``.

    Attributes
    ----------
    eigenvalues : ndarray, shape (2n,), complex
        ``lambda`` [1/s], sorted by ``|lambda|``.
    right : ndarray, shape (2n, 2n), complex
        Right eigenvectors as columns, ``A Phi = Phi diag(lambda)``.
    left : ndarray, shape (2n, 2n), complex
        Left eigenvectors as columns, ``Psi^H A = diag(lambda) Psi^H`` and
        ``Psi^H Phi = I``: the modal coordinate of mode j is ``eta_j = Psi[:, j]^H x``.
    """

    eigenvalues: np.ndarray
    right: np.ndarray
    left: np.ndarray

    def is_complex(self, tolerance: float = REAL_EIGENVALUE_TOLERANCE) -> np.ndarray:
        """Boolean mask of oscillatory (complex) eigenvalues, shape (2n,)."""
        lam = self.eigenvalues
        return np.abs(lam.imag) > tolerance * np.maximum(np.abs(lam), 1e-300)


def state_space_matrix(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
    """The first-order system matrix ``[[0, I], [-M^-1 K, -M^-1 C]]``, shape (2n, 2n)."""
    m = _as_matrix("mass", mass)
    n = m.shape[0]
    c = _as_matrix("damping", damping, n)
    k = _as_matrix("stiffness", stiffness, n)
    minv_k = np.linalg.solve(m, k)
    minv_c = np.linalg.solve(m, c)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-minv_k, -minv_c]])


def state_space_modes(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray) -> StateSpaceModes:
    """Complex modes of the damped system.

    Parameters
    ----------
    mass, damping, stiffness : ndarray, shape (n, n) (``mass`` may be its diagonal)
        ``M`` [kg m^2], ``C`` [N m s/rad], ``K`` [N m/rad].

    Returns
    -------
    StateSpaceModes
        Left eigenvectors from ``Phi^-1`` (biorthonormal also within repeated
        eigenvalues, e.g. the planet-mode pairs); a rigid-body mode makes ``A``
        defective and the left eigenvectors meaningless (``ParameterError``).
    """
    a = state_space_matrix(mass, damping, stiffness)
    lam, right = sla.eig(a)
    order = np.lexsort((lam.imag, np.abs(lam)))
    lam, right = lam[order], right[:, order]
    right = right / np.linalg.norm(right, axis=0)
    cond = np.linalg.cond(right)
    if not np.isfinite(cond) or cond > 1e12:
        raise ParameterError("stiffness", f"defective system matrix (cond {cond:.2g})", "no rigid-body modes (non-singular K)")
    left = np.linalg.inv(right).conj().T
    return StateSpaceModes(lam, right, left)


def modal_assurance(u: np.ndarray, v: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Mass-weighted modal assurance criterion between shape sets.

    ``MAC_ij = |u_i^T M v_j|^2 / ((u_i^H M u_i)(v_j^H M v_j))``, 1 for identical shapes.

    Parameters
    ----------
    u : ndarray, shape (n, p)
    v : ndarray, shape (n, r), may be complex
    mass : ndarray, shape (n, n)

    Returns
    -------
    ndarray, shape (p, r)
    """
    mu = mass @ u
    num = np.abs(mu.conj().T @ v) ** 2
    du = np.real(np.einsum("ip,ip->p", u.conj(), mu))
    dv = np.real(np.einsum("ir,ir->r", v.conj(), mass @ v))
    return num / np.outer(du, dv)


@dataclass(frozen=True)
class Mode:
    """One mode of a (linearised) system.

    Attributes
    ----------
    index : int
        1-based, in order of undamped natural frequency.
    undamped_frequency_hz : float
        From ``K u = omega^2 M u`` [Hz].
    overdamped : bool
        True if the damped system has no oscillatory (complex) eigenvalue pair for
        this mode: a disturbance decays without oscillating (two real roots).
    damping_ratio : float
        ``-Re(lambda) / |lambda|`` of the matched eigenvalue pair; for an overdamped
        mode the modal estimate ``u^T C u / (2 omega)`` (>= 1 in practice) [-].
    damped_frequency_hz : float
        ``Im(lambda) / (2 pi)`` [Hz]; NaN for an overdamped mode.
    modal_damping_ratio : float
        ``u^T C u / (2 omega)`` with the mass-normalised undamped shape (exact for
        proportional damping) [-].
    eigenvalue : complex or None
        Matched state-space eigenvalue with ``Im > 0`` [1/s]; None if overdamped.
    mac : float
        Mass-weighted MAC between the undamped shape and the matched complex shape.
    shape : ndarray, shape (n,)
        Undamped shape normalised to a largest component of +1.
    energy_fraction : ndarray, shape (n,)
        Share of the modal kinetic energy per degree of freedom ``M_ii u_i^2 / u^T M u`` [-].
    kind : str
        ``"rotational"``, ``"planet"`` or ``"rigid"`` (classification by the caller; default ``"mode"``).
    eigen_index : int or None
        Index of the matched eigenvalue in :attr:`StateSpaceModes.eigenvalues`; None if overdamped.
    """

    index: int
    undamped_frequency_hz: float
    overdamped: bool
    damping_ratio: float
    damped_frequency_hz: float
    modal_damping_ratio: float
    eigenvalue: complex | None
    mac: float
    shape: np.ndarray
    energy_fraction: np.ndarray
    kind: str = "mode"
    eigen_index: int | None = None


def _normalise_shape(u: np.ndarray) -> np.ndarray:
    j = int(np.argmax(np.abs(u)))
    return u / u[j] if u[j] != 0 else u


def modal_analysis(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray) -> tuple[list[Mode], StateSpaceModes, UndampedModes]:
    """Undamped and damped modes of ``M q'' + C q' + K q = 0``, matched mode by mode.

    Every complex eigenvalue pair (``Im lambda > 0``) is assigned to the undamped mode
    whose shape it resembles most (mass-weighted MAC, optimal one-to-one assignment);
    undamped modes without a pair are overdamped. Real eigenvalues (the overdamped
    roots) stay in the returned :class:`StateSpaceModes`.

    Parameters
    ----------
    mass, damping, stiffness : ndarray, shape (n, n) (``mass`` may be its diagonal)

    Returns
    -------
    modes : list of Mode
        In order of undamped natural frequency.
    state_space : StateSpaceModes
    undamped : UndampedModes
    """
    m = _as_matrix("mass", mass)
    n = m.shape[0]
    c = _as_matrix("damping", damping, n)
    k = _as_matrix("stiffness", stiffness, n)
    und = undamped_modes(m, k)
    ss = state_space_modes(m, c, k)
    osc = np.flatnonzero(ss.is_complex() & (ss.eigenvalues.imag > 0))
    assigned: dict[int, tuple[int, float]] = {}
    if osc.size:
        mac = modal_assurance(und.shapes, ss.right[:n, osc], m)
        rows, cols = linear_sum_assignment(-mac)
        assigned = {int(r): (int(osc[cidx]), float(mac[r, cidx])) for r, cidx in zip(rows, cols)}
    modes = []
    for i in range(n):
        u = und.shapes[:, i]
        w = float(und.omega_rad_s[i])
        modal_zeta = float(u @ c @ u) / (2.0 * w) if w > 0 else float("nan")
        mu2 = np.diag(m) * u * u
        energy = mu2 / mu2.sum() if mu2.sum() > 0 else mu2
        if i in assigned:
            j, mac_val = assigned[i]
            lam = complex(ss.eigenvalues[j])
            zeta = -lam.real / abs(lam)
            modes.append(Mode(i + 1, w / (2 * math.pi), False, zeta, lam.imag / (2 * math.pi), modal_zeta, lam, mac_val,
                              _normalise_shape(u), energy, eigen_index=j))
        else:
            modes.append(Mode(i + 1, w / (2 * math.pi), True, modal_zeta, float("nan"), modal_zeta, None, float("nan"),
                              _normalise_shape(u), energy, "rigid" if w == 0.0 else "mode"))
    return modes, ss, und


# --------------------------------------------------------------------------- drivetrain modes
def _element_groups(a: Assembly) -> tuple[list[str], np.ndarray]:
    """Names of mesh groups / shafts and the (n_group, n_mesh + n_shaft) membership matrix."""
    names: list[str] = []
    member = []
    for i, mesh in enumerate(a.meshes):
        g = f"{mesh.stage}.{mesh.kind}"
        if g not in names:
            names.append(g)
        member.append(names.index(g))
    for s in a.shafts:
        names.append(s.name)
        member.append(len(names) - 1)
    mat = np.zeros((len(names), len(member)))
    mat[member, np.arange(len(member))] = 1.0
    return names, mat


def _share_text(names: list[str], share: np.ndarray, cover: float = 0.9, at_most: int = 3) -> str:
    order = np.argsort(share)[::-1]
    parts, total = [], 0.0
    for j in order[:at_most]:
        parts.append(f"{names[j]} {100 * share[j]:.0f}%")
        total += share[j]
        if total >= cover:
            break
    return ", ".join(parts)


@dataclass(frozen=True)
class DrivetrainMode:
    """A mode of the linearised drivetrain, with names.

    Attributes
    ----------
    mode : Mode
        The generic mode (frequencies, damping, flags, shapes).
    kind : str
        ``"planet"`` (only the planets of ``stage`` move; multiplicity n - 1) or ``"rotational"``.
    stage : str or None
        The stage of a planet mode.
    shape_referred : ndarray, shape (n_dof,)
        Deviation angles referred to the rotor, ``q_i / kappa_i`` (a rigid rotation of the
        whole train is uniform), normalised to a largest component of +1.
    dominant_bodies : str
        Bodies holding most of the modal kinetic energy, e.g. ``"generator 100%"`` (the
        planets of a stage counted together as ``"stage1.planets"``).
    strain_energy_fraction : dict of str -> float
        Share of the modal strain energy per mesh group (``stage1.sun_planet``, ...) and shaft.
    dominant_elements : str
        The springs holding most of the modal strain energy.
    """

    mode: Mode
    kind: str
    stage: str | None
    shape_referred: np.ndarray
    dominant_bodies: str
    strain_energy_fraction: dict[str, float]
    dominant_elements: str

    def as_dict(self, dof_names: list[str]) -> dict:
        """Plain dict (JSON-ready)."""
        m = self.mode
        lam = m.eigenvalue
        return {
            "mode": m.index,
            "kind": self.kind,
            "stage": self.stage,
            "undamped_frequency_hz": m.undamped_frequency_hz,
            "damped_frequency_hz": None if m.overdamped else m.damped_frequency_hz,
            "damping_ratio": m.damping_ratio,
            "modal_damping_ratio": m.modal_damping_ratio,
            "overdamped": m.overdamped,
            "eigenvalue_per_s": None if lam is None else [lam.real, lam.imag],
            "dominant_bodies": self.dominant_bodies,
            "dominant_elements": self.dominant_elements,
            "kinetic_energy_fraction": dict(zip(dof_names, map(float, m.energy_fraction))),
            "strain_energy_fraction": dict(self.strain_energy_fraction),
            "shape": dict(zip(dof_names, map(float, m.shape))),
            "shape_referred": dict(zip(dof_names, map(float, self.shape_referred))),
        }


@dataclass(frozen=True)
class DrivetrainModalAnalysis:
    """Modal analysis of a drivetrain at an operating point (see :func:`drivetrain_modes`).

    Attributes
    ----------
    modes : list of DrivetrainMode
        In order of undamped natural frequency.
    model : LinearModel
        The linearisation (matrices, equilibrium, assembly).
    state_space : StateSpaceModes
        All ``2 n`` eigenvalues with right and left eigenvectors.
    """

    modes: list[DrivetrainMode]
    model: LinearModel
    state_space: StateSpaceModes

    @property
    def dof_names(self) -> list[str]:
        """Body names in state order."""
        return self.model.dof_names

    @property
    def underdamped(self) -> list[DrivetrainMode]:
        """The oscillatory modes."""
        return [m for m in self.modes if not m.mode.overdamped]

    @property
    def overdamped_roots_per_s(self) -> np.ndarray:
        """Decay rates ``-lambda`` of the real eigenvalues [1/s], ascending."""
        ss = self.state_space
        lam = ss.eigenvalues[~ss.is_complex()]
        return np.sort(-lam.real)

    def table_rows(self) -> list[dict]:
        """One flat row per mode (CSV-ready): frequencies, damping, flags, dominant bodies, referred shape."""
        rows = []
        for dm in self.modes:
            m = dm.mode
            row = {
                "mode": m.index,
                "kind": dm.kind if dm.stage is None else f"{dm.kind} ({dm.stage})",
                "undamped_frequency_hz": m.undamped_frequency_hz,
                "damped_frequency_hz": m.damped_frequency_hz,
                "damping_ratio": m.damping_ratio,
                "modal_damping_ratio": m.modal_damping_ratio,
                "overdamped": m.overdamped,
                "dominant_bodies": dm.dominant_bodies,
                "dominant_elements": dm.dominant_elements,
            }
            for name, x in zip(self.dof_names, dm.shape_referred):
                row[f"shape_referred[{name}]"] = float(x)
            rows.append(row)
        return rows

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready): operating point, equilibrium, modes, overdamped roots."""
        a = self.model.assembly
        eq = self.model.equilibrium
        return {
            "operating_point": self.model.operating_point.as_dict(),
            "dof_names": list(self.dof_names),
            "equilibrium": {
                "contact_force_n": dict(zip(a.mesh_names, map(float, eq.contact_force_n))),
                "mesh_stiffness_n_per_m": dict(zip(a.mesh_names, map(float, eq.mesh_stiffness_n_per_m))),
                "mesh_damping_ns_per_m": dict(zip(a.mesh_names, map(float, eq.mesh_damping_ns_per_m))),
                "shaft_torque_nm": dict(zip(a.shaft_names, map(float, eq.shaft_torque_nm))),
                "rotor_torque_nm": eq.rotor_torque_nm,
                "newton_iterations": eq.iterations,
            },
            "modes": [m.as_dict(self.dof_names) for m in self.modes],
            "n_underdamped": len(self.underdamped),
            "overdamped_roots_per_s": [float(x) for x in self.overdamped_roots_per_s],
        }


def drivetrain_modes(drivetrain: Drivetrain, operating_point: OperatingPoint, stiffness_factor: np.ndarray | float = 1.0) -> DrivetrainModalAnalysis:
    """Linearise a drivetrain at an operating point and analyse its modes.

    Parameters
    ----------
    drivetrain : Drivetrain
        E.g. ``table6_gearbox()``; a scenario supplies its drivetrain the same way.
    operating_point : OperatingPoint
        Rotor speed and output counter torque (e.g. ``OperatingPoint.from_rpm(16, 25.4e3)``
        or ``OperatingPoint.of_drivetrain(dt, omega)``).
    stiffness_factor : float or ndarray
        Mesh stiffness multiplier (1: mean stiffness).

    Returns
    -------
    DrivetrainModalAnalysis
    """
    model = linearise(drivetrain, operating_point, stiffness_factor)
    a = model.assembly
    modes, ss, und = modal_analysis(model.mass, model.damping, model.stiffness)
    names = model.dof_names
    roles = [a.bodies[j].role for j in a.free]
    stages = [a.bodies[j].stage for j in a.free]
    kappa = a.kinematic_ratio
    group_names, membership = _element_groups(a)
    body_groups = [f"{stages[i]}.planets" if roles[i] == "planet" else names[i] for i in range(len(names))]
    body_group_names = list(dict.fromkeys(body_groups))
    body_membership = np.array([[g == h for h in body_groups] for g in body_group_names], dtype=float)
    k_mesh = a.cos_alpha * model.equilibrium.mesh_stiffness_n_per_m
    k_elem = np.concatenate([k_mesh, a.shaft_k])
    rows = np.vstack([a.A, a.S])
    out = []
    for m, u in zip(modes, und.shapes.T):
        big = np.abs(u).max()
        moving = np.abs(u) > STILL_TOLERANCE * big
        planet_stages = {stages[i] for i in np.flatnonzero(moving)}
        if moving.any() and all(roles[i] == "planet" for i in np.flatnonzero(moving)) and len(planet_stages) == 1:
            kind, stage = "planet", planet_stages.pop()
        elif m.kind == "rigid":
            kind, stage = "rigid", None
        else:
            kind, stage = "rotational", None
        referred = _normalise_shape(u / kappa)
        strain = k_elem * (rows @ u) ** 2
        strain_share = membership @ strain / strain.sum() if strain.sum() > 0 else membership @ strain
        mode = replace(m, kind=kind)
        out.append(
            DrivetrainMode(
                mode=mode,
                kind=kind,
                stage=stage,
                shape_referred=referred,
                dominant_bodies=_share_text(body_group_names, body_membership @ m.energy_fraction),
                strain_energy_fraction=dict(zip(group_names, map(float, strain_share))),
                dominant_elements=_share_text(group_names, strain_share),
            )
        )
    return DrivetrainModalAnalysis(out, model, ss)


def two_inertia_frequency_hz(stiffness_nm_per_rad: float, inertia1_kgm2: float, inertia2_kgm2: float) -> float:
    """Closed-form natural frequency of two inertias on a torsional shaft [Hz].

    ``f = sqrt(k (J1 + J2) / (J1 J2)) / (2 pi)``.
    """
    k, j1, j2 = stiffness_nm_per_rad, inertia1_kgm2, inertia2_kgm2
    return math.sqrt(k * (j1 + j2) / (j1 * j2)) / (2.0 * math.pi)
