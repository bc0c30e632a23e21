"""Planet load sharing of a planetary stage, and its hand estimate for a pin position error.

**Load-sharing factor** (the K_gamma of IEC 61400-4 and ISO 6336): at every instant the largest
planet's mesh force over the mean of the planets' mesh forces, ``K(t) = max_i F_i(t) / mean_i F_i(t)``
(sun-planet meshes; with equal planets the ring-planet forces share alike). Over an analysis window
:func:`load_sharing` reports its largest value (the design value), its mean, and each planet's mean
share ``mean_t F_i / mean_t mean_j F_j``. Equal planets on an ideal carrier give 1 exactly.

**Hand estimate** (:func:`pin_error_factor`): a planet whose pin sits ``e`` ahead of its nominal
position (tangential error, in the direction of normal rotation) meets both its meshes ``e`` early:
each deflection grows by ``e`` at the pitch circle (:mod:`components.model.stage_rows`). With the
sun and carrier held on stiff bearings, the planet's path from the carrier to the sun and ring is
its bearing (tangential stiffness ``k_b``) in series with the two meshes in parallel (moment balance
on the planet: ``F_sp = F_rp``; each mesh's tangent stiffness ``k = dF/dd`` at the pitch-circle
deflection ``d``; the bearing carries ``2 F cos(alpha)``), so the mesh force follows the planet's
path displacement ``x`` with the stiffness ``k_eff = k / (1 + 2 k cos(alpha) / k_b)``. The sun and
carrier rotations are common to all planets, and the planets carry the stage torque together,
``sum_i F_i = N F``; hence ``F_i = F + k_eff (e_i - mean_j e_j)`` and for one planet in error::

    K = 1 + (1 - 1/N) k_eff e / F

With the CFS law ``F = k0 d^(3/2)`` the tangent stiffness is ``k = 1.5 F / d``: with stiff bearings
``K - 1 = 1.5 (1 - 1/N) e / d``, the error over the static mesh deflection. Linear in ``e`` while
``e << d``; a floating sun or carrier (bearing stiffness 0) of a three-planet stage shares the load
equally whatever the errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..validation import positive


@dataclass(frozen=True)
class LoadSharing:
    """The load sharing of one planetary stage over an analysis window.

    Attributes
    ----------
    stage : str
    factor : float
        ``max_t K(t)``: the largest ratio of the most loaded planet's mesh force to the mean [-].
    mean_factor : float
        ``mean_t K(t)`` [-].
    shares : tuple of float
        Each planet's mean force over the mean of all planets' (planet 1 first) [-].
    most_loaded : int
        The planet (1-based) with the largest mean share.
    columns : tuple of str
        The sun-planet force of each planet it was computed from.
    """

    stage: str
    factor: float
    mean_factor: float
    shares: tuple[float, ...]
    most_loaded: int
    columns: tuple[str, ...]

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {"factor": self.factor, "mean_factor": self.mean_factor, "shares": list(self.shares),
                "most_loaded_planet": self.most_loaded, "forces": list(self.columns),
                "definition": "max over the window of (largest planet sun-mesh force / mean of the planets')"}


def load_sharing(stage: str, forces_n: np.ndarray, columns: tuple[str, ...] = ()) -> LoadSharing:
    """The load sharing of a stage from its planets' mesh forces over a window.

    Parameters
    ----------
    stage : str
    forces_n : ndarray, shape (N, P)
        The sun-planet mesh force of each of the ``P`` planets at ``N`` samples of the window [N].
    columns : tuple of str
        Their names (reported).

    Raises
    ------
    ParameterError
        Fewer than one sample or two planets, or a sample whose mean force is not positive (the stage
        does not transmit load in normal power flow: no factor is defined).
    """
    f = np.asarray(forces_n, dtype=float)
    if f.ndim != 2 or f.shape[0] < 1 or f.shape[1] < 2:
        raise ParameterError("forces_n", f.shape, "samples x planets with at least one sample and two planets")
    mean = f.mean(axis=1)
    if not np.all(mean > 0.0):
        raise ParameterError(f"{stage} mean planet force", float(mean.min()), "> 0 at every sample of the window "
                             "(the stage transmits load in normal power flow)")
    ratio = f.max(axis=1) / mean
    shares = f.mean(axis=0) / mean.mean()
    return LoadSharing(stage, float(ratio.max()), float(ratio.mean()), tuple(map(float, shares)),
                       int(np.argmax(shares)) + 1, tuple(columns))


def pin_error_factor(error_m: float, force_n: float, mesh_stiffness_n_per_m: float, n_planets: int,
                     pressure_angle_rad: float, bearing_stiffness_n_per_m: float = math.inf) -> float:
    """The hand estimate of the load-sharing factor for one planet's tangential pin error (module docstring).

    Parameters
    ----------
    error_m : float
        Tangential pin position error of one planet [m] (positive ahead).
    force_n : float
        Mean planet mesh force F [N].
    mesh_stiffness_n_per_m : float
        Tangent stiffness ``dF/dd`` of each mesh at F, on the pitch-circle deflection [N/m].
    n_planets : int
    pressure_angle_rad : float
    bearing_stiffness_n_per_m : float
        Planet bearing stiffness [N/m] (inf: rigid).
    """
    k = positive("mesh_stiffness", mesh_stiffness_n_per_m)
    f = positive("force", force_n)
    n = int(n_planets)
    if n < 2:
        raise ParameterError("n_planets", n_planets, ">= 2")
    rigid = bearing_stiffness_n_per_m == math.inf
    k_b = math.inf if rigid else positive("bearing_stiffness", bearing_stiffness_n_per_m)
    k_eff = k / (1.0 + 2.0 * k * math.cos(pressure_angle_rad) / k_b)
    return 1.0 + (1.0 - 1.0 / n) * k_eff * abs(error_m) / f
