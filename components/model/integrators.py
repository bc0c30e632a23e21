"""The error control of the gearbox's integrator: :class:`StepControl`.

The integrator itself - the ROS2(3) W-method of Shampine and Reichelt (MATLAB's ``ode23s``)
with Jacobian reuse, a kept second factorisation and the observed-order step control after
rejections - is written once, in :mod:`components.model.kernel.integrator`, and runs compiled
or interpreted with the rest of the gearbox's communication step.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..validation import integer_at_least, positive


@dataclass(frozen=True)
class StepControl:
    """Error control of the gearbox's integrator (:mod:`components.model.kernel.integrator`).

    Parameters
    ----------
    rtol : float
        Relative tolerance.
    atol_q : float
        Absolute tolerance on positions (deviation angles) [rad].
    atol_v : float
        Absolute tolerance on speeds [rad/s].
    h_min : float
        Smallest step [s] before the integrator gives up.
    max_steps : int
        Maximum internal steps (accepted + rejected) per communication step.
    jacobian_max_age : int
        Accepted steps after which the Jacobian is re-evaluated (1: every step).
    """

    rtol: float = 1e-4
    atol_q: float = 1e-8
    atol_v: float = 1e-5
    h_min: float = 1e-12
    max_steps: int = 100_000
    jacobian_max_age: int = 20

    def __post_init__(self) -> None:
        positive("rtol", self.rtol)
        positive("atol_q", self.atol_q)
        positive("atol_v", self.atol_v)
        positive("h_min", self.h_min)
        integer_at_least("max_steps", self.max_steps, 1)
        integer_at_least("jacobian_max_age", self.jacobian_max_age, 1)
