"""An FMU that ends the simulation itself (FMI 2.0 co-simulation, section 4.2.3).

When ``fmi2DoStep`` returns ``fmi2Discard`` the master asks the FMU
``fmi2GetBooleanStatus(fmi2Terminated)``: an FMU that says it terminated has
ended the simulation (the Reference-FMU Stair does so when its counter reaches
10), and ``fmi2GetRealStatus(fmi2LastSuccessfulTime)`` tells up to when it
computed. The run then ends *normally* (complete, exit status 0, ``ended_by``
naming the FMU):

* at ``t_{k+1}`` when the FMU's last successful time is the end of the step
  (the usual case): the other FMUs finish the step as usual and the outputs at
  ``t_{k+1}`` are the last sample, also off the output grid;
* at ``t_k`` when it stopped inside the step (the last sample is the one at ``t_k``).

A discard without termination stays a failure; its message then gives the last
successful time the FMU reports.
"""

from __future__ import annotations

from dataclasses import dataclass

from .fmi_runtime import FmuInstance

FMI_DISCARD = 2
#: relative tolerance when comparing the last successful time with the end of the step
TIME_RTOL = 1e-9


@dataclass(frozen=True)
class Discard:
    """What an FMU says after ``fmi2DoStep`` returned ``fmi2Discard``.

    Attributes
    ----------
    terminated : bool
        ``fmi2Terminated``: the FMU ended the simulation.
    last_successful_time_s : float or None
        ``fmi2LastSuccessfulTime`` (None when the FMU cannot tell).
    reached_step_end : bool
        The last successful time is the end of the discarded step ``t_{k+1}``.
    """

    terminated: bool
    last_successful_time_s: float | None
    reached_step_end: bool

    def note(self) -> str:
        """Text appended to the failure message of a discard without termination."""
        if self.last_successful_time_s is None:
            return "; the FMU did not terminate and reports no last successful time"
        return f"; the FMU did not terminate, last successful time {self.last_successful_time_s:.9g} s"


def discard_status(inst: FmuInstance, function: str, status: int, step_end_s: float) -> Discard | None:
    """The FMU's termination status after a discarded ``fmi2DoStep``; None for any other failure."""
    if function != "fmi2DoStep" or status != FMI_DISCARD:
        return None
    terminated, last = inst.termination_status()
    reached = last is not None and abs(last - step_end_s) <= TIME_RTOL * max(1.0, abs(step_end_s))
    return Discard(terminated, last, reached)
