"""Gear contact laws: CFS (eq. 2-4) and the MSC.Adams-style impact law (eq. 1).

A mesh is described by :class:`MeshContact` (SI units). :class:`ContactLaw`
evaluates the normal contact force of *all* meshes of an assembly at once,
together with its derivatives with respect to deflection and deflection rate,
so the drivetrain can assemble an analytic Jacobian.

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
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .. import units
from ..validation import finite, in_range, non_negative, one_of, positive, set_fields

CONTACT_LAWS = ("cfs", "impact")
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


@dataclass(frozen=True)
class ContactLaw:
    """Vectorised contact law over a fixed set of meshes.

    Parameters
    ----------
    meshes : sequence of MeshContact
        One entry per mesh, in assembly order.
    """

    meshes: Sequence[MeshContact]
    _k: np.ndarray = field(init=False, repr=False)
    _e: np.ndarray = field(init=False, repr=False)
    _c: np.ndarray = field(init=False, repr=False)
    _lam: np.ndarray = field(init=False, repr=False)
    _half_jt: np.ndarray = field(init=False, repr=False)
    _impact: np.ndarray = field(init=False, repr=False)
    _dmax: np.ndarray = field(init=False, repr=False)
    _cmax: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        m = tuple(self.meshes)
        set_fields(
            self,
            meshes=m,
            _k=np.array([x.stiffness for x in m], dtype=float),
            _e=np.array([x.exponent for x in m], dtype=float),
            _c=np.array([x.damping for x in m], dtype=float),
            _lam=np.array([x.regularisation for x in m], dtype=float),
            _half_jt=np.array([0.5 * x.backlash_circumferential_m for x in m], dtype=float),
            _impact=np.array([x.law == "impact" for x in m], dtype=bool),
            _dmax=np.array([x.impact_depth_m for x in m], dtype=float),
            _cmax=np.array([x.impact_damping_max for x in m], dtype=float),
        )
        set_fields(self, _any_impact=bool(self._impact.any()), _all_impact=bool(self._impact.all()))
        # stacked (2, n_mesh) constants for the derivative-free fast path
        set_fields(
            self,
            _pm_half_jt=np.vstack([-self._half_jt, self._half_jt]),
            _lam2=np.vstack([self._lam, self._lam]),
            _sqrt_law=bool(np.all(self._e == 1.5)),
            # |delta| beyond which tanh(lambda (|delta| -+ j_t/2)) == 1 in double precision
            _deep=self._half_jt + 20.0 / self._lam,
            _zeros=np.zeros(len(m)),  # clipping bound (an array operand is cheaper than the scalar 0)
        )

    @property
    def size(self) -> int:
        """Number of meshes."""
        return len(self.meshes)

    def backlash_deflection(self, deflection: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Regularised indentation d_BL of eq. 3-4 and its first two derivatives.

        Parameters
        ----------
        deflection : ndarray, shape (..., n_mesh)
            Linearised tooth distance delta [m] at the pitch radius.

        Returns
        -------
        d_bl, d_bl_prime, d_bl_second : ndarray
            d_BL [m], d d_BL / d delta [-], d^2 d_BL / d delta^2 [1/m].
        """
        h = self._half_jt
        abs_d = np.abs(deflection)
        if not np.count_nonzero(abs_d < self._deep):  # all deep in flank contact: tanh saturated exactly
            flank = np.sign(deflection)
            return deflection - flank * h, np.ones_like(abs_d), np.zeros_like(abs_d)
        lam = self._lam
        x1 = deflection - h
        x2 = deflection + h
        u1 = lam * x1
        u2 = lam * x2
        t1 = np.tanh(u1)
        t2 = np.tanh(u2)
        d_bl = deflection + 0.5 * (x1 * t1 - x2 * t2)  # eq. 3, 4
        s1 = 1.0 - t1 * t1
        s2 = 1.0 - t2 * t2
        d_bl_prime = 1.0 + 0.5 * (t1 + u1 * s1 - t2 - u2 * s2)
        d_bl_second = lam * (s1 * (1.0 - u1 * t1) - s2 * (1.0 - u2 * t2))
        return d_bl, d_bl_prime, d_bl_second

    def hard_backlash(self, deflection: np.ndarray) -> np.ndarray:
        """Penetration with a sharp backlash: 0 inside ``|delta| < j_t/2`` [m]."""
        h = self._half_jt
        return np.where(deflection > h, deflection - h, np.where(deflection < -h, deflection + h, 0.0))

    def evaluate(
        self,
        deflection: np.ndarray,
        rate: np.ndarray,
        stiffness_factor: np.ndarray | float = 1.0,
    ) -> ContactForces:
        """Contact forces of all meshes.

        Parameters
        ----------
        deflection : ndarray, shape (..., n_mesh)
            Deflection delta [m] (eq. 8, 10), positive when the flank loaded in
            normal power flow is compressed.
        rate : ndarray, shape (..., n_mesh)
            Deflection rate [m/s].
        stiffness_factor : ndarray or float
            Multiplier on k0 (time-varying mesh stiffness); 1 for the paper's model.

        Returns
        -------
        ContactForces
        """
        k = self._k if type(stiffness_factor) is float and stiffness_factor == 1.0 else self._k * stiffness_factor
        e = self._e
        if self._all_impact:
            return self._impact_law(deflection, rate, k)
        d_bl, d_bl_p, d_bl_pp = self.backlash_deflection(deflection)
        abs_bl = np.abs(d_bl)
        sgn = np.sign(d_bl)
        pow_em1 = abs_bl ** (e - 1.0)
        elastic = k * sgn * pow_em1 * abs_bl  # k0 sgn(d_BL) |d_BL|^e (eq. 2)
        d_elastic = k * e * pow_em1
        rate_bl = d_bl_p * rate
        c = self._c
        damping = c * abs_bl * rate_bl  # c0 |d_BL| d_BL_dot (eq. 2, 9)
        force = elastic + damping
        dF_dd = (d_elastic + c * sgn * rate_bl) * d_bl_p + c * abs_bl * d_bl_pp * rate
        dF_dv = c * abs_bl * d_bl_p
        # flank-consistent clipping: a flank pushes, never pulls (see module docstring)
        active = force * np.sign(deflection) > 0.0
        force = np.where(active, force, 0.0)
        dF_dd = np.where(active, dF_dd, 0.0)
        dF_dv = np.where(active, dF_dv, 0.0)
        if self._any_impact:
            imp = self._impact_law(deflection, rate, k)
            sel = self._impact
            force = np.where(sel, imp.force, force)
            dF_dd = np.where(sel, imp.d_force_d_deflection, dF_dd)
            dF_dv = np.where(sel, imp.d_force_d_rate, dF_dv)
            elastic = np.where(sel, imp.elastic, elastic)
        return ContactForces(force, dF_dd, dF_dv, elastic)

    def force_and_elastic(
        self, deflection: np.ndarray, rate: np.ndarray, stiffness_factor: np.ndarray | float = 1.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Contact force [N] and its elastic part [N] at one or many states, without derivatives.

        The same numbers as ``evaluate(...).force`` and ``evaluate(...).elastic`` (same
        operations in the same order) for callers that need no Jacobian: the monolithic
        right-hand side and the evaluation of recorded results.

        Parameters
        ----------
        deflection, rate : ndarray, shape (..., n_mesh)
            Deflection [m] and its rate [m/s].
        stiffness_factor : ndarray or float
            Multiplier on k0.
        """
        if self._any_impact:
            cf = self.evaluate(deflection, rate, stiffness_factor)
            return cf.force, cf.elastic
        k = self._k * stiffness_factor
        d_bl, d_bl_p, _ = self.backlash_deflection(deflection)
        abs_bl = np.abs(d_bl)
        sgn = np.sign(d_bl)
        pow_em1 = np.sqrt(abs_bl) if self._sqrt_law else abs_bl ** (self._e - 1.0)
        elastic = k * sgn * pow_em1 * abs_bl  # eq. 2
        force = elastic + self._c * abs_bl * (d_bl_p * rate)  # eq. 2, 9
        return np.where(force * np.sign(deflection) > 0.0, force, 0.0), elastic  # flank-consistent clipping

    def force(self, deflection: np.ndarray, rate: np.ndarray, stiffness_factor: np.ndarray | float = 1.0) -> np.ndarray:
        """Contact forces only (no derivatives) for one state, shape (n_mesh,) [N].

        Same values as ``evaluate(...).force``; written with few numpy calls
        because it sits on the co-simulation hot path.
        """
        if self._any_impact:
            return self.evaluate(deflection, rate, stiffness_factor).force
        abs_d = np.abs(deflection)
        # (count_nonzero: the same test as .any(), without the reduction machinery)
        if self._sqrt_law and not np.count_nonzero(abs_d < self._deep):
            # every mesh deep in flank contact: d_BL = delta - sgn(delta) j_t/2 and d d_BL/d delta = 1 exactly.
            # Here delta != 0, so sgn(delta) = +-1 and, c0 and the clipped force being >= 0, the products
            # c0 sgn(delta) and sgn(delta) max(., 0) are exactly copysign(., delta) (one numpy call less)
            pen = abs_d - self._half_jt
            k = self._k if type(stiffness_factor) is float and stiffness_factor == 1.0 else self._k * stiffness_factor
            signed = pen * (k * np.sqrt(pen) + np.copysign(self._c, deflection) * rate)
            return np.copysign(np.maximum(signed, self._zeros), deflection)
        d_bl, rate_bl = self._regularised(deflection, rate)
        abs_bl = np.abs(d_bl)
        sgn = np.sign(d_bl)
        root = np.sqrt(abs_bl) if self._sqrt_law else abs_bl ** (self._e - 1.0)
        flank = np.sign(deflection)
        signed = flank * abs_bl * (self._k * stiffness_factor * sgn * root + self._c * rate_bl)  # sgn(delta) * eq. 2
        return flank * np.maximum(signed, self._zeros)  # flank-consistent clipping

    def stiffness_sensitivity(
        self, deflection: np.ndarray, rate: np.ndarray, stiffness_factor: np.ndarray | float = 1.0
    ) -> np.ndarray:
        """``dF / d(stiffness factor)`` of every mesh at one state [N], shape (n_mesh,).

        The force is linear in the stiffness multiplier ``f`` on ``k0`` (time-varying
        mesh stiffness) wherever the flank is in contact, ``dF/df = k0 sgn(d_BL)
        |d_BL|^e``, and 0 where the flank-consistent clipping applies.

        Parameters
        ----------
        deflection, rate : ndarray, shape (n_mesh,)
            Deflection [m] and its rate [m/s].
        stiffness_factor : ndarray or float
            Current multiplier f [-] (decides which meshes are clipped).
        """
        if self._any_impact or not self._sqrt_law:
            cf = self.evaluate(deflection, rate, stiffness_factor)
            return np.where(cf.force != 0.0, cf.elastic / stiffness_factor, 0.0)
        d_bl, rate_bl = self._regularised(deflection, rate)
        abs_bl = np.abs(d_bl)
        elastic = self._k * np.sign(d_bl) * abs_bl * np.sqrt(abs_bl)  # per unit stiffness factor
        flank = np.sign(deflection)
        active = flank * (elastic * stiffness_factor + self._c * abs_bl * rate_bl) > 0.0
        return np.where(active, elastic, 0.0)

    def _regularised(self, deflection: np.ndarray, rate: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Backlash-regularised deflection d_BL [m] (eq. 3, 4) and its rate [m/s], shapes (n_mesh,).

        The two tanh terms (delta -/+ j_t / 2) are evaluated as the rows of one array.
        """
        X = deflection + self._pm_half_jt  # rows: delta - j_t/2, delta + j_t/2
        U = X * self._lam2
        T = np.tanh(U)
        XT = X * T
        UST = U * (1.0 - T * T) + T  # d(X tanh(lambda X))/dX, per row
        return deflection + 0.5 * (XT[0] - XT[1]), (1.0 + 0.5 * (UST[0] - UST[1])) * rate

    def _impact_law(self, deflection: np.ndarray, rate: np.ndarray, k: np.ndarray) -> ContactForces:
        """Eq. 1 with a sharp backlash and the cubic STEP damping of MSC.Adams."""
        p = self.hard_backlash(deflection)
        abs_p = np.abs(p)
        sgn = np.sign(p)
        e = self._e
        pow_em1 = abs_p ** (e - 1.0)
        elastic = k * sgn * pow_em1 * abs_p
        s = np.clip(abs_p / self._dmax, 0.0, 1.0)
        step = self._cmax * s * s * (3.0 - 2.0 * s)  # STEP(p, 0, 0, d_max, c_max)
        d_step = self._cmax * 6.0 * s * (1.0 - s) / self._dmax
        force = elastic + step * rate
        dF_dd = k * e * pow_em1 + d_step * sgn * rate
        dF_dv = step
        active = force * sgn > 0.0
        return ContactForces(
            np.where(active, force, 0.0),
            np.where(active, dF_dd, 0.0),
            np.where(active, dF_dv, 0.0),
            elastic,
        )

    def potential_energy(self, deflection: np.ndarray, nodes: int = 64) -> np.ndarray:
        """Elastic energy stored in each mesh, ``V = int_0^delta F_el d delta`` [N m].

        Multiply by ``cos(alpha)`` to get the energy of the generalised forces
        (the moment arm is the base radius). Integrated by Gauss-Legendre
        quadrature on the pieces between 0, the backlash edges and ``delta``,
        vectorised over all meshes.

        Parameters
        ----------
        deflection : ndarray, shape (n_mesh,)
            Deflection [m].
        nodes : int
            Gauss-Legendre nodes per piece.

        Returns
        -------
        ndarray, shape (n_mesh,)
        """
        d = np.asarray(deflection, dtype=float)
        x, w = np.polynomial.legendre.leggauss(nodes)
        h = self._half_jt
        # pieces [0, min(|d|, h)] and [min(|d|, h), |d|] on the side of d (an edge is a kink)
        s = np.where(d < 0.0, -1.0, 1.0)
        edge = s * np.minimum(np.abs(d), h)
        total = np.zeros(self.size)
        for a, b in ((np.zeros_like(d), edge), (edge, d)):
            mid, half = 0.5 * (a + b), 0.5 * (b - a)
            pts = mid + np.outer(x, half)  # (nodes, n_mesh)
            f = self.evaluate(pts, np.zeros_like(pts)).elastic
            total += half * (w @ f)
        return total
