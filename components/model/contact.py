"""Gear contact: the parameters of a mesh (:class:`MeshContact`, SI) and the laws evaluated over many states.

The laws themselves - CFS (eq. 2-4) and the MSC.Adams-style impact law (eq. 1) - are written
once, in :mod:`components.model.kernel.contact`; :func:`contact_table` turns the meshes'
parameters into the rows that code reads, and :class:`ContactLaw` evaluates it for arrays of
states (analyses, the energy audit, tests), compiled or interpreted like every kernel.

Sign of the contact force
-------------------------
A flank can push, never pull, so the force of a mesh must have the sign of the
flank the teeth are nearer to, ``sgn(delta)``. Eq. 2-4 violate this in two
places, which dtcosim handles by clipping ("flank-consistent clipping"):
``F = sgn(delta) max(0, sgn(delta) F_raw)``.

1. The damping term: while teeth separate quickly, ``c0 |d_BL| d_BL_dot`` can
   exceed the elastic term and the total force would change sign within one
   flank contact; the paper warns about exactly this (Sec. 2.2).
2. The regularisation itself: ``x tanh(lambda x)`` under-estimates ``|x|`` near
   ``x = 0``, so ``d_BL`` of eq. 3 dips to ``-0.139/lambda`` just *inside* each
   backlash edge (at ``0.64/lambda`` from it; -0.014 mm for lambda = 10/mm, an
   82 N pull with the Table 3 stiffness) and the flank would pull the teeth
   back across the gap.
   Left alone, this glues lightly loaded teeth to the flank and suppresses the
   backlash traversal of Fig. 10-11.

The clipped force is continuous in the state (it passes through zero), so
implicit integrators keep converging; its derivatives are those of the active
branch (zero on the clipped branch). The impact law is clipped the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .. import units
from ..validation import finite, in_range, non_negative, one_of, positive, set_fields
from . import kernel
from .kernel.contact import (
    CMAX, DAMPING, DEEP, DMAX, EXPONENT, HALF_JT, K0, LAMBDA, LAW, LAW_DESCRIPTIONS, LAWS, N_CONTACT_COLUMNS,
)

#: the contact laws by name, in the order of their codes in the kernel's contact table, and what each is
CONTACT_LAWS = LAWS
CONTACT_LAW_DESCRIPTIONS = LAW_DESCRIPTIONS
#: Contact-force magnitude below which a mesh counts as "inside the backlash" (out of contact) [N].
CONTACT_LOSS_THRESHOLD_N = 1.0


@dataclass(frozen=True)
class MeshContact:
    """Contact parameters of one gear mesh, SI units.

    Parameters
    ----------
    stiffness : float
        Hertzian contact stiffness k0 [N/m^e] (eq. 1, 2).
    exponent : float
        Force exponent e [-], 3/2 for Hertzian contact.
    damping : float
        CFS contact damping c0 [N s/m^2]; damping coefficient is ``c0 |d_BL|`` (eq. 9).
    regularisation : float
        Backlash regularisation factor lambda [1/m] (eq. 4).
    backlash_normal_m : float
        Linear (normal) backlash j_n [m]; the circumferential backlash is
        ``j_t = j_n / cos(alpha)``.
    pressure_angle_rad : float
        Pressure angle alpha [rad]; forces act on the base radius ``r cos(alpha)``.
    law : {"cfs", "impact"}
        Contact law: CFS (eq. 2 with the tanh backlash of eq. 3-4) or "impact"
        (eq. 1: same stiffness term, damping ``STEP(p, 0, 0, d_max, c_max) p_dot`` with
        the cubic STEP of MSC.Adams and a sharp backlash).
    impact_depth_m : float
        Penetration d_max [m] at which the impact damping reaches c_max (Table 3: 0.1 mm).
    impact_damping : float or None
        Maximum impact damping c_max [N s/m]. ``None`` means ``c0 * d_max``, so that
        both laws have the same damping coefficient at full penetration.
    contact_ratio : float
        Transverse contact ratio epsilon [-] (Table 1: 1.62 sun-planet); used only by
        the time-varying mesh stiffness option.
    stiffness_variation : float
        Relative amplitude of time-varying mesh stiffness [-]: 0 (default) keeps the
        paper's constant stiffness. See :mod:`components.model.mesh_stiffness`.
    """

    stiffness: float
    exponent: float = 1.5
    damping: float = 0.0
    regularisation: float = 1.0e4
    backlash_normal_m: float = 0.0
    pressure_angle_rad: float = math.radians(20.0)
    law: str = "cfs"
    impact_depth_m: float = 1.0e-4
    impact_damping: float | None = None
    contact_ratio: float = 1.62
    stiffness_variation: float = 0.0

    def __post_init__(self) -> None:
        set_fields(
            self,
            stiffness=positive("stiffness", self.stiffness),
            exponent=in_range("exponent", self.exponent, 1.0, 3.0),
            damping=non_negative("damping", self.damping),
            regularisation=positive("lambda", self.regularisation),
            backlash_normal_m=non_negative("backlash", self.backlash_normal_m),
            pressure_angle_rad=in_range("pressure_angle_rad", self.pressure_angle_rad, 0.0, 0.5 * math.pi - 1e-6),
            law=one_of("law", self.law, CONTACT_LAWS),
            impact_depth_m=positive("impact_depth_m", self.impact_depth_m),
            contact_ratio=in_range("contact_ratio", self.contact_ratio, 1.0, 10.0),
            stiffness_variation=in_range("stiffness_variation", self.stiffness_variation, 0.0, 0.9),
        )
        if self.impact_damping is not None:
            set_fields(self, impact_damping=non_negative("impact_damping", self.impact_damping))

    @classmethod
    def from_paper(
        cls,
        k0_n_per_mm_e: float,
        c0_ns_per_mm2: float,
        lambda_per_mm: float,
        backlash_mm: float,
        pressure_angle_deg: float = 20.0,
        exponent: float = 1.5,
        **kwargs,
    ) -> "MeshContact":
        """Build from the paper's units (Tables 3, 5, 6).

        Parameters
        ----------
        k0_n_per_mm_e : float
            Contact stiffness [N/mm^e].
        c0_ns_per_mm2 : float
            Contact damping [N s/mm^2] (the tables print N s/mm; c = c0 |delta|).
        lambda_per_mm : float
            Regularisation factor [1/mm].
        backlash_mm : float
            Linear backlash j_n [mm].
        pressure_angle_deg : float
            Pressure angle [deg].
        """
        e = in_range("exponent", exponent, 1.0, 3.0)
        return cls(
            stiffness=units.contact_stiffness(positive("k0", k0_n_per_mm_e), e),
            exponent=e,
            damping=units.contact_damping(non_negative("c0", c0_ns_per_mm2)),
            regularisation=units.regularisation(positive("lambda", lambda_per_mm)),
            backlash_normal_m=units.mm(non_negative("backlash", backlash_mm)),
            pressure_angle_rad=math.radians(finite("pressure_angle_deg", pressure_angle_deg)),
            **kwargs,
        )

    @property
    def backlash_circumferential_m(self) -> float:
        """Circumferential backlash j_t = j_n / cos(alpha) [m] (eq. 4)."""
        return self.backlash_normal_m / math.cos(self.pressure_angle_rad)

    @property
    def impact_damping_max(self) -> float:
        """c_max [N s/m] used by the impact law."""
        if self.impact_damping is None:
            return self.damping * self.impact_depth_m
        return self.impact_damping


def contact_table(meshes: Sequence[MeshContact]) -> np.ndarray:
    """The kernel's contact table: one row per mesh (columns of :mod:`components.model.kernel.contact`), shape (m, 9)."""
    table = np.zeros((len(meshes), N_CONTACT_COLUMNS))
    for row, mesh in zip(table, meshes):
        half_jt = 0.5 * mesh.backlash_circumferential_m
        row[K0] = mesh.stiffness
        row[EXPONENT] = mesh.exponent
        row[DAMPING] = mesh.damping
        row[LAMBDA] = mesh.regularisation
        row[HALF_JT] = half_jt
        row[LAW] = CONTACT_LAWS.index(mesh.law)
        row[DMAX] = mesh.impact_depth_m
        row[CMAX] = mesh.impact_damping_max
        row[DEEP] = half_jt + 20.0 / mesh.regularisation  # |d| beyond which tanh(lambda (|d| -+ j_t/2)) == 1
    return table


@dataclass(frozen=True)
class ContactForces:
    """Forces of all meshes and their partial derivatives, each shape ``(..., n_mesh)``.

    Attributes
    ----------
    force : ndarray
        Normal contact force F [N], positive on the flank loaded in normal power flow.
    d_force_d_deflection : ndarray
        dF/dd [N/m].
    d_force_d_rate : ndarray
        dF/d(d_dot) [N s/m].
    elastic : ndarray
        Elastic part of the force (before clipping) [N]; used by the energy audit.
    """

    force: np.ndarray
    d_force_d_deflection: np.ndarray
    d_force_d_rate: np.ndarray
    elastic: np.ndarray


class ContactLaw:
    """The contact laws of a fixed set of meshes, evaluated over arrays of states.

    Parameters
    ----------
    meshes : sequence of MeshContact
        One entry per mesh, in assembly order.
    kernel : {"auto", "numpy", "compiled"}, optional
        Form of the kernel that evaluates it (:func:`components.model.kernel.monolithic`).

    Attributes
    ----------
    table : ndarray, shape (n_mesh, 9)
        The kernel's contact table (:func:`contact_table`).
    """

    def __init__(self, meshes: Sequence[MeshContact], kernel: str | None = None) -> None:
        self.meshes = tuple(meshes)
        self.table = contact_table(self.meshes)
        self._kernel = kernel

    @property
    def size(self) -> int:
        """Number of meshes."""
        return len(self.meshes)

    def _many(self, evaluations: int) -> object:
        return kernel.monolithic(self._kernel, brief=evaluations <= kernel.BRIEF_EVALUATIONS)[0]

    def evaluate(self, deflection: np.ndarray, rate: np.ndarray,
                 stiffness_factor: np.ndarray | float = 1.0) -> ContactForces:
        """Contact forces of all meshes and their derivatives.

        Parameters
        ----------
        deflection : ndarray, shape (..., n_mesh)
            Deflection delta [m] (eq. 8, 10), positive when the flank loaded in
            normal power flow is compressed.
        rate : ndarray, shape (..., n_mesh)
            Deflection rate [m/s].
        stiffness_factor : ndarray or float
            Multiplier on k0 (time-varying mesh stiffness); 1 for the paper's model.
        """
        d, r, f = np.broadcast_arrays(np.asarray(deflection, dtype=float), np.asarray(rate, dtype=float),
                                      np.asarray(stiffness_factor, dtype=float))
        shape = d.shape
        # copies: a broadcast view is read-only in future numpy, and numba warns about it when it compiles
        flat = [np.array(x, dtype=float, order="C").reshape(-1, self.size) for x in (d, r, f)]
        out = [np.empty_like(flat[0]) for _ in range(4)]
        self._many(flat[0].size).contact_forces_many(*flat, self.table, *out)
        return ContactForces(*(o.reshape(shape) for o in out))

    def force_and_elastic(self, deflection: np.ndarray, rate: np.ndarray,
                          stiffness_factor: np.ndarray | float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """Contact force [N] and its elastic part [N] (as :meth:`evaluate`)."""
        cf = self.evaluate(deflection, rate, stiffness_factor)
        return cf.force, cf.elastic

    def backlash_deflection(self, deflection: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Regularised indentation d_BL [m] of eq. 3-4 and its first two derivatives [-], [1/m], shape (..., n_mesh)."""
        d = np.ascontiguousarray(np.broadcast_to(np.asarray(deflection, dtype=float), np.shape(deflection)))
        flat = d.reshape(-1, self.size)
        out = [np.empty_like(flat) for _ in range(3)]
        self._many(flat.size).regularised_many(flat, self.table, *out)
        return tuple(o.reshape(d.shape) for o in out)

    def potential_energy(self, deflection: np.ndarray, nodes: int = 64) -> np.ndarray:
        """Elastic energy stored in each mesh, ``V = int_0^delta F_el d delta`` [N m], shape (n_mesh,).

        Multiply by ``cos(alpha)`` to get the energy of the generalised forces (the moment arm is
        the base radius). Integrated by Gauss-Legendre quadrature on the pieces between 0, the
        backlash edges and ``delta`` (an edge is a kink), vectorised over all meshes.
        """
        d = np.asarray(deflection, dtype=float)
        x, w = np.polynomial.legendre.leggauss(nodes)
        h = self.table[:, HALF_JT]
        s = np.where(d < 0.0, -1.0, 1.0)
        edge = s * np.minimum(np.abs(d), h)
        total = np.zeros(self.size)
        for a, b in ((np.zeros_like(d), edge), (edge, d)):
            mid, half = 0.5 * (a + b), 0.5 * (b - a)
            pts = mid + np.outer(x, half)  # (nodes, n_mesh)
            f = self.evaluate(pts, np.zeros_like(pts)).elastic
            total += half * (w @ f)
        return total
