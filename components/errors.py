"""Exception classes raised by the physics core.

Every error that a user can cause by a bad input is a :class:`ParameterError`
that names the parameter, the offending value and what was expected, and it is
raised on construction of the parameter set, before anything is integrated.
"""

from __future__ import annotations

from typing import Any


class DtcosimError(Exception):
    """Base class of every error raised by dtcosim."""


class ParameterError(DtcosimError, ValueError):
    """A parameter has a value outside its admissible range.

    Parameters
    ----------
    name : str
        Dotted name of the parameter, e.g. ``"stage1.planet_inertia_kgm2"``.
    value : Any
        The rejected value.
    expected : str
        Human-readable description of what is admissible, e.g. ``"> 0"``.
    bounds : components.validation.Bounds, optional
        The admissible range as numbers, when it is a simple one (the validators
        of :mod:`components.validation` attach it; FMU builds publish it).
    """

    def __init__(self, name: str, value: Any, expected: str, bounds: Any = None) -> None:
        self.name = name
        self.value = value
        self.expected = expected
        self.bounds = bounds
        super().__init__(f"invalid parameter {name} = {value!r}: expected {expected}")

    def __reduce__(self):  # keep the exception picklable (Dask ships it between processes)
        return (type(self), (self.name, self.value, self.expected, self.bounds))


class SolverError(DtcosimError, RuntimeError):
    """The time integration failed.

    Parameters
    ----------
    message : str
        What went wrong.
    time_s : float
        Simulation time [s] at which the integrator stopped.
    """

    def __init__(self, message: str, time_s: float) -> None:
        self.time_s = float(time_s)
        super().__init__(f"{message} (at t = {self.time_s:.6g} s)")

    def __reduce__(self):
        return (type(self), (str(self).rsplit(" (at t =", 1)[0], self.time_s))


class WallTimeLimitError(SolverError):
    """The integration ran into its wall-clock time limit (``SolverSettings.wall_time_limit_s``).

    Parameters
    ----------
    limit_s : float
        The limit [s] of wall-clock time.
    time_s : float
        Simulation time [s] reached.
    """

    def __init__(self, limit_s: float, time_s: float) -> None:
        self.limit_s = float(limit_s)
        SolverError.__init__(self, f"wall-time limit of {self.limit_s:g} s reached", time_s)

    def __reduce__(self):
        return (type(self), (self.limit_s, self.time_s))


def os_error_text(exc: OSError, named: str | None = None) -> str:
    """What an OSError says, as a message quotes it: ``"<file>: <reason>"``, or ``"<reason>"`` where it names no file
    or the file ``named`` (the one the message names already)."""
    where = f"{exc.filename}: " if exc.filename not in (None, named) else ""
    return f"{where}{exc.strerror or exc}"
