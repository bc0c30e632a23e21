"""The longest communication step that resolves the modes a co-simulation splits across FMUs, and the longest output
interval and shortest analysis window that resolve them.

A fixed-step master holds (or extrapolates) every FMU's inputs over a communication step ``H``.
Inside one FMU a mode is integrated to its solver's tolerance, but a mode whose motion sits in
bodies of two FMUs - the generator's inertia (the GeneratorRotor FMU) swinging on the gearbox's
shafts (the Gearbox FMU), a torque-driven rotor (the Rotor FMU) - is integrated with the coupling's
error, which grows steeply with ``H f``. On the paper's drivetrain (mode 1, 0.953 Hz, 100 % of its
kinetic energy in the generator) the standard deviation of the gear forces over [5, 30] s differed
from the monolithic reference's by 6e-5 at H = 20 ms (``H f`` = 0.019), 0.36 % at 0.1 s (0.095),
4.7 % at 0.25 s, 36 % at 0.5 s and 3.4 times at 1 s; the means by less than 0.15 %
(``dtcosim run --stop 30 --step H --compare-reference``, 2026-12-07). :data:`STEPS_PER_PERIOD` = 20
(``H f`` <= 0.05, ~0.1 % there) is the step a run is warned beyond.

The same mode - the drivetrain's lowest, in which the generator swings, whose oscillation is the
gear forces' fluctuation - must also be sampled finely enough by the recorded output, since a run's
statistics and its rainflow counts come from the samples: at an output interval of 0.1 s (10.5
samples per period) the stage-1 sun-planet force's DEL (m = 3) over [5, 30] s came out 0.6 % below
the one of 0.02 s, at 0.5 s (2.1 per period) 14.5 % below, its maximum 0.4 % (same runs).
:data:`SAMPLES_PER_PERIOD` = 10 is the interval a run is warned beyond; a window shorter than one period
is warned about too (over [5, 5.25] s that force's standard deviation was a fifth of the one over [5, 30] s).

Only the linear model's eigenvectors are computed (numpy; the same linearisation as
:mod:`components.analysis.settling`): every run checks its step, output interval and window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from ..model.drivetrain import Drivetrain
from ..model.rotor import RotorParameters
from .eigen import state_space_matrix
from .equilibrium import OperatingPoint, linearise
from .rotor_coupling import CoupledModel, coupled

#: communication steps per period of the fastest split mode that a step may not fall short of
STEPS_PER_PERIOD = 20
#: recorded samples per period of that mode that an output interval may not fall short of
SAMPLES_PER_PERIOD = 10
#: share of a mode's kinetic energy in the bodies of other FMUs from which the mode counts as split
SPLIT_SHARE = 0.1


@dataclass(frozen=True)
class CouplingLimit:
    """The fastest mode split across FMUs and the longest step that resolves it (:meth:`note`; the output interval:
    :meth:`sampling_note`; the window: :meth:`window_note`).

    Attributes
    ----------
    frequency_hz : float
        Its undamped natural frequency [Hz].
    damping_ratio : float
    bodies : str
        Its kinetic energy in the bodies of other FMUs, e.g. ``"generator 100 %"``.
    step_s : float
        ``1 / (STEPS_PER_PERIOD frequency_hz)`` [s].
    """

    frequency_hz: float
    damping_ratio: float
    bodies: str
    step_s: float

    def note(self, step_s: float) -> str | None:
        """A warning where the communication step ``step_s`` [s] is longer than :attr:`step_s` (None: it is not)."""
        if step_s <= self.step_s * (1.0 + 1e-9):
            return None
        return (f"the communication step {step_s:g} s is longer than 1/{STEPS_PER_PERIOD} of the period of the "
                f"{self.frequency_hz:.3g} Hz mode (damping ratio {self.damping_ratio:.2g}) whose motion is split "
                f"across FMUs ({self.bodies} of its kinetic energy), {self.step_s:.3g} s: each FMU holds the other's "
                f"outputs over a step, so that mode is coupled coarsely (on the paper's drivetrain the gear forces' "
                f"standard deviation came out 0.4 % off at H f = 0.1, 5 % at 0.25, 36 % at 0.5); use a step of "
                f"{self.step_s:.3g} s or less (`dtcosim run --compare-reference` measures the difference)")

    @property
    def output_interval_s(self) -> float:
        """``1 / (SAMPLES_PER_PERIOD frequency_hz)`` [s]: the longest output interval that samples the mode."""
        return 1.0 / (SAMPLES_PER_PERIOD * self.frequency_hz)

    def sampling_note(self, output_interval_s: float) -> str | None:
        """A warning where the output interval [s] samples the mode fewer than :data:`SAMPLES_PER_PERIOD` times per
        period (None: it does not)."""
        if output_interval_s <= self.output_interval_s * (1.0 + 1e-9):
            return None
        per_period = 1.0 / (output_interval_s * self.frequency_hz)
        return (f"the output interval {output_interval_s:g} s samples the {self.frequency_hz:.3g} Hz mode (the gear "
                f"forces' fluctuation: {self.bodies} of its kinetic energy) {per_period:.2g} times per period, fewer "
                f"than {SAMPLES_PER_PERIOD}: the statistics and fatigue loads come from the samples and miss what "
                f"happens between them (on the paper's drivetrain a DEL came out 0.6 % low at 10 samples per period, "
                f"15 % low at 2); use an output interval of {self.output_interval_s:.3g} s or less")

    def window_note(self, window_s: tuple[float, float]) -> str | None:
        """A warning where an analysis window is shorter than one period of the mode (None: it is not)."""
        length, period = window_s[1] - window_s[0], 1.0 / self.frequency_hz
        if length >= period * (1.0 - 1e-9):
            return None
        return (f"the analysis window [{window_s[0]:g}, {window_s[1]:g}] s is shorter than one period ({period:.3g} s) "
                f"of the {self.frequency_hz:.3g} Hz mode in which the gear forces fluctuate: its statistics and "
                f"fatigue loads see part of one oscillation (on the paper's drivetrain the stage-1 sun-planet force's "
                f"standard deviation over [5, 5.25] s was a fifth of that over [5, 30] s); use a window of "
                f"{period:.3g} s or more")

    def warnings(self, step_s: float, output_interval_s: float, window_s: tuple[float, float]) -> dict[str, str]:
        """The warnings of a run with this step, output interval and analysis window [s], by what they are about
        (``step_warning``, ``output_warning``, ``window_length_warning``); {} where none applies."""
        notes = {"step_warning": self.note(step_s), "output_warning": self.sampling_note(output_interval_s),
                 "window_length_warning": self.window_note(window_s)}
        return {key: note for key, note in notes.items() if note is not None}

    def as_dict(self) -> dict:
        return {"frequency_hz": self.frequency_hz, "damping_ratio": self.damping_ratio, "bodies": self.bodies,
                "step_s": self.step_s, "steps_per_period": STEPS_PER_PERIOD,
                "output_interval_s": self.output_interval_s, "samples_per_period": SAMPLES_PER_PERIOD}


def coupling_limit(model: CoupledModel, split_bodies: Iterable[str]) -> CouplingLimit | None:
    """The limit of the fastest oscillatory mode of ``model`` with at least :data:`SPLIT_SHARE` of its kinetic energy
    in the bodies ``split_bodies`` (names of ``model.body_names`` simulated by other FMUs); None where none is."""
    names = list(model.body_names)
    picks = [i for i, name in enumerate(names) if name in set(split_bodies)]
    if not picks:
        return None
    n = model.mass.shape[0]
    eigenvalues, vectors = np.linalg.eig(state_space_matrix(model.mass, model.damping, model.stiffness))
    best: CouplingLimit | None = None
    for lam, vector in zip(eigenvalues, vectors.T):
        if lam.imag <= 1e-9 * abs(lam):  # one of each conjugate pair; real roots do not oscillate
            continue
        energy = np.asarray(model.body_inertia_kgm2) * np.abs(model.basis @ vector[n:]) ** 2
        total = float(energy.sum())
        share = float(energy[picks].sum()) / total if total > 0.0 else 0.0
        frequency = float(abs(lam)) / (2.0 * math.pi)
        if share < SPLIT_SHARE or (best is not None and frequency <= best.frequency_hz):
            continue
        bodies = ", ".join(f"{names[i]} {100.0 * energy[i] / total:.0f} %" for i in picks
                           if energy[i] >= 0.005 * total)
        best = CouplingLimit(frequency, float(-lam.real / abs(lam)), bodies, 1.0 / (STEPS_PER_PERIOD * frequency))
    return best


def drivetrain_coupling_limit(drivetrain: Drivetrain, operating_point: OperatingPoint, split_bodies: Iterable[str],
                              rotor: RotorParameters | None = None) -> CouplingLimit | None:
    """:func:`coupling_limit` of a drivetrain at an operating point (rotor held, or torque-driven with ``rotor``)."""
    return coupling_limit(coupled(linearise(drivetrain, operating_point), rotor), split_bodies)
