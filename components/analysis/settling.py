"""How long a drivetrain takes to forget its start: the settling time from its slowest-decaying mode.

A run starts at the static operating point of its initial inputs (:mod:`components.model.kernel.statics`),
but a recorded or turbulent input is already in motion at t = 0: the accelerations and the dynamic
deflections the history of the input would have built are missing, and the difference rings out with
the drivetrain's own modes. Each mode decays as ``exp(-sigma t)`` with ``sigma = -Re(lambda)``
(``zeta omega_n`` for an oscillatory mode, the root itself for an overdamped one), so after ``n``
time constants ``tau = 1 / sigma`` of the slowest one every start-up contribution is below
``exp(-n)`` of its initial size (five: 0.7 %). That is the settling time
:func:`settling_time` gives and the analysis window of a run or a load case should start after.

Rigid-body eigenvalues (``|lambda|`` below :data:`RIGID_FRACTION` of the largest; there are none
with the rotor held or with the free rotor's rigid rotation removed) are left out.

:func:`settling_time` takes a whole modal analysis (``dtcosim modes``); :func:`drivetrain_settling`
needs only the eigenvalues and computes nothing else (every run states its settling time: no mode
matching, no scipy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model.drivetrain import Drivetrain
from ..model.rotor import RotorParameters
from .eigen import state_space_matrix
from .equilibrium import OperatingPoint, linearise
from .rotor_coupling import CoupledModel, coupled

if TYPE_CHECKING:
    from .modes import DrivetrainModalAnalysis

#: time constants of the slowest mode a window starts after (exp(-5) = 0.7 % of the start-up amplitude)
N_TIME_CONSTANTS = 5.0
#: eigenvalues smaller than this fraction of the largest are rigid-body motion, not a decay
RIGID_FRACTION = 1.0e-9


@dataclass(frozen=True)
class Settling:
    """The settling time of a drivetrain and the mode it comes from.

    Attributes
    ----------
    time_s : float
        ``n_time_constants * time_constant_s`` [s].
    time_constant_s : float
        ``1 / sigma`` of the slowest-decaying eigenvalue [s].
    n_time_constants : float
    frequency_hz : float
        Its undamped natural frequency ``|lambda| / 2 pi`` [Hz] (an oscillatory mode), NaN for a real root.
    damping_ratio : float
        ``sigma / |lambda|`` (an oscillatory mode), 1 for a real root.
    oscillatory : bool
    rotor : str
        ``"held"`` (prescribed speed) or ``"free"`` (torque-driven rotor).
    """

    time_s: float
    time_constant_s: float
    n_time_constants: float
    frequency_hz: float
    damping_ratio: float
    oscillatory: bool
    rotor: str

    def describe(self) -> str:
        """``"2.75 s = 5 time constants of the 6.88 Hz mode (damping ratio 0.042, rotor held)"``."""
        what = (f"the {self.frequency_hz:.3g} Hz mode (damping ratio {self.damping_ratio:.2g}"
                if self.oscillatory else f"the overdamped root {1.0 / self.time_constant_s:.3g} 1/s (")
        return (f"{self.time_s:.3g} s = {self.n_time_constants:g} time constants of {what}, rotor {self.rotor}): "
                "the slowest-decaying mode of the drivetrain at its operating point")

    def as_dict(self) -> dict:
        return {"time_s": self.time_s, "time_constant_s": self.time_constant_s,
                "n_time_constants": self.n_time_constants,
                "frequency_hz": None if math.isnan(self.frequency_hz) else self.frequency_hz,
                "damping_ratio": self.damping_ratio, "oscillatory": self.oscillatory, "rotor": self.rotor,
                "description": self.describe()}


def settling_time(analysis: DrivetrainModalAnalysis, n_time_constants: float = N_TIME_CONSTANTS) -> Settling:
    """The settling time of a modal analysis (see the module docstring).

    Raises
    ------
    ValueError
        When no eigenvalue decays (an undamped or unstable drivetrain has no settling time).
    """
    return settling_of_eigenvalues(analysis.state_space.eigenvalues, analysis.rotor_held, n_time_constants)


def drivetrain_settling(drivetrain: Drivetrain, operating_point: OperatingPoint, stiffness_factor=1.0,
                        rotor: RotorParameters | None = None,
                        n_time_constants: float = N_TIME_CONSTANTS) -> Settling:
    """The settling time of a drivetrain at an operating point, from the eigenvalues of its linearisation alone.

    The same linear model as :func:`components.analysis.modes.drivetrain_modes` (rotor held, or
    torque-driven with ``rotor``), so the same eigenvalues, and :func:`settling_time` of them.

    Raises
    ------
    ValueError
        As :func:`settling_time`.
    """
    return model_settling(coupled(linearise(drivetrain, operating_point, stiffness_factor), rotor), n_time_constants)


def model_settling(model: CoupledModel, n_time_constants: float = N_TIME_CONSTANTS) -> Settling:
    """:func:`drivetrain_settling` of a drivetrain already linearised (rotor held where ``model.rotor`` is None)."""
    eigenvalues = np.linalg.eigvals(state_space_matrix(model.mass, model.damping, model.stiffness))
    return settling_of_eigenvalues(eigenvalues, model.rotor is None, n_time_constants)


def settling_of_eigenvalues(eigenvalues: np.ndarray, rotor_held: bool,
                            n_time_constants: float = N_TIME_CONSTANTS) -> Settling:
    """:class:`Settling` from the eigenvalues of a drivetrain's state-space model (see the module docstring)."""
    lam = np.asarray(eigenvalues, dtype=complex)
    size = np.abs(lam)
    lam = lam[size > RIGID_FRACTION * float(size.max())]
    sigma = -lam.real
    if lam.size == 0 or not np.all(sigma > 0.0):
        raise ValueError("a drivetrain whose every mode decays (an eigenvalue with Re >= 0 has no settling time)")
    slowest = lam[int(np.argmin(sigma))]
    s = float(-slowest.real)
    oscillatory = abs(slowest.imag) > 1e-9 * abs(slowest)
    tau = 1.0 / s
    return Settling(time_s=n_time_constants * tau, time_constant_s=tau, n_time_constants=float(n_time_constants),
                    frequency_hz=abs(slowest) / (2.0 * math.pi) if oscillatory else float("nan"),
                    damping_ratio=s / abs(slowest) if oscillatory else 1.0, oscillatory=bool(oscillatory),
                    rotor="held" if rotor_held else "free")
