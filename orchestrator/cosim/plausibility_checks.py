"""A scenario's values judged by physics, before any FMU is instantiated.

The rules are :mod:`components.analysis.plausibility`; this module applies them to a resolved
system, through its FMUs' records (never by a file or variable name):

* the drivetrain of the dtcosim Gearbox FMU with the scenario's values (scenario parameters,
  ``--set``, a study point) against the same drivetrain as the FMU was built: the FMU's own
  values were judged where they were defined (its drivetrain file, or the paper's presets), so
  a failure is reported when the scenario introduces it - a value it changes, or a rule the FMU
  as built passes - at the rating the FMU records (its operating point's rotor speed and its
  generator's counter torque);
* the wind source's mean rotor speed, the generator's counter torque and load-event factors and
  a torque controller's torques against that rating (the combination of FMUs is the scenario's).

A key the scenario keeps on purpose is named in its ``[plausibility] allow`` (or on the command
line, ``--allow-implausible COMPONENT.PARAMETER``); each must name a parameter of its FMU.
"""

from __future__ import annotations

from typing import Any

from components.analysis.plausibility import Judgement, Rating, implausible, judge, judge_operation
from components.model.description import build
from components.model.parameter_map import GENERATOR_FIELDS, WIND_FIELDS, flatten
from components.model.torque_controller import CONTROLLER_FIELDS

from ..errors import EntryError, ScenarioError, suggestion
from ..inputs.origins import responsible
from .physics_view import (
    PhysicsUnavailable,
    controller_parameters,
    dtcosim_component,
    gearbox_drivetrain,
    generator_parameters,
    wind_parameters,
)
from .roles import GEARBOX, GENERATOR, TORQUE_CONTROLLER, WIND_SOURCE

#: the FMU parameter of a field of a parameter set (the flat maps the FMUs use)
_WIND_SPEED = next(k for k, f in WIND_FIELDS.items() if f == "mean_speed_rad_s")
_COUNTER_TORQUE = next(k for k, f in GENERATOR_FIELDS.items() if f == "counter_torque_nm")
_CONTROLLER_TORQUES = {k: f for k, f in CONTROLLER_FIELDS.items() if f in ("rated_torque_nm", "max_torque_nm")}


def check_allowed(system) -> None:
    """Each ``[plausibility] allow`` entry names a parameter of its component's FMU.

    Raises
    ------
    ScenarioError
        ``plausibility.allow[i]`` naming the entry, with the closest parameter names.
    """
    scenario = system.scenario
    for i, key in enumerate(scenario.allow_implausible):
        comp, _, param = key.partition(".")
        if comp not in system.interfaces:
            raise ScenarioError(f"plausibility.allow[{i}]", key, "a parameter of a declared component: "
                                + ", ".join(system.interfaces), scenario.source)
        variables = system.interfaces[comp].variables
        if param not in variables or variables[param].causality != "parameter":
            names = [n for n, v in variables.items() if v.causality == "parameter"]
            raise ScenarioError(f"plausibility.allow[{i}]", key, f"a parameter of {comp} "
                                f"({system.interfaces[comp].path.name}){suggestion(param, names)}", scenario.source)


def _rating(role) -> tuple[Rating, Any]:
    """The rating a Gearbox FMU records, and its drivetrain as built."""
    model = role.record["model"]
    template = build(model["drivetrain"], "model.drivetrain")
    return Rating.of(template, float(model["rotor_speed_rad_s"])), template


def _drivetrain_findings(system, gear: str, rating: Rating, template) -> tuple[Judgement, ...]:
    allow = [k.split(".", 1)[1] for k in system.scenario.allow_implausible if k.split(".", 1)[0] == gear]
    built = flatten(template)
    given = [k for k, v in system.scenario.component(gear).parameters.items() if built.get(k) != v]  # changed ones
    return implausible(judge(gearbox_drivetrain(system, gear), rating), allow, base=judge(template, rating),
                       given=given)


def _operation_findings(system, rating: Rating) -> tuple[Judgement, ...]:
    speeds, torques, factors = {}, {}, {}
    for name, role in system.roles.items():
        if role.record is None:
            continue
        if role.role == WIND_SOURCE:
            speeds[f"{name}.{_WIND_SPEED}"] = wind_parameters(system, name).mean_speed_rad_s
        elif role.role == GENERATOR:
            base = generator_parameters(system, name).counter_torque_nm
            torques[f"{name}.{_COUNTER_TORQUE}"] = base
            for assigned in system.events:
                if assigned.component == name and assigned.event.kind != "grid_fault":  # a fault drops it to 0
                    factors[f"{name}.event{assigned.slot}.factor"] = (assigned.event.factor, base)
        elif role.role == TORQUE_CONTROLLER:
            law = controller_parameters(system, name)
            torques.update({f"{name}.{k}": getattr(law, f) for k, f in _CONTROLLER_TORQUES.items()})
    return implausible(judge_operation(rating, speeds, torques, factors), system.scenario.allow_implausible)


def plausibility_problem(system) -> EntryError | None:
    """The error for the first implausible value the scenario introduces (scenario key, value, bound), else None.

    Named where the value was given (the scenario, ``--set``, a study's point, a load-case entry, an SSP);
    a value of the FMU's own, implausible with the values given around it, where the last of those was
    (:func:`orchestrator.inputs.origins.responsible`). Scenarios without exactly one dtcosim Gearbox FMU
    have no rating: nothing is judged.
    """
    check_allowed(system)
    try:
        gear = dtcosim_component(system, GEARBOX).component
        rating, template = _rating(system.roles[gear])
        findings = [(gear, j.key, j) for j in _drivetrain_findings(system, gear, rating, template)]
        findings += [(*j.key.split(".", 1), j) for j in _operation_findings(system, rating)]
    except PhysicsUnavailable:
        return None  # no dtcosim gearbox, or values its model refuses (model_problem names those)
    if not findings:
        return None
    comp, param, j = findings[0]
    given = system.scenario.component(comp).parameters
    value = given.get(param, f"{j.value:.6g} (as built)")
    stage = param.split(".", 1)[0]
    around = sorted(k for k in given if k.split(".", 1)[0] == stage)
    note = "" if param in given else (" (the FMU's own value, implausible with the values this scenario gives: "
                                      + ", ".join(around) + ")")
    origin, own = responsible(system.scenario, comp, param, around)
    return origin.refusal(f"components.{comp}.parameters.{param}", value,
                          f"{j.expected}; it is {j.in_si} in SI{note}; a deliberate value is kept by [plausibility] "
                          f'allow = ["{comp}.{param}"] in the {origin.holder} or --allow-implausible {comp}.{param}',
                          own)
