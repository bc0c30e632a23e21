"""The drivetrain a scenario starts from: its physics behind the FMUs at the operating point of its initialisation.

:func:`drivetrain_at_start` rebuilds the drivetrain behind a scenario's dtcosim FMUs
(:func:`~orchestrator.cosim.physics_view.drivetrain_with_generator`) and reads its operating
point from what the initialisation transferred: the Gearbox's ``omega_rotor`` (or the wind's
mean speed where a WindSource drives it) and its ``counter_torque`` (else the generator's). The
rotor is held where the rotor speed is prescribed and free where a torque-driven Rotor FMU
drives the Gearbox. :func:`start_analyses` turns it into the settling time of
:mod:`components.analysis.settling` (the time a run's analysis window should start after) and
the limits that resolve the modes split across FMUs (:mod:`components.analysis.coupling_step`:
the longest step and output interval, the shortest window).
Both are used by ``dtcosim modes``, by every run (``summary.json`` ``settling``) and by the
load-case sets (``runs.transient = "settled"``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Mapping, NamedTuple

from components.analysis.coupling_step import CouplingLimit, coupling_limit
from components.analysis.equilibrium import OperatingPoint, linearise
from components.analysis.rotor_coupling import ROTOR_BODY, coupled
from components.analysis.settling import Settling, model_settling
from components.model.drivetrain import Drivetrain
from components.model.generator import GENERATOR_BODY, GeneratorParameters
from components.model.rotor import RotorParameters

from .physics_view import PhysicsUnavailable, drivetrain_with_generator, physics_view, rotor_driven_view
from .roles import GENERATOR, ROTOR, WIND_SOURCE
from .resolved import ResolvedSystem


@dataclass(frozen=True)
class StartPoint:
    """A scenario's drivetrain and the operating point it starts at.

    Attributes
    ----------
    drivetrain : Drivetrain
        With the generator's inertia and base counter torque (no load events).
    rotor : RotorParameters or None
        The torque-driven rotor; None: the rotor speed is held (prescribed).
    operating_point : OperatingPoint
    source : str
        Where speed and torque came from.
    """

    drivetrain: Drivetrain
    rotor: RotorParameters | None
    operating_point: OperatingPoint
    source: str


def drivetrain_at_start(system: ResolvedSystem, start_values: Mapping[str, Any] | None = None) -> StartPoint:
    """The drivetrain and operating point of a resolved system (see the module docstring).

    ``start_values``: what the initialisation transferred (``RunOutcome.start_values``); None:
    instantiate and initialise the FMUs once to get them.

    Raises
    ------
    PhysicsUnavailable
        A scenario without one dtcosim Gearbox (a third-party FMU, a system without a drivetrain)
        or whose Gearbox's rotor speed is not connected.
    """
    dt, gear_c, _ = drivetrain_with_generator(system)
    rotor = rotor_driven_view(system).rotor if any(r.record is not None for r in system.with_role(ROTOR)) else None
    wind = physics_view(system).wind if rotor is None and any(
        r.record is not None for r in system.with_role(WIND_SOURCE)) else None
    if start_values is None:
        from .master import CoSimulation

        start_values = CoSimulation(system).initial_values(transferred=True)
    speed_key, torque_key = f"{gear_c.component}.omega_rotor", f"{gear_c.component}.counter_torque"
    if wind is not None:
        omega0, speed_source = wind.mean_speed_rad_s, "the wind's mean speed"
    elif speed_key in start_values:
        omega0, speed_source = float(start_values[speed_key]), f"{speed_key} at the start"
    else:
        raise PhysicsUnavailable(f"a scenario that connects {speed_key}")
    if dt.generator.events:
        dt = replace(dt, generator=GeneratorParameters(dt.generator.inertia_kgm2, dt.generator.counter_torque_nm))
    torque, torque_source = dt.generator.counter_torque_nm, "the generator's counter_torque"
    if torque_key in start_values and float(start_values[torque_key]) != 0.0:
        torque, torque_source = float(start_values[torque_key]), f"{torque_key} at the start"
    return StartPoint(dt, rotor, OperatingPoint(omega0, torque), f"{speed_source}; {torque_source}")


class StartAnalyses(NamedTuple):
    """What a scenario's drivetrain at its start says about a run of it (None where it says nothing)."""

    #: the settling time (:mod:`components.analysis.settling`): when a run's analysis window should start
    settling: Settling | None
    #: the longest step and output interval, and the shortest window, that resolve the modes split across FMUs
    #: (:mod:`components.analysis.coupling_step`)
    coupling: CouplingLimit | None


def start_analyses(system: ResolvedSystem, start_values: Mapping[str, Any] | None = None) -> StartAnalyses:
    """The settling time and the coupling limit of a scenario's drivetrain at its start, from one start point and one
    linearisation; both None where there is no dtcosim drivetrain (``start_values``: see :func:`drivetrain_at_start`).

    The modes split across FMUs are the generator's where a generator FMU of its own drives the Gearbox, and a
    torque-driven rotor's. Raises nothing for a drivetrain the modal analysis cannot linearise either (None): both
    are statements about a run, never reasons to refuse one.
    """
    try:
        start = drivetrain_at_start(system, start_values)
        model = coupled(linearise(start.drivetrain, start.operating_point), start.rotor)
    except (PhysicsUnavailable, ValueError, ArithmeticError, KeyError):  # numpy's LinAlgError is a ValueError
        return StartAnalyses(None, None)
    split = [GENERATOR_BODY] if system.with_role(GENERATOR) else []
    split += [ROTOR_BODY] if start.rotor is not None else []
    return StartAnalyses(_or_none(model_settling, model), _or_none(coupling_limit, model, split))


def _or_none(analysis, *args):
    """``analysis(*args)``, or None where the linear model has no answer (no decaying mode, a singular matrix)."""
    try:
        return analysis(*args)
    except (ValueError, ArithmeticError):
        return None


def window_note(settling: Settling, window_start_s: float, start_s: float, what: str) -> str | None:
    """A warning when a window starts before the run has settled (None: it starts after)."""
    settled_at = start_s + settling.time_s
    if window_start_s + 1e-9 >= settled_at:
        return None
    return (f"{what} starts at {window_start_s:g} s, {settled_at - window_start_s:.3g} s before the drivetrain has "
            f"settled at {settled_at:.3g} s ({settling.describe()}): the statistics include what is left of the "
            f"start-up; start the window at {settled_at:.3g} s or later")
