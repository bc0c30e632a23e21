"""Modes of a linear mechanical system ``M q'' + C q' + K q = 0`` (any ``M, C, K``).

* :func:`undamped_modes` - the symmetric generalised eigenproblem ``K u = omega^2 M u``.
* :func:`state_space_modes` - eigenvalues ``lambda`` and right/left eigenvectors of the
  first-order system ``x' = [[0, I], [-M^-1 K, -M^-1 C]] x``.
* :func:`modal_analysis` - both, matched mode by mode (mass-weighted MAC between the
  undamped shape and the displacement part of each complex pair), with damping
  ratios, damped frequencies and an overdamped flag per mode.

scipy (``scipy.linalg``, ``scipy.optimize``: ~0.3 s of imports) is imported by the
functions that use it, so :func:`state_space_matrix` (what a run's settling time needs,
:func:`components.analysis.settling.drivetrain_settling`) costs numpy alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError

#: |Im lambda| / |lambda| below which an eigenvalue counts as real (overdamped root).
REAL_EIGENVALUE_TOLERANCE = 1e-7


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
    import scipy.linalg

    m = _as_matrix("mass", mass)
    k = _as_matrix("stiffness", stiffness, m.shape[0])
    for name, x in (("mass", m), ("stiffness", k)):
        if np.abs(x - x.T).max() > 1e-9 * max(np.abs(x).max(), 1e-300):
            raise ParameterError(name, "asymmetric", "a symmetric matrix")
    try:
        w2, u = scipy.linalg.eigh(0.5 * (k + k.T), 0.5 * (m + m.T))
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
    import scipy.linalg

    a = state_space_matrix(mass, damping, stiffness)
    lam, right = scipy.linalg.eig(a)
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
        The undamped natural frequency of the matched eigenvalue, ``|lambda| / (2 pi)`` [Hz], so that a
        row's undamped and damped frequency belong to one eigenvalue (``Im lambda <= |lambda|``: the
        damped frequency never exceeds it); for an overdamped mode, from ``K u = omega^2 M u``.
    system_frequency_hz : float
        From ``K u = omega^2 M u``: the frequency of the undamped system's mode whose shape this row shows
        [Hz] (equal to the above for proportional damping).
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
    system_frequency_hz: float = float("nan")


def normalise_shape(u: np.ndarray) -> np.ndarray:
    j = int(np.argmax(np.abs(u)))
    return u / u[j] if u[j] != 0 else u


def modal_analysis(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray) -> tuple[list[Mode], StateSpaceModes, UndampedModes]:
    """Undamped and damped modes of ``M q'' + C q' + K q = 0``, matched mode by mode.

    Every complex eigenvalue pair (``Im lambda > 0``) is assigned one-to-one to an undamped
    mode, minimising the sum over pairs of ``|ln(|lambda| / omega)| - MAC`` (mass-weighted
    MAC of the shapes): close in frequency first - the modes of a planetary stage come in
    groups of equal or nearly equal frequency whose shapes alone do not tell them apart -
    then alike in shape. Each row reports its eigenvalue's ``|lambda|`` as the undamped and
    ``Im lambda`` as the damped frequency (never above it); undamped modes without a pair are
    overdamped. Rows are ordered by undamped frequency. Real eigenvalues (the overdamped
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
        magnitude = np.abs(ss.eigenvalues[osc])
        with np.errstate(divide="ignore"):
            distance = np.abs(np.log(magnitude[None, :] / und.omega_rad_s[:, None]))
        distance[~np.isfinite(distance)] = 1e6  # a rigid-body mode takes no oscillating eigenvalue
        from scipy.optimize import linear_sum_assignment

        rows, cols = linear_sum_assignment(distance - mac)
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
            modes.append(Mode(i + 1, abs(lam) / (2 * math.pi), False, zeta, lam.imag / (2 * math.pi), modal_zeta, lam,
                              mac_val, normalise_shape(u), energy, eigen_index=j, system_frequency_hz=w / (2 * math.pi)))
        else:
            modes.append(Mode(i + 1, w / (2 * math.pi), True, modal_zeta, float("nan"), modal_zeta, None, float("nan"),
                              normalise_shape(u), energy, "rigid" if w == 0.0 else "mode",
                              system_frequency_hz=w / (2 * math.pi)))
    modes.sort(key=lambda mode: mode.undamped_frequency_hz)
    modes = [replace(mode, index=k + 1) for k, mode in enumerate(modes)]
    return modes, ss, und
