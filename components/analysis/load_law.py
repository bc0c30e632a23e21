"""The generator (output) torque as a function of rotor speed, for the Campbell diagram's operating points.

``quadratic``: below rated speed the torque grows with the square of the rotor
speed (the optimal tip-speed-ratio law of region 2), at and above rated speed it
stays at the rated torque; ``constant``: the rated torque at every speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..units import rad_per_s_to_rpm, rpm
from ..validation import finite, one_of, positive

LOAD_LAWS = ("quadratic", "constant")


@dataclass(frozen=True)
class LoadLaw:
    """Generator (output) torque as a function of rotor speed.

    Parameters
    ----------
    kind : {"quadratic", "constant"}
        See module docstring.
    rated_speed_rad_s : float
        Rated rotor speed [rad/s] (default 16 rpm).
    rated_torque_nm : float
        Torque at and above rated speed [N m] (default 25.4 kN m), non-zero.
    """

    kind: str = "quadratic"
    rated_speed_rad_s: float = rpm(16.0)
    rated_torque_nm: float = 25.4e3

    def __post_init__(self) -> None:
        one_of("load_law", self.kind, LOAD_LAWS)
        positive("rated_speed_rad_s", self.rated_speed_rad_s)
        if finite("rated_torque_nm", self.rated_torque_nm) == 0.0:
            raise ParameterError("rated_torque_nm", self.rated_torque_nm, "non-zero")

    def torque_nm(self, rotor_speed_rad_s: float | np.ndarray) -> np.ndarray:
        """Output torque [N m] at rotor speed(s) [rad/s]."""
        w = np.abs(np.asarray(rotor_speed_rad_s, dtype=float))
        if self.kind == "constant":
            return np.full_like(w, self.rated_torque_nm)
        return self.rated_torque_nm * np.minimum(w / self.rated_speed_rad_s, 1.0) ** 2

    def describe(self) -> str:
        """One-line statement of the law (for plots and files)."""
        r = f"{rad_per_s_to_rpm(self.rated_speed_rad_s):g} rpm, {self.rated_torque_nm / 1e3:g} kN m"
        if self.kind == "constant":
            return f"constant generator torque ({self.rated_torque_nm / 1e3:g} kN m)"
        return f"generator torque ~ speed^2 up to rated ({r}), rated torque above"

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {
            "kind": self.kind,
            "rated_speed_rpm": rad_per_s_to_rpm(self.rated_speed_rad_s),
            "rated_torque_nm": self.rated_torque_nm,
            "description": self.describe(),
        }
