"""What a co-simulation run produced: its samples, how it ended and what it cost.

:class:`RunOutcome` is returned by :meth:`orchestrator.cosim.master.CoSimulation.run`
and read by the run's writers, analyses, plots, comparisons and the studies.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .resolved import RecordedVariable


@dataclass
class RunOutcome:
    """What a co-simulation run produced.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        Sample times [s].
    values : ndarray, shape (n, m)
        Recorded variables, columns as ``columns``.
    columns : tuple of RecordedVariable
    complete : bool
        True if the run reached the stop time.
    steps : int
        Communication steps completed (the samples cover the sampled ones among them).
    stopped_at_s : float
        Time of the last completed communication point [s].
    error : str or None
        Why the run stopped early (FMU failure, interruption, a results file that could not be written).
    interrupted : bool
        True if stopped by a signal (Ctrl-C, SIGTERM, SIGHUP).
    stop_signal : str or None
        Name of that signal (``"SIGINT"``, ...).
    stage : str
        Where the run ended: ``"stepping"`` (also when complete), ``"writing"`` (the sink failed),
        or, for outcomes built by a caller after an exception, ``"instantiation"``/``"initialisation"``.
    wall_time_s : float
        Whole run: instantiation, initialisation, stepping, cleanup [s].
    loop_time_s : float
        Stepping loop only [s].
    cpu_time_s, loop_cpu_time_s : float
        Process CPU time [s] of the whole run and of the stepping loop (the FMUs run in
        this process, so it includes their work; use it for benchmarks on a shared machine).
    initial_values : dict of str -> float
        Values transferred by the initialisation sweeps (``"generator.omega0"`` ...).
    start_values : dict of str -> float
        Every value transferred in initialisation: the bindings and the connected inputs
        (``"gearbox.omega_rotor"`` ...): the operating point the run starts at.
    fmu_log : dict of str -> list of str
        Last log messages of each FMU.
    profile : dict of str -> dict of str -> float, optional
        With profiling on: seconds spent in each FMI function per component,
        ``{"gearbox": {"fmi2SetReal": ..., "fmi2DoStep": ..., "fmi2GetReal": ...}}``.
    text : dict of str -> ndarray of object
        Samples of the recorded String variables by column name (their ``values``
        column is NaN); Integer, Enumeration and Boolean columns are in ``values``
        as exact floats (Boolean 0.0/1.0).
    ended_by : str or None
        The FMU that ended the run by terminating (``fmi2Discard`` with
        ``fmi2Terminated``); the run is then complete at ``stopped_at_s``.
    """

    time_s: np.ndarray
    values: np.ndarray
    columns: tuple[RecordedVariable, ...]
    complete: bool
    steps: int
    stopped_at_s: float
    error: str | None = None
    interrupted: bool = False
    wall_time_s: float = 0.0
    loop_time_s: float = 0.0
    cpu_time_s: float = 0.0
    loop_cpu_time_s: float = 0.0
    initial_values: dict[str, float] = field(default_factory=dict)
    start_values: dict[str, float] = field(default_factory=dict)
    fmu_log: dict[str, list[str]] = field(default_factory=dict)
    profile: dict[str, dict[str, float]] | None = None
    stop_signal: str | None = None
    stage: str = "stepping"
    text: dict[str, np.ndarray] = field(default_factory=dict)
    ended_by: str | None = None

    @classmethod
    def empty(cls, columns: tuple[RecordedVariable, ...], start_s: float, error: str, stage: str,
              interrupted: bool = False, stop_signal: str | None = None,
              fmu_log: dict[str, list[str]] | None = None) -> "RunOutcome":
        """The outcome of a run that stopped before its first sample (instantiation or initialisation)."""
        return cls(time_s=np.empty(0), values=np.empty((0, len(columns))), columns=tuple(columns), complete=False,
                   steps=0, stopped_at_s=start_s, error=error, interrupted=interrupted, stop_signal=stop_signal,
                   stage=stage, fmu_log=dict(fmu_log or {}))

    def column(self, name: str) -> np.ndarray:
        """Samples of ``"component.variable"`` (strings for a String variable)."""
        if name in self.text:
            return self.text[name]
        for i, c in enumerate(self.columns):
            if c.column == name:
                return self.values[:, i]
        raise KeyError(f"{name!r} was not recorded; recorded: {', '.join(c.column for c in self.columns)}")

    @property
    def names(self) -> list[str]:
        """Recorded column names."""
        return [c.column for c in self.columns]
