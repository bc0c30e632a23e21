"""SIGINT, SIGTERM and SIGHUP as requests to stop a run cleanly.

Ctrl-C sends SIGINT; a scheduler ending a job (``kill``, ``scancel``, a
container stopping) sends SIGTERM; a closed terminal sends SIGHUP. Inside a
:class:`StopRequests` block all three only set a flag: the master checks it
after each FMU is instantiated and between blocks of steps, the runner between
its result files. Nothing is interrupted half-way, in particular no Python code
running inside an FMU (pythonfmu runs the slaves in this interpreter; a
KeyboardInterrupt raised there would come back as a misleading FMU failure).

A second signal while the first is being honoured raises
:class:`~orchestrator.errors.RunInterrupted` at once (the user insists); files
are written by temporary file and rename, so that still leaves no half file.

Exit statuses follow the shell's convention ``128 + signal number``: 130 for
SIGINT, 143 for SIGTERM, 129 for SIGHUP (:func:`exit_status`).
"""

from __future__ import annotations

import signal

from ..errors import RunInterrupted, reason_of, signal_name
from ..import_safe_signals import install, restore

#: the signals that ask a run to stop
STOP_SIGNALS = tuple(s for s in (signal.SIGINT, getattr(signal, "SIGTERM", None), getattr(signal, "SIGHUP", None))
                     if s is not None)


def exit_status(signum: int) -> int:
    """``128 + signum`` (130 for Ctrl-C)."""
    return 128 + int(signum)


class StopRequests:
    """Turns :data:`STOP_SIGNALS` into a flag for the duration of a ``with`` block.

    Parameters
    ----------
    enabled : bool
        False: a flag that is never set (the process's handlers are left alone).

    Attributes
    ----------
    signum : int or None
        The first signal received.
    """

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled
        self.signum: int | None = None
        self._previous: dict[int, object] = {}

    def __enter__(self) -> "StopRequests":
        if self.enabled:
            self._previous = install(dict.fromkeys(STOP_SIGNALS, self._handler))
        return self

    def __exit__(self, *exc) -> None:
        restore(self._previous)
        self._previous = {}

    def _handler(self, signum, frame) -> None:
        if self.signum is None:
            self.signum = signum
            return
        raise RunInterrupted(signum, "a second signal", None)

    def request(self, signum: int = signal.SIGINT) -> None:
        """Ask the run to stop as if ``signum`` had arrived (tests, embedding applications)."""
        if self.signum is None:
            self.signum = signum

    @property
    def requested(self) -> bool:
        """True once a stop signal arrived."""
        return self.signum is not None

    @property
    def signal_name(self) -> str | None:
        return None if self.signum is None else signal_name(self.signum)

    @property
    def reason(self) -> str:
        """``"interrupted by SIGTERM"`` ("" before any request)."""
        return "" if self.signum is None else reason_of(self.signum)

    def raise_if_requested(self, stage: str, time_s: float | None = None) -> None:
        """Raise :class:`RunInterrupted` naming ``stage`` if a stop was requested."""
        if self.signum is not None:
            raise RunInterrupted(self.signum, stage, time_s)
