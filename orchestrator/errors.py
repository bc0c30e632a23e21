"""Exceptions raised by the orchestrator.

Every mistake a user can make in a scenario is a :class:`ScenarioError` naming the
offending key (``"simulation.step"``, ``"connections[2].to"``,
``"components.gearbox.parameters.stage1.k0"``), its value and what was expected.
Scenario errors are raised while the scenario is loaded and checked against the
FMUs' model descriptions, before any FMU is instantiated.

Failures while the co-simulation runs are :class:`FmuStepError` (an FMU returned
fmi2Discard, fmi2Error or fmi2Fatal) and name the component, the FMI function,
the simulation time and the status, plus the FMU's last log messages.
"""

from __future__ import annotations

import difflib
from typing import Any

from components.errors import DtcosimError

FMI_STATUS_LABELS = ("ok", "warning", "discard", "error", "fatal", "pending")


def suggestion(name: str, choices, n: int = 3) -> str:
    """`` (did you mean a, b?)`` with up to ``n`` close matches of ``name`` among ``choices``, or ``""``."""
    close = difflib.get_close_matches(name, list(choices), n=n, cutoff=0.6)
    return f" (did you mean {', '.join(close)}?)" if close else ""


def status_label(status: int) -> str:
    """Readable name of an FMI 2 status code (``3`` -> ``"error"``)."""
    return FMI_STATUS_LABELS[status] if 0 <= status < len(FMI_STATUS_LABELS) else f"illegal status {status}"


class EntryError(DtcosimError, ValueError):
    """An entry of a user's input file (or of the objects built from it) is invalid.

    The message reads ``"<source>: invalid <kind> entry <key> = <value>: expected <expected>"``,
    ``kind`` a class attribute of each subclass.

    Parameters
    ----------
    key : str
        Dotted path of the offending entry, e.g. ``"connections[2].to"``.
    value : Any
        The rejected value.
    expected : str
        What would have been accepted.
    source : str, optional
        File the entry was read from (prefixed to the message).
    """

    kind = "input"

    def __init__(self, key: str, value: Any, expected: str, source: str | None = None) -> None:
        self.key = key
        self.value = value
        self.expected = expected
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}invalid {self.kind} entry {key} = {value!r}: expected {expected}")

    def __reduce__(self):  # picklable: Dask may ship it between processes
        return (type(self), (self.key, self.value, self.expected, self.source))


class ScenarioError(EntryError):
    """A scenario (TOML file, SSP or the objects built from them) is invalid."""

    kind = "scenario"


class AlgebraicLoopError(ScenarioError):
    """The connections close a loop of direct-feedthrough dependencies.

    A fixed-step master without iteration cannot solve such a loop; the message
    lists the variables on the cycle.
    """

    def __init__(self, cycle: list[str], source: str | None = None, hint: str = "") -> None:
        self.cycle = list(cycle)
        self.hint = hint
        ScenarioError.__init__(
            self,
            "connections",
            " -> ".join(self.cycle),
            "no algebraic loop: every cycle of connections must pass through an output that does not "
            "depend directly on the FMU's inputs (ModelStructure dependencies)" + (f"; {hint}" if hint else ""),
            source,
        )

    def __reduce__(self):
        return (type(self), (self.cycle, self.source, self.hint))


class InitializationError(DtcosimError, RuntimeError):
    """The initial values could not be propagated (FMI call failed or no fixed point)."""


#: what pythonfmu 0.7's C wrapper logs after any Python exception in a slave ("... PyObject_CallMethod unknown error")
_WRAPPER_NOISE = "Fatal py exception encountered"


class FmuStepError(DtcosimError, RuntimeError):
    """An FMU returned a status worse than fmi2Warning during the run.

    Parameters
    ----------
    component : str
        Instance name in the scenario (e.g. ``"gearbox"``).
    function : str
        FMI function that failed (``"fmi2DoStep"``, ``"fmi2GetReal"``, ...).
    time_s : float
        Communication point at which the call was made [s].
    status : int
        FMI status code (2 discard, 3 error, 4 fatal).
    log : list of str
        The FMU's last log messages (may be empty).
    """

    def __init__(self, component: str, function: str, time_s: float, status: int, log: list[str] | None = None) -> None:
        self.component = component
        self.function = function
        self.time_s = float(time_s)
        self.status = int(status)
        self.log = list(log or [])
        # pythonfmu adds its own line after an exception the slave already explained: show the explanation
        shown = [m for m in self.log if _WRAPPER_NOISE not in m] or self.log
        detail = ("; FMU log: " + " | ".join(shown[-5:])) if shown else ""
        super().__init__(
            f"FMU {component!r}: {function} returned {status_label(self.status)} (status {self.status}) "
            f"at t = {self.time_s:.6g} s{detail}"
        )

    def __reduce__(self):
        return (type(self), (self.component, self.function, self.time_s, self.status, self.log))


class SspError(DtcosimError, ValueError):
    """An SSP file cannot be read or written (names the file and the problem)."""


def signal_name(signum: int) -> str:
    """``2`` -> ``"SIGINT"``."""
    import signal

    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


def reason_of(signum: int) -> str:
    """Why a run stopped, as a summary and the command line say it: ``"interrupted by SIGTERM"``."""
    import signal

    if signum == signal.SIGINT:
        return "interrupted by the user (Ctrl-C)"
    return f"interrupted by {signal_name(signum)}"


class RunInterrupted(KeyboardInterrupt):
    """A stop signal (SIGINT, SIGTERM, SIGHUP) ended a command before it could finish its current stage.

    A KeyboardInterrupt, so nothing that catches ``Exception`` swallows it; the
    command line turns it into one line and the exit status ``128 + signum``.

    Parameters
    ----------
    signum : int
        The signal.
    stage : str
        What was going on (``"instantiation"``, ``"initialisation"``, ...).
    time_s : float, optional
        Simulation time reached [s].
    """

    def __init__(self, signum: int, stage: str, time_s: float | None = None) -> None:
        self.signum = int(signum)
        self.stage = stage
        self.time_s = time_s
        at = f" at t = {time_s:.6g} s" if time_s is not None else ""
        super().__init__(f"{reason_of(self.signum)} during {stage}{at}")

    def __reduce__(self):
        return (type(self), (self.signum, self.stage, self.time_s))
