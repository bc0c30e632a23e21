"""The Gearbox FMU's parameters: the drivetrain's flat names and the integrator's.

Drivetrain parameters are exactly those of :mod:`components.model.parameter_map`
(shared with the orchestrator's scenarios): per stage ``stageK.<field>`` (the
sun-planet and ring-planet meshes of a planetary stage share one set of mesh
parameters while they are equal, else ``stageK.sun_mesh.<field>`` and
``stageK.ring_mesh.<field>``), per shaft ``shaftK.stiffness`` and ``shaftK.damping``; start values
are the template's (the build preset's) values. The generator's parameters
belong to the GeneratorRotor FMU and are not exposed (the inertia interface's
copy of its inertia is the Gearbox parameter ``generator_inertia``, :mod:`fmus.slaves.gearbox`). Integrator tolerances are
``solver.<field>`` (:class:`~components.model.integrators.StepControl`).
"""

from __future__ import annotations

from typing import Callable

from components.model.drivetrain import Drivetrain
from components.model.integrators import StepControl
from components.model.parameter_map import (
    description_of_parameter,
    flatten,
    unflatten,
    unit_exponent_parameter,
    unit_of_parameter,
)
from components.model.stages import PlanetaryStage

from .base import fmu_parameter_names
from .interface import Value, Variable, integer_parameter, real_parameter

#: reads the current value of an FMU variable by name
ValueOf = Callable[[str], Value]

#: flat names of components.model.parameter_map that are not Gearbox FMU parameters
_NOT_GEARBOX = ("generator.", "output_torque")
#: parameter_map parameters that are integer codes
_INTEGER_CODES = ("contact_law",)

SOLVER_REAL_FIELDS = (
    ("rtol", "1", "relative tolerance of the Rosenbrock W-method"),
    ("atol_q", "rad", "absolute tolerance on the deviation angles"),
    ("atol_v", "rad/s", "absolute tolerance on the deviation speeds"),
    ("h_min", "s", "smallest internal step before the communication step is discarded"),
)
SOLVER_INTEGER_FIELDS = (
    ("max_steps", "maximum internal steps per communication step before the step is discarded"),
    ("jacobian_max_age", "accepted internal steps after which the Jacobian is re-evaluated (1: every step)"),
)


def _context(template: Drivetrain, name: str) -> str:
    prefix = name.split(".", 1)[0]
    for stage in template.stages:
        if stage.name == prefix:
            meshes = ""
            if isinstance(stage, PlanetaryStage):
                meshes = {".sun_mesh.": " (sun-planet meshes)", ".ring_mesh.": " (ring-planet meshes)"}.get(
                    next((m for m in (".sun_mesh.", ".ring_mesh.") if m in name), ""),
                    " (sun-planet and ring-planet meshes)")
            field = name.rsplit(".", 1)[-1]
            in_mesh = field in ("k0", "exponent", "c0", "lambda", "backlash", "pressure_angle", "contact_law",
                                "impact_depth", "impact_damping", "contact_ratio", "stiffness_variation")
            return f"{prefix}, {stage.kind} stage{meshes if in_mesh else ''}"
    for k, shaft in enumerate(template.shafts):
        if shaft.name == prefix:
            return f"{prefix}, {template.stages[k].name} output to {template.stages[k + 1].name} input"
    return f"{prefix}, {template.stages[-1].name} output to the generator"


def drivetrain_parameter_names(template: Drivetrain) -> list[str]:
    """Flat names of the drivetrain parameters the Gearbox FMU exposes, in interface order."""
    return [n for n in flatten(template) if not n.startswith(_NOT_GEARBOX)]


def drivetrain_variables(template: Drivetrain) -> list[Variable]:
    """Parameters of every stage, mesh and shaft of ``template`` (its values are the start values)."""
    values = flatten(template)
    out = []
    for name in drivetrain_parameter_names(template):
        description = f"{_context(template, name)}: {description_of_parameter(name)}"
        if name.rsplit(".", 1)[-1] in _INTEGER_CODES:
            out.append(integer_parameter(name, int(values[name]), description))
        else:
            out.append(real_parameter(name, values[name], unit_of_parameter(name), description,
                                      unit_exponent_parameter(name)))
    return out


def drivetrain_from_values(template: Drivetrain, value: ValueOf) -> Drivetrain:
    """A drivetrain with the structure of ``template`` and the parameter values (validated)."""
    return unflatten(template, {name: value(name) for name in drivetrain_parameter_names(template)})


def solver_variables(control: StepControl) -> list[Variable]:
    """Integrator parameters ``solver.*``."""
    out = [real_parameter(f"solver.{n}", getattr(control, n), unit, text) for n, unit, text in SOLVER_REAL_FIELDS]
    out += [integer_parameter(f"solver.{n}", getattr(control, n), text) for n, text in SOLVER_INTEGER_FIELDS]
    return out


def control_from_values(value: ValueOf) -> StepControl:
    """Integrator tolerances from the parameters ``solver.*``."""
    names = [n for n, _, _ in SOLVER_REAL_FIELDS] + [n for n, _ in SOLVER_INTEGER_FIELDS]
    with fmu_parameter_names({n: f"solver.{n}" for n in names}):
        return StepControl(**{n: value(f"solver.{n}") for n in names})
