"""Time-varying mesh stiffness: the multiplier on ``k0`` of every mesh and its slope at a driver angle.

The model (pair counts, smoothing, planet phasing) is described in
:mod:`components.model.mesh_stiffness`, which fills the phasing table (one column per mesh,
rows named below). With the mesh-cycle position ``y = (cycle0 + cycles_per_rad theta) mod 1 - 1/2``
and the smootherstep argument ``s = clip((p/2 - |y|) / w + 1/2, 0, 1)``:

    f = 1 - v p + v (6 s^5 - 15 s^4 + 10 s^3),    df/dtheta = -30 v cycles_per_rad / w sgn(y) s^2 (1 - s)^2
"""

from __future__ import annotations

import numpy as np

from .contact import sign

#: rows of the phasing table: mesh cycles per driver radian, cycle at theta = 0 (shifted), p/2, 1/w, v, v p,
#: the slope's scale -30 v cycles_per_rad / w
CYCLES_PER_RAD, CYCLE0, HALF_P, INV_W, VARIATION, VP, SLOPE_SCALE = range(7)
N_PHASING_ROWS = 7


def stiffness_factors(angle, phasing, out_factor, out_slope):
    """Multiplier [-] and its derivative by the driver angle [1/rad] of every mesh at driver angle ``angle`` [rad].

    The numpy form also takes a column of angles (shape (N, 1); the outputs (N, n_mesh)).
    """
    y = np.remainder(phasing[CYCLE0] + phasing[CYCLES_PER_RAD] * angle, 1.0) - 0.5  # Python's float % (the loop's)
    s = np.minimum(np.maximum((phasing[HALF_P] - np.abs(y)) * phasing[INV_W] + 0.5, 0.0), 1.0)
    s2 = s * s
    out_factor[...] = 1.0 - phasing[VP] + phasing[VARIATION] * (s2 * s * (s * (6.0 * s - 15.0) + 10.0))
    u = s - s2
    out_slope[...] = phasing[SLOPE_SCALE] * (np.sign(y) + 0.0) * (u * u)  # + 0.0: sign(-0.0) is 0.0, as sign()'s


def _stiffness_factors_loop(angle, phasing, out_factor, out_slope):
    for i in range(out_factor.shape[0]):
        y = (phasing[CYCLE0, i] + phasing[CYCLES_PER_RAD, i] * angle) % 1.0 - 0.5
        s = min(max((phasing[HALF_P, i] - abs(y)) * phasing[INV_W, i] + 0.5, 0.0), 1.0)
        s2 = s * s
        out_factor[i] = 1.0 - phasing[VP, i] + phasing[VARIATION, i] * (s2 * s * (s * (6.0 * s - 15.0) + 10.0))
        u = s - s2  # s (1 - s): the smootherstep's slope vanishes outside the ramps
        out_slope[i] = phasing[SLOPE_SCALE, i] * sign(y) * (u * u)


#: the loop numba compiles in place of the numpy form (see :mod:`components.compile.jit`)
COMPILED = {"stiffness_factors": _stiffness_factors_loop}
