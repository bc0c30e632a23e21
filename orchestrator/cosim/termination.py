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
successful time the FMU reports. So does a "termination" without progress (last
successful time ``t_k`` or none): pythonfmu 0.7 FMUs answer ``fmi2Terminated =
true`` after *every* discarded step, also when their solver failed and they kept
the state at ``t_k`` (dtcosim's Gearbox), which is a failure, not an end.
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
    progressed : bool
        The last successful time is after the start of the step ``t_k``.
    """

    terminated: bool
    last_successful_time_s: float | None
    reached_step_end: bool
    progressed: bool

    @property
    def ends_run(self) -> bool:
        """The FMU ended the simulation: terminated after computing past ``t_k``."""
        return self.terminated and self.progressed

    def note(self) -> str:
        """Text appended to the failure message of a discard that does not end the run."""
        last = self.last_successful_time_s
        when = "no last successful time" if last is None else f"last successful time {last:.9g} s"
        if self.terminated:
            return f"; the FMU reports fmi2Terminated without progress in the step ({when}): a failed step"
        return f"; the FMU did not terminate ({when})"


def discard_status(inst: FmuInstance, function: str, status: int, step_start_s: float,
                   step_end_s: float) -> Discard | None:
    """The FMU's termination status after a discarded ``fmi2DoStep``; None for any other failure."""
    if function != "fmi2DoStep" or status != FMI_DISCARD:
        return None
    terminated, last = inst.termination_status()
    tol = TIME_RTOL * max(1.0, abs(step_end_s))
    reached = last is not None and abs(last - step_end_s) <= tol
    progressed = last is not None and last > step_start_s + tol
    return Discard(terminated, last, reached, progressed)
