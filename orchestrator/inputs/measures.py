"""What a study computes per run: built-in measures and summary statistics.

Measures are written as text in a study file:

``I_max_acc`` [rad/s^2]
    Eq. 11: ``max_t |d omega_out / dt|`` over the whole run (not only the
    analysis window), the output gear being the last stage's output member.
    Monolithic engine: evaluated from the ODE right-hand side at every accepted
    LSODA step and refined with the solver's interpolant around the maximum
    (:func:`components.reference.acceleration.peak_output_acceleration`), a second
    integration whose cost is not part of ``cpu_time``. Co-simulation engine:
    the Gearbox FMU's ``alpha_out_max`` at the end of the run, the running
    maximum of ``|d omega_out/dt|`` over every accepted internal step of its
    integrator (it resolves tooth impacts far shorter than the communication
    step; no interpolant refinement, so it can sit slightly below the monolithic
    value). A Gearbox FMU without that output (built by an older dtcosim): the
    largest finite difference of the recorded ``omega_out`` samples, a lower
    bound that cannot resolve pulses shorter than the sampling interval.
``cpu_time`` [s]
    Eq. 12: process CPU time of the integration, measured in the worker with
    ``time.process_time``. Monolithic: the LSODA integration alone (not the
    evaluation of the recorded variables). Co-simulation: the master's run from
    instantiation to freeing the FMUs (pythonfmu FMUs run inside the worker's
    process, so their work counts).
``wall_time`` [s]
    Wall-clock time of the same span.
``steps``, ``rhs_calls`` [-]
    Internal LSODA steps and right-hand-side evaluations of the timed
    integration (monolithic engine only).
``<component>.<variable>:<statistic>``
    A statistic of a recorded variable over the analysis window, e.g.
    ``gearbox.stage1.F_sp[1]:std``; statistics ``mean``, ``std``, ``min``,
    ``max``, ``absmax`` (largest magnitude), ``rms``, or ``del<m>`` (e.g.
    ``del4``): the damage-equivalent load for the Woehler exponent ``m``,
    rainflow-counted over the window with :class:`components.analysis.fatigue.FatigueSettings`'
    defaults (``N_ref`` = 1 Hz x window length, half-cycle residue), the value a
    run's ``fatigue_del.csv`` gives with a default ``[analysis]``. Units as in
    ``timeseries.csv`` (SI): the unit the base declares for the variable - its FMU
    for a scenario base, the monolithic solver's result for a model base - set by
    :func:`orchestrator.study.prepare.prepare_study` (``-`` when it declares none);
    a name never gives a unit, so a parsed statistic has none until then.
``<component>.<stage>:load_sharing`` [-]
    The planet load-sharing factor of a planetary stage of a gearbox, e.g.
    ``gearbox.stage1:load_sharing``: over the analysis window the largest ratio of
    the most loaded planet's sun-mesh force to the planets' mean
    (:mod:`components.analysis.load_sharing`), from the contact forces the gearbox
    declares for that stage (recorded for the study).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from components.errors import DtcosimError

#: built-in measures: name -> (unit, description, engines)
BUILTIN: dict[str, tuple[str, str, tuple[str, ...]]] = {
    "I_max_acc": ("rad/s2", "peak output-gear acceleration max |d omega_out/dt| (eq. 11)", ("cosim", "monolithic")),
    "cpu_time": ("s", "CPU time of the integration (eq. 12)", ("cosim", "monolithic")),
    "wall_time": ("s", "wall-clock time of the integration", ("cosim", "monolithic")),
    "steps": ("1", "internal solver steps", ("monolithic",)),
    "rhs_calls": ("1", "right-hand-side evaluations", ("monolithic",)),
}
STATISTICS = ("mean", "std", "min", "max", "absmax", "rms")
#: statistics of a planetary stage (``component.stage:<name>``) rather than of one variable
STAGE_STATISTICS = ("load_sharing",)
#: ``del<m>``: damage-equivalent load for the Woehler exponent m (> 0)
_DEL_RE = re.compile(r"^del(\d+(?:\.\d+)?)$")


def wohler_exponent_of(stat: str) -> float | None:
    """``m`` of a ``del<m>`` statistic (``"del4"`` -> 4.0), None for any other name."""
    match = _DEL_RE.match(stat)
    m = float(match.group(1)) if match else None
    return m if m is not None and math.isfinite(m) and m > 0 else None


class MeasureError(DtcosimError, ValueError):
    """A measure name cannot be parsed (``expected`` says what would be)."""

    def __init__(self, text: object, expected: str) -> None:
        self.text = text
        self.expected = expected
        super().__init__(f"invalid measure {text!r}: expected {expected}")

    def __reduce__(self):
        return (type(self), (self.text, self.expected))


@dataclass(frozen=True)
class Measure:
    """One measure of a study.

    Attributes
    ----------
    name : str
        As written, e.g. ``"I_max_acc"`` or ``"gearbox.stage3.F_mesh:max"``.
    variable : str or None
        ``"component.variable"`` of a statistic (None for a built-in measure).
    statistic : str or None
        One of :data:`STATISTICS` (None for a built-in measure).
    unit : str
        SI unit of the value (``"1"``: dimensionless); of a statistic the unit its base declares for the
        variable, ``""`` until :func:`orchestrator.study.prepare.prepare_study` sets it.
    description : str
    """

    name: str
    variable: str | None
    statistic: str | None
    unit: str
    description: str

    @property
    def of_stage(self) -> bool:
        """True for a statistic of a planetary stage (``gearbox.stage1:load_sharing``): ``variable`` names the stage."""
        return self.statistic in STAGE_STATISTICS

    @property
    def builtin(self) -> bool:
        """True for ``I_max_acc``, ``cpu_time``, ``wall_time``, ``steps``, ``rhs_calls``."""
        return self.variable is None

    @property
    def column(self) -> str:
        """CSV column header ``name [unit]``."""
        return f"{self.name} [{self.unit}]"

    @property
    def engines(self) -> tuple[str, ...]:
        """Engines that can compute it."""
        return BUILTIN[self.name][2] if self.builtin else ("cosim", "monolithic")


def parse_measure(text: object) -> Measure:
    """A :class:`Measure` from its name.

    Raises
    ------
    MeasureError
        Neither a built-in name nor ``component.variable:statistic``.
    """
    expected = ("a built-in measure (" + ", ".join(BUILTIN) + ") or 'component.variable:statistic' with statistic "
                + " | ".join(STATISTICS) + " | del<m> (damage-equivalent load, e.g. del4), or "
                "'component.stage:load_sharing'")
    if not isinstance(text, str) or not text:
        raise MeasureError(text, expected)
    if text in BUILTIN:
        unit, description, _ = BUILTIN[text]
        return Measure(text, None, None, unit, description)
    variable, colon, stat = text.rpartition(":")
    comp, dot, var = variable.partition(".")
    if stat in STAGE_STATISTICS and comp and var:
        return Measure(text, variable, stat, "1", f"planet load-sharing factor of {variable} (max over the window "
                       "of the largest planet's sun-mesh force over the mean)")
    m = wohler_exponent_of(stat)
    if not colon or not dot or not comp or not var or (stat not in STATISTICS and m is None):
        raise MeasureError(text, expected)
    what = stat if m is None else f"damage-equivalent load (m = {m:g}, N_ref = 1 Hz x window)"
    return Measure(text, variable, stat, "", f"{what} of {variable}")  # the unit: as the base declares it


