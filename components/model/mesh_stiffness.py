"""Time-varying mesh stiffness: the number of tooth pairs in contact changes at the mesh frequency.

Model
-----
A spur mesh with transverse contact ratio ``epsilon`` (Table 1: epsilon_SP = 1.62)
has ``ceil(epsilon)`` tooth pairs in contact during a fraction
``p = epsilon - floor(epsilon)`` of every mesh cycle and ``floor(epsilon)`` pairs
during the rest. The mesh cycle is one base pitch: one tooth pair passing, phase
``2 pi`` per cycle. Phase 0 is the instant a new pair enters contact, so the
``ceil(epsilon)``-pair zone is ``[0, 2 pi p)`` of every cycle.

The contact law's stiffness ``k0`` (eq. 2) is multiplied by

    f(phase) = 1 + v (r(phase) - p),

where ``r`` is the indicator of the ``ceil(epsilon)``-pair zone (smoothed, below)
and ``v`` is :attr:`MeshContact.stiffness_variation`. The mean of ``f`` over a mesh
cycle is exactly 1, so the paper's mean stiffness - and with it Table 7's mean
forces - stands. The definition of ``v``:

    v = (k_max - k_min) / k_mean,

the peak-to-peak stiffness variation relative to the mean
(``k_max = k_mean (1 + v (1 - p))``, ``k_min = k_mean (1 - v p)``). ``v = 1 /
epsilon`` is the stiffness proportional to the number of pairs in contact (every
pair as stiff as the others); measured spur-gear mesh stiffness usually varies
less than that because the single pair is stiffest in the middle of its path. ``v =
0`` (the default) switches the option off. An integer contact ratio (``p = 0``)
gives a constant number of pairs and ``f = 1``.

Smoothing
---------
The sharp switch between pair counts is replaced, at each of the two edges per
cycle, by the quintic "smootherstep" ``6 s^5 - 15 s^4 + 10 s^3`` over a width of
``w`` mesh cycles centred on the edge (``w = TRANSITION_FRACTION = 0.05`` by
default: 0.12 ms at the stage-3 mesh frequency of 427 Hz at 16 rpm). The ramp is
point-symmetric about the edge, so the mean is unchanged; it is twice continuously
differentiable, so an implicit integrator with error control does not have to
resolve a jump. ``w`` is clipped to ``min(p, 1 - p)`` so that the two ramps never
overlap.

Phasing
-------
:class:`~components.model.assembly.Assembly` gives each mesh a phase rate (mesh-cycle
radians per radian of rotor rotation: ``Z_ring`` x carrier ratio for both meshes
of a planet, ``Z_drive`` x drive ratio for a parallel mesh) and an offset for
sequential planet phasing (Parker and Lin, 2004): planet ``i`` at carrier angle
``psi_i = 2 pi (i - 1) / n`` (numbered in the direction of rotation) has sun-mesh
offset ``-Z_sun psi_i`` and ring-mesh offset ``+Z_ring psi_i``. The offset between
the sun and ring mesh of the same planet depends on tooth details the paper does
not give; it is taken as 0. See ``docs/analyses.md`` for the check of these offsets.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from . import kernel as model_kernel
from .kernel.stiffness import CYCLE0, CYCLES_PER_RAD, HALF_P, INV_W, N_PHASING_ROWS, SLOPE_SCALE, VARIATION, VP

#: Width of each smoothed transition between pair counts, as a fraction of one mesh cycle [-].
TRANSITION_FRACTION = 0.05


def pair_fraction(contact_ratio: float | np.ndarray) -> np.ndarray:
    """Fraction ``p = epsilon - floor(epsilon)`` of a mesh cycle with ``ceil(epsilon)`` pairs [-].

    Parameters
    ----------
    contact_ratio : float or ndarray
        Transverse contact ratio epsilon [-], >= 1.
    """
    eps = np.asarray(contact_ratio, dtype=float)
    if np.any(~np.isfinite(eps)) or np.any(eps < 1.0):
        raise ParameterError("contact_ratio", contact_ratio, ">= 1 (finite)")
    p = eps - np.floor(eps)
    return np.where(p < 1e-12, 0.0, p)


def multi_pair_indicator(
    phase_rad: np.ndarray, contact_ratio: float | np.ndarray, transition: float = TRANSITION_FRACTION
) -> np.ndarray:
    """Smoothed indicator of the ``ceil(epsilon)``-pair zone of the mesh cycle [-].

    Parameters
    ----------
    phase_rad : ndarray, shape (..., n_mesh)
        Mesh-cycle phase [rad] (``2 pi`` per tooth pair passing); any real value.
    contact_ratio : float or ndarray, shape broadcastable to (..., n_mesh)
        Contact ratio epsilon [-].
    transition : float
        Transition width [mesh cycles], in (0, 0.5]; clipped to ``min(p, 1 - p)``.

    Returns
    -------
    ndarray
        1 inside ``[0, 2 pi p)`` (mod ``2 pi``), 0 outside, smooth ramps of width
        ``transition`` centred on the two edges; mean over a cycle exactly ``p``
        (``f - 1 + p`` of :func:`stiffness_factor` with ``v = 1``).
    """
    phase = np.asarray(phase_rad, dtype=float)
    p = np.broadcast_to(pair_fraction(contact_ratio), phase.shape[-1:] if phase.ndim else ())
    return _factor_by_phase(phase, contact_ratio, 1.0, transition, True) - 1.0 + p


def stiffness_factor(
    phase_rad: np.ndarray,
    contact_ratio: float | np.ndarray,
    variation: float | np.ndarray,
    transition: float = TRANSITION_FRACTION,
) -> np.ndarray:
    """Multiplier of the contact stiffness ``k0`` at a mesh-cycle phase [-].

    ``f = 1 + v (r(phase) - p)`` with ``r`` the smoothed indicator of the multi-pair zone; the
    cycle mean of ``f`` is 1 and its peak-to-peak value is ``v`` (module docstring). Evaluated
    by the kernel (:func:`components.model.kernel.stiffness.stiffness_factors`), one mesh per
    column with a phase rate of 1 rad/rad.

    Parameters
    ----------
    phase_rad : ndarray, shape (..., n_mesh)
        Mesh-cycle phase of every mesh [rad] (``2 pi`` per tooth pair passing).
    contact_ratio : float or ndarray, shape broadcastable to (..., n_mesh)
        Contact ratio epsilon [-] (Table 1: 1.62 sun-planet).
    variation : float or ndarray, shape broadcastable to (..., n_mesh)
        Peak-to-peak stiffness variation relative to the mean, ``(k_max - k_min) /
        k_mean`` [-], in [0, 1 / p) so that the stiffness stays positive (1 is allowed for
        :func:`multi_pair_indicator`).
    transition : float
        Width of each smoothed transition [mesh cycles].

    Returns
    -------
    ndarray, shape (..., n_mesh)
        Stiffness multiplier (1 where ``variation`` is 0).
    """
    return _factor_by_phase(phase_rad, contact_ratio, variation, transition, False)


def _factor_by_phase(phase_rad, contact_ratio, variation, transition: float, allow_unit_variation: bool) -> np.ndarray:
    """:func:`stiffness_factor`, optionally with ``v`` up to 1 (:func:`multi_pair_indicator`)."""
    phase = np.atleast_1d(np.asarray(phase_rad, dtype=float))
    m = phase.shape[-1]
    columns = np.broadcast_to(np.asarray(contact_ratio, dtype=float), (m,)), \
        np.broadcast_to(np.asarray(variation, dtype=float), (m,))
    out = np.empty(phase.shape)
    flat_phase = phase.reshape(-1, m)
    flat_out = out.reshape(-1, m)
    pairs = np.column_stack(columns)
    for eps, v in np.unique(pairs, axis=0):  # the meshes of one contact ratio and variation in one evaluation
        same = np.flatnonzero((pairs[:, 0] == eps) & (pairs[:, 1] == v))
        one = MeshPhasing([1.0], [0.0], [eps], [v], transition, allow_unit_variation)
        flat_out[:, same] = one.factors(flat_phase[:, same].ravel())[0][:, 0].reshape(-1, same.size)
    return out.reshape(np.shape(phase_rad)) if np.ndim(phase_rad) else out[0]


class MeshPhasing:
    """Stiffness factors of all meshes as a function of the driver (rotor) angle, with their slope.

    The phasing table of the kernel (:mod:`components.model.kernel.stiffness`): ``phase = rate *
    angle + offset`` per mesh (see :class:`~components.model.assembly.Mesh`), with the parameters
    validated and the per-mesh constants formed once. The slope ``d f / d angle`` is analytic
    (the smootherstep's derivative ``30 s^2 (1 - s)^2``), so an integrator forms the partial time
    derivative ``d f / d t = slope x driver speed`` without differencing.

    Parameters
    ----------
    rate : array_like, shape (n_mesh,)
        Mesh-cycle phase per radian of driver rotation [rad/rad].
    offset : array_like, shape (n_mesh,)
        Mesh-cycle phase at driver angle 0 [rad].
    contact_ratio : array_like, shape (n_mesh,)
        Contact ratio epsilon [-].
    variation : array_like, shape (n_mesh,)
        Peak-to-peak stiffness variation relative to the mean [-] (0: constant).
    transition : float
        Width of each smoothed transition [mesh cycles].
    allow_unit_variation : bool
        Accept ``v p < 1`` up to ``v = 1`` (the indicator of :func:`multi_pair_indicator`).

    Attributes
    ----------
    table : ndarray, shape (7, n_mesh)
        The kernel's phasing table (rows of :mod:`components.model.kernel.stiffness`).
    """

    def __init__(self, rate, offset, contact_ratio, variation, transition: float = TRANSITION_FRACTION,
                 allow_unit_variation: bool = False) -> None:
        if not 0.0 < transition <= 0.5:
            raise ParameterError("transition", transition, "within (0, 0.5] mesh cycles")
        p = pair_fraction(contact_ratio)
        v = np.asarray(variation, dtype=float)
        too_large = v > 1.0 if allow_unit_variation else v * p >= 1.0
        if np.any(~np.isfinite(v)) or np.any(v < 0.0) or np.any(too_large):
            raise ParameterError("stiffness_variation", variation, ">= 0 and < 1 / (epsilon - floor(epsilon))")
        w = np.minimum(transition, np.minimum(p, 1.0 - p))
        # an integer contact ratio (p = 0, w = 0) has a constant pair count: factor exactly 1
        v = np.where(w > 0.0, v, 0.0)
        inv_w = 1.0 / np.where(w > 0.0, w, 1.0)
        cycles_per_rad = np.asarray(rate, dtype=float) / (2.0 * math.pi)
        self.table = np.zeros((N_PHASING_ROWS, cycles_per_rad.size))
        self.table[CYCLES_PER_RAD] = cycles_per_rad
        self.table[CYCLE0] = np.asarray(offset, dtype=float) / (2.0 * math.pi) - 0.5 * p + 0.5
        self.table[HALF_P] = 0.5 * p
        self.table[INV_W] = inv_w
        self.table[VARIATION] = v
        self.table[VP] = v * p
        self.table[SLOPE_SCALE] = -30.0 * v * inv_w * cycles_per_rad

    def factors(self, driver_angles_rad: np.ndarray, kernel: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Multipliers [-] and their slopes [1/rad] at many driver angles, each shape (N, n_mesh)."""
        angles = np.ascontiguousarray(np.atleast_1d(np.asarray(driver_angles_rad, dtype=float)))
        factor = np.empty((angles.size, self.table.shape[1]))
        slope = np.empty_like(factor)
        brief = factor.size <= model_kernel.BRIEF_EVALUATIONS
        model_kernel.monolithic(kernel, brief=brief)[0].stiffness_factors_many(angles, self.table, factor, slope)
        return factor, slope

    def factor(self, driver_angle_rad: float) -> np.ndarray:
        """Stiffness multiplier of every mesh at a driver angle [-], shape (n_mesh,)."""
        return self.factors(driver_angle_rad)[0][0]

    def factor_and_slope(self, driver_angle_rad: float) -> tuple[np.ndarray, np.ndarray]:
        """Stiffness multiplier [-] and its derivative with respect to the driver angle [1/rad], each (n_mesh,)."""
        factor, slope = self.factors(driver_angle_rad)
        return factor[0], slope[0]


def mesh_frequency_hz(teeth_per_driver_revolution: float | np.ndarray, rotor_speed_rad_s: float | np.ndarray) -> np.ndarray:
    """Mesh frequency [Hz] from the mesh-phase rate and the rotor speed.

    Parameters
    ----------
    teeth_per_driver_revolution : float or ndarray
        Tooth pairs passing per revolution of the rotor, i.e. ``Mesh.teeth_per_driver_rad``
        (mesh-cycle radians per rotor radian) [-].
    rotor_speed_rad_s : float or ndarray
        Rotor speed [rad/s].
    """
    return np.abs(np.multiply.outer(rotor_speed_rad_s, teeth_per_driver_revolution)) / (2.0 * math.pi)


def max_step_s(
    teeth_per_driver_revolution: np.ndarray,
    variation: np.ndarray,
    max_rotor_speed_rad_s: float,
    transition: float = TRANSITION_FRACTION,
) -> float:
    """Largest integration step that cannot jump over a stiffness transition [s].

    An adaptive integrator only sees the stiffness where it evaluates the right-hand
    side: a step longer than a pair-count zone can skip the zone entirely while its
    error estimate stays small. Capping the step at half a transition width (of the
    fastest mesh whose stiffness varies) makes every transition visible.

    Parameters
    ----------
    teeth_per_driver_revolution : ndarray, shape (n_mesh,)
        ``Mesh.teeth_per_driver_rad`` of every mesh [-].
    variation : ndarray, shape (n_mesh,)
        Stiffness variation of every mesh [-]; meshes with 0 are ignored.
    max_rotor_speed_rad_s : float
        Largest rotor speed magnitude over the run [rad/s].
    transition : float
        Transition width [mesh cycles].

    Returns
    -------
    float
        ``transition * T_mesh,min / 2`` [s]; ``inf`` if no mesh varies or the rotor stands still.
    """
    rate = np.abs(np.asarray(teeth_per_driver_revolution, dtype=float))[np.asarray(variation) > 0.0]
    omega = abs(float(max_rotor_speed_rad_s))
    if rate.size == 0 or omega == 0.0:
        return math.inf
    period = 2.0 * math.pi / (rate.max() * omega)
    return 0.5 * transition * period
