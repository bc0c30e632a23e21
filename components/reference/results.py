"""Time-series results of a drivetrain simulation and their statistics.

Variable names follow the Gearbox FMU interface so that monolithic and
co-simulated results can be compared name by name:

* ``stage{k}.F_sp[{i}]``, ``stage{k}.F_rp[{i}]``, ``stage{k}.F_mesh`` - contact forces [N]
* ``stage{k}.d_sp[{i}]`` ... - mesh deflections [m] (``F`` replaced by ``d``)
* ``shaft{k}.torque`` - shaft torques [N m]
* ``<body>.omega`` - absolute body speeds [rad/s], e.g. ``stage1.sun.omega``
* ``omega_rotor`` [rad/s], ``torque_rotor`` [N m], ``omega_out`` [rad/s],
  ``alpha_out`` [rad/s^2] (output-gear acceleration), ``omega_gen`` [rad/s],
  ``load_torque`` [N m]

What each series is - its unit and kind - is not read from these names: the solver
declares it where it makes the series (:attr:`SimulationResult.signals`, from
:mod:`components.model.signals`, as the Gearbox FMU declares its outputs).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..errors import ParameterError
from ..model.signals import Signal


def window_mask(time_s: np.ndarray, window: tuple[float, float] | None) -> np.ndarray | slice:
    """Samples with ``window[0] <= t <= window[1]`` (all samples for None)."""
    if window is None:
        return slice(None)
    return (time_s >= window[0] - 1e-12) & (time_s <= window[1] + 1e-12)


def select_window(
    time_s: np.ndarray, values: np.ndarray, window: tuple[float, float] | None
) -> tuple[np.ndarray, np.ndarray]:
    """Validated samples of one series inside an analysis window.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Strictly increasing sample times [s].
    values : ndarray, shape (N,)
        Finite samples.
    window : (float, float) or None
        ``(start, end)`` [s]; None keeps every sample.

    Returns
    -------
    t, x : ndarray
        The samples inside the window (at least 2).

    Raises
    ------
    ParameterError
        Shapes differ, times not increasing, non-finite samples, or fewer than
        2 samples in the window.
    """
    from ..errors import ParameterError

    t = np.asarray(time_s, dtype=float)
    x = np.asarray(values, dtype=float)
    if t.ndim != 1 or x.shape != t.shape:
        raise ParameterError("values", x.shape, f"a 1-D series of the time vector's shape {t.shape}")
    if t.size < 2 or np.any(np.diff(t) <= 0.0):
        raise ParameterError("time_s", t.size, "at least 2 strictly increasing sample times")
    if window is not None:
        lo, hi = window
        if not hi > lo:
            raise ParameterError("window", window, "(start, end) with end > start")
        sel = window_mask(t, window)
        if sel.sum() < 2:
            raise ParameterError("window", window, f"at least 2 samples inside [{t[0]:g}, {t[-1]:g}] s")
        t, x = t[sel], x[sel]
    if not np.all(np.isfinite(x)):
        raise ParameterError("values", "non-finite samples", "finite values (an incomplete run?)")
    return t, x


def window_statistics(time_s: np.ndarray, values: np.ndarray, window: tuple[float, float] | None) -> dict[str, float]:
    """Mean, std, min and max of samples with ``window[0] <= t <= window[1]``.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
    values : ndarray, shape (N,)
    window : (float, float) or None
        Analysis window [s]; None means all samples.
    """
    x = np.asarray(values)[window_mask(time_s, window)]
    if x.size == 0:
        return {"mean": float("nan"), "std": float("nan"), "min": float("nan"), "max": float("nan")}
    return {"mean": float(x.mean()), "std": float(x.std()), "min": float(x.min()), "max": float(x.max())}


@dataclass
class EnergyAudit:
    """Energy balance of a run [J]: ``input = output + dissipated + delta_stored``.

    Attributes
    ----------
    input_work_j : float
        Work done by the rotor (kinematic driver) on the gearbox.
    output_work_j : float
        Work extracted by the counter torque at the output.
    dissipated_j : float
        Energy dissipated by mesh and shaft damping.
    stored_change_j : float
        Change of kinetic + elastic energy.
    """

    input_work_j: float
    output_work_j: float
    dissipated_j: float
    stored_change_j: float

    @property
    def residual_j(self) -> float:
        """``input - output - dissipated - delta_stored`` [J]."""
        return self.input_work_j - self.output_work_j - self.dissipated_j - self.stored_change_j

    @property
    def relative_residual(self) -> float:
        """Residual relative to the input work [-]."""
        return abs(self.residual_j) / max(abs(self.input_work_j), 1e-300)

    def as_dict(self) -> dict[str, float]:
        """Plain dict (JSON-ready)."""
        return {
            "input_work_j": self.input_work_j,
            "output_work_j": self.output_work_j,
            "dissipated_j": self.dissipated_j,
            "stored_change_j": self.stored_change_j,
            "residual_j": self.residual_j,
            "relative_residual": self.relative_residual,
        }


@dataclass
class SimulationResult:
    """Sampled results of a run.

    Attributes
    ----------
    time_s : ndarray, shape (N,)
        Sample times [s].
    series : dict of str -> ndarray, shape (N,)
        Every recorded variable by name (see module docstring for names and units).
    complete : bool
        False if the run stopped early; the samples hold what was computed.
    message : str
        Solver message (the failure reason when ``complete`` is False).
    wall_time_s : float
        Wall-clock time of the integration [s].
    energy : EnergyAudit or None
        Energy balance over the run.
    signals : dict of str -> Signal
        What each series is (unit, kind, details), declared by the solver that made it
        (:mod:`components.model.signals`); analyses select series and read units from it.
    """

    time_s: np.ndarray
    series: dict[str, np.ndarray]
    complete: bool = True
    message: str = ""
    wall_time_s: float = 0.0
    energy: EnergyAudit | None = None
    info: dict = field(default_factory=dict)
    signals: dict[str, Signal] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.series[name]
        except KeyError:
            raise KeyError(f"no variable {name!r}; have {sorted(self.series)}") from None

    @property
    def names(self) -> list[str]:
        """Recorded variable names."""
        return list(self.series)

    def names_of(self, *kinds: str) -> list[str]:
        """The series declared as one of ``kinds`` (e.g. ``"contact_force"``), in recording order."""
        return [n for n in self.series if n in self.signals and self.signals[n].kind in kinds]

    @property
    def units(self) -> dict[str, str]:
        """The declared unit of every declared series."""
        return {n: self.signals[n].unit for n in self.series if n in self.signals}

    def statistics(self, window: tuple[float, float] | None = None, names=None) -> dict[str, dict[str, float]]:
        """Statistics of each variable over ``window`` [s]."""
        names = self.names if names is None else names
        return {n: window_statistics(self.time_s, self.series[n], window) for n in names}


def series_and_time(
    result: SimulationResult | Mapping[str, np.ndarray], time_s: np.ndarray | None
) -> tuple[Mapping[str, np.ndarray], np.ndarray]:
    """The series and sample times [s] of a :class:`SimulationResult` or of a plain mapping.

    Raises
    ------
    ParameterError
        If ``result`` is a plain mapping and ``time_s`` is None.
    """
    if isinstance(result, SimulationResult):
        return result.series, result.time_s
    if time_s is None:
        raise ParameterError("time_s", None, "sample times for a plain mapping of series")
    return result, time_s
