"""The physics behind a scenario's FMUs, read from their records (never guessed).

Every dtcosim FMU records the parameter set it was built from
(``resources/dtcosim.json``: the Gearbox its drivetrain structure and defaults,
the WindSource and GeneratorRotor their parameter sets). The physics of a
scenario is that record with the scenario's parameter values applied through the
same flat parameter maps the FMUs use (:mod:`components.model.parameter_map`),
so the monolithic reference, ``--compare-reference``, ``dtcosim modes SCENARIO``,
the run analyses and the study engine all see exactly the system the FMUs
simulate. This module is the one place that builds it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Mapping

from components.errors import DtcosimError, ParameterError
from components.model.description import build
from components.model.drivetrain import Drivetrain
from components.model.generator import GeneratorParameters
from components.model.rotor import RotorParameters, rotor_from_values
from components.model.torque_controller import TorqueLawParameters, controller_from_values
from components.model.parameter_map import (
    flatten,
    generator_from_values,
    unflatten,
    wind_from_values,
)
from components.model.wind import WindParameters

from ..frozen_map import FrozenMap
from .roles import GEARBOX, GENERATOR, ROTOR, TORQUE_CONTROLLER, WIND_SOURCE, ComponentRole
from .resolved import ResolvedSystem


class PhysicsUnavailable(DtcosimError, ValueError):
    """The scenario's physics cannot be built from its FMUs' records (the message says why)."""


@dataclass(frozen=True)
class PhysicsView:
    """The whole drivetrain of a scenario of a wind source, a gearbox and a generator.

    Attributes
    ----------
    drivetrain : Drivetrain
        The gearbox of the Gearbox FMU's record with the scenario's values, and the
        generator of the GeneratorRotor FMU (inertia, counter torque, load events).
    wind : WindParameters
        The rotor-speed process of the WindSource FMU.
    components : mapping of str -> str
        Role -> component name.
    sources : mapping of str -> str
        Role -> what that FMU was built from (``"preset table6"``, a drivetrain file).
    notes : tuple of str
        Differences between the co-simulation set-up and this monolithic description.
    start : {"operating_point", "rest"}
        Where the Gearbox starts (its parameter ``start_at_rest``): the monolithic reference starts there too.
    """

    drivetrain: Drivetrain
    wind: WindParameters
    components: Mapping[str, str]
    sources: Mapping[str, str]
    notes: tuple[str, ...] = ()
    start: str = "operating_point"


def dtcosim_component(system: ResolvedSystem, role: str) -> ComponentRole:
    """The one component with ``role`` whose FMU carries a dtcosim record.

    Raises
    ------
    PhysicsUnavailable
        None or several such components (the message names them).
    """
    found = [r for r in system.with_role(role) if r.record is not None]
    if len(found) != 1:
        others = [r.component for r in system.with_role(role) if r.record is None]
        extra = f"; {', '.join(others)} declared {role} without a dtcosim record" if others else ""
        names = f" ({', '.join(r.component for r in found)})" if found else ""
        raise PhysicsUnavailable(f"needs exactly one dtcosim FMU with the role {role}; the scenario has "
                                 f"{len(found)}{names}{extra}")
    return found[0]


def _values(system: ResolvedSystem, component: str) -> dict:
    return system.parameter_values(component)


def gearbox_drivetrain(system: ResolvedSystem, component: str) -> Drivetrain:
    """The drivetrain of a Gearbox FMU's record with the component's effective parameter values.

    The generator in it is the record's default (the Gearbox FMU has no generator
    parameters); :func:`physics_view` puts the GeneratorRotor's in.
    """
    role = system.roles.get(component)
    if role is None or role.role != GEARBOX or role.record is None:
        raise PhysicsUnavailable(f"{component} is not a dtcosim Gearbox FMU (it has no record of its drivetrain)")
    template = build(role.record["model"]["drivetrain"], "model.drivetrain")
    values = _values(system, component)
    flat = {k: values[k] for k in flatten(template) if k in values}
    try:
        return unflatten(template, flat)
    except ParameterError as exc:
        raise PhysicsUnavailable(f"{component}: {exc}") from None


def _from_record(system: ResolvedSystem, component: str, role_name: str, fmu: str, key: str, what: str,
                 from_values):
    """``from_values(effective values, record model[key])`` of a dtcosim FMU of ``role_name``, errors as PhysicsUnavailable."""
    role = system.roles.get(component)
    if role is None or role.role != role_name or role.record is None:
        raise PhysicsUnavailable(f"{component} is not a dtcosim {fmu} FMU (it has no record of its {what})")
    try:
        return from_values(_values(system, component), build(role.record["model"][key], f"model.{key}"))
    except ParameterError as exc:
        raise PhysicsUnavailable(f"{component}: {exc}") from None


def wind_parameters(system: ResolvedSystem, component: str) -> WindParameters:
    """The rotor-speed process of a WindSource FMU's record with the component's effective parameter values."""
    return _from_record(system, component, WIND_SOURCE, "WindSource", "wind", "wind model", wind_from_values)


def generator_parameters(system: ResolvedSystem, component: str) -> GeneratorParameters:
    """The generator of a GeneratorRotor FMU's record with the component's effective values (events included)."""
    return _from_record(system, component, GENERATOR, "GeneratorRotor", "generator", "generator",
                        generator_from_values)


def rotor_parameters(system: ResolvedSystem, component: str) -> RotorParameters:
    """The rotor (and main shaft) of a Rotor FMU's record with the component's effective parameter values."""
    return _from_record(system, component, ROTOR, "Rotor", "rotor", "rotor", rotor_from_values)


def controller_parameters(system: ResolvedSystem, component: str) -> TorqueLawParameters:
    """The torque law of a TorqueController FMU's record with the component's effective parameter values."""
    return _from_record(system, component, TORQUE_CONTROLLER, "TorqueController", "controller", "law",
                        controller_from_values)


def drivetrain_with_generator(system: ResolvedSystem) -> tuple[Drivetrain, ComponentRole, ComponentRole]:
    """The Gearbox FMU's drivetrain with the GeneratorRotor FMU's generator, and the two components.

    Raises
    ------
    PhysicsUnavailable
        Either role missing or doubled, a foreign FMU in it, a gearbox without a generator shaft.
    """
    gear_c = dtcosim_component(system, GEARBOX)
    gen_c = dtcosim_component(system, GENERATOR)
    drivetrain = gearbox_drivetrain(system, gear_c.component)
    if drivetrain.generator is None:
        raise PhysicsUnavailable(f"{gear_c.component}: its record has no generator shaft (not a co-simulation gearbox)")
    return replace(drivetrain, generator=generator_parameters(system, gen_c.component)), gear_c, gen_c


def physics_view(system: ResolvedSystem) -> PhysicsView:
    """The monolithic description of a scenario of one dtcosim WindSource, Gearbox and GeneratorRotor.

    Raises
    ------
    PhysicsUnavailable
        A role missing or doubled, a foreign FMU in one of the roles, or values the
        model rejects.
    """
    wind_c = dtcosim_component(system, WIND_SOURCE)
    drivetrain, gear_c, gen_c = drivetrain_with_generator(system)
    notes = []
    bound = {str(b.target) for b in system.scenario.initial}
    if f"{gen_c.component}.initial_speed" not in bound:
        notes.append("the generator's initial speed is not bound to the gearbox output speed; the reference starts "
                     "kinematically consistent")
    components = {WIND_SOURCE: wind_c.component, GEARBOX: gear_c.component, GENERATOR: gen_c.component}
    sources = {role: str(system.roles[name].record.get("source", "")) for role, name in components.items()}
    start = "rest" if _values(system, gear_c.component).get("start_at_rest") else "operating_point"
    return PhysicsView(drivetrain, wind_parameters(system, wind_c.component), FrozenMap(components),
                       FrozenMap(sources), tuple(notes), start)


@dataclass(frozen=True)
class RotorDrivenView:
    """The drivetrain of a scenario whose Gearbox a torque-driven Rotor FMU drives.

    Attributes
    ----------
    drivetrain : Drivetrain
        The Gearbox FMU's drivetrain with the GeneratorRotor's generator.
    rotor : RotorParameters
        The Rotor FMU's rotor (and main shaft) with the scenario's values.
    initial_speed_rad_s : float
        The Rotor's ``initial_speed`` parameter (a scenario may bind it at run time from a record).
    components : mapping of str -> str
        Role -> component name.
    """

    drivetrain: Drivetrain
    rotor: RotorParameters
    initial_speed_rad_s: float
    components: Mapping[str, str]


def rotor_driven_view(system: ResolvedSystem) -> RotorDrivenView:
    """The drivetrain, rotor and initial rotor speed of a scenario of one dtcosim Rotor, Gearbox and GeneratorRotor.

    Raises
    ------
    PhysicsUnavailable
        A role missing or doubled, a foreign FMU in one of the roles, or values the model rejects.
    """
    rotor_c = dtcosim_component(system, ROTOR)
    drivetrain, gear_c, gen_c = drivetrain_with_generator(system)
    rotor = rotor_parameters(system, rotor_c.component)
    components = {ROTOR: rotor_c.component, GEARBOX: gear_c.component, GENERATOR: gen_c.component}
    return RotorDrivenView(drivetrain, rotor, float(_values(system, rotor_c.component)["initial_speed"]),
                           FrozenMap(components))
