"""Flat FMU parameters of a drivetrain and back: stages, meshes, shafts, integrator.

The *structure* of the gearbox (stage kinds and names, planets per stage,
shafts) comes from a template :class:`~components.drivetrain.Drivetrain` (the
build preset). Every number of it is an FMU parameter whose start value is the
template's value, named ``<stage>.<field>``, ``<stage>.<mesh>.<field>``,
``<shaft>.<field>`` and ``solver.<field>``. Rebuilding the dataclasses from the
parameter values validates them; a :class:`ParameterError` is re-raised under
the FMU variable's name.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

from components.contact import CONTACT_LAWS, MeshContact
from components.drivetrain import Drivetrain
from components.errors import ParameterError
from components.integrators import StepControl
from components.stages import ParallelStage, PlanetaryStage, Shaft

from .base import fmu_parameter_names
from .interface import Value, Variable, enumeration_text, integer_parameter, real_parameter

#: reads the current value of an FMU variable by name
ValueOf = Callable[[str], Value]


@dataclass(frozen=True)
class Field:
    """A dataclass field exposed as a Real FMU parameter.

    Attributes
    ----------
    suffix : str
        Last part of the FMU variable name.
    attribute : str
        Dataclass field name.
    error_name : str
        Name under which the dataclass's validation reports the field (``{prefix}`` is
        replaced by the stage or shaft name).
    unit : str
        Unit (key of :data:`fmus.slaves.interface.UNITS`).
    description : str
        Description (the unit is appended by the interface).
    """

    suffix: str
    attribute: str
    error_name: str
    unit: str
    description: str


MESH_FIELDS = (
    Field("k0", "stiffness", "stiffness", "N/m^1.5",
          "contact stiffness k0 of eq. 1-2 (unit N/m^e for exponent e; Table 6: 5e5 N/mm^1.5)"),
    Field("exponent", "exponent", "exponent", "1", "force exponent e of eq. 1-2 (1.5: Hertzian)"),
    Field("c0", "damping", "damping", "N.s/m2", "CFS contact damping c0: damping coefficient c0 |d_BL| (eq. 2, 9)"),
    Field("lambda", "regularisation", "lambda", "1/m", "backlash regularisation factor lambda (eq. 4)"),
    Field("backlash", "backlash_normal_m", "backlash", "m",
          "normal backlash j_n (eq. 4; circumferential j_t = j_n / cos(alpha))"),
    Field("pressure_angle", "pressure_angle_rad", "pressure_angle_rad", "rad", "pressure angle alpha"),
    Field("impact_depth", "impact_depth_m", "impact_depth_m", "m",
          "impact law: penetration d_max at which the damping reaches c_max (eq. 1)"),
    Field("impact_damping", "impact_damping", "impact_damping", "N.s/m",
          "impact law: maximum damping c_max (eq. 1); a negative value means automatic, c0 * d_max"),
    Field("contact_ratio", "contact_ratio", "contact_ratio", "1",
          "transverse contact ratio (used by the time-varying mesh stiffness only)"),
    Field("stiffness_variation", "stiffness_variation", "stiffness_variation", "1",
          "relative amplitude of the time-varying mesh stiffness (0: constant stiffness, as in the paper)"),
)

PLANETARY_FIELDS = (
    Field("sun_radius", "sun_radius_m", "{prefix}.sun_radius_m", "m", "sun pitch radius"),
    Field("ring_radius", "ring_radius_m", "{prefix}.ring_radius_m", "m",
          "ring pitch radius (planet radius = (ring - sun) / 2; stage ratio 1 + ring / sun)"),
    Field("sun_mass", "sun_mass_kg", "{prefix}.sun_mass_kg", "kg", "sun mass"),
    Field("sun_inertia", "sun_inertia_kgm2", "{prefix}.sun_inertia_kgm2", "kg.m2", "sun polar moment of inertia"),
    Field("planet_mass", "planet_mass_kg", "{prefix}.planet_mass_kg", "kg",
          "mass of one planet (gives the carrier's orbital inertia n m_p r_c^2)"),
    Field("planet_inertia", "planet_inertia_kgm2", "{prefix}.planet_inertia_kgm2", "kg.m2",
          "spin moment of inertia of one planet"),
    Field("carrier_inertia", "carrier_inertia_kgm2", "{prefix}.carrier_inertia_kgm2", "kg.m2",
          "carrier inertia in addition to the planets' orbital inertia (the paper gives none: 0)"),
    Field("width", "width_m", "{prefix}.width_m", "m", "face width (informational)"),
    Field("module", "module_m", "{prefix}.module_m", "m", "gear module (mesh frequency of the time-varying stiffness)"),
)

PARALLEL_FIELDS = (
    Field("drive_radius", "drive_radius_m", "{prefix}.drive_radius_m", "m", "drive (input) gear pitch radius"),
    Field("driven_radius", "driven_radius_m", "{prefix}.driven_radius_m", "m", "driven (output) gear pitch radius"),
    Field("drive_mass", "drive_mass_kg", "{prefix}.drive_mass_kg", "kg", "drive gear mass"),
    Field("drive_inertia", "drive_inertia_kgm2", "{prefix}.drive_inertia_kgm2", "kg.m2", "drive gear moment of inertia"),
    Field("driven_mass", "driven_mass_kg", "{prefix}.driven_mass_kg", "kg", "driven gear mass"),
    Field("driven_inertia", "driven_inertia_kgm2", "{prefix}.driven_inertia_kgm2", "kg.m2",
          "driven gear moment of inertia"),
    Field("width", "width_m", "{prefix}.width_m", "m", "face width (informational)"),
    Field("module", "module_m", "{prefix}.module_m", "m", "gear module (mesh frequency of the time-varying stiffness)"),
)

SHAFT_FIELDS = (
    Field("stiffness", "stiffness_nm_per_rad", "{prefix}.stiffness_nm_per_rad", "N.m/rad", "torsional stiffness"),
    Field("damping", "damping_nms_per_rad", "{prefix}.damping_nms_per_rad", "N.m.s/rad", "torsional damping"),
)

SOLVER_FIELDS = (
    Field("rtol", "rtol", "rtol", "1", "relative tolerance of the Rosenbrock W-method"),
    Field("atol_q", "atol_q", "atol_q", "rad", "absolute tolerance on the deviation angles"),
    Field("atol_v", "atol_v", "atol_v", "rad/s", "absolute tolerance on the deviation speeds"),
    Field("h_min", "h_min", "h_min", "s", "smallest internal step before the step is discarded"),
)

SOLVER_INTEGER_FIELDS = (
    ("max_steps", "maximum internal steps per communication step before the step is discarded"),
    ("jacobian_max_age", "accepted internal steps after which the Jacobian is re-evaluated (1: every step)"),
)

_MESH_ROLES = {
    "sun_mesh": "sun-planet meshes",
    "ring_mesh": "ring-planet meshes",
    "mesh": "mesh",
}


def _stage_title(stage) -> str:
    return f"{stage.name} ({stage.kind})"


def _fields_of(stage) -> tuple[Field, ...]:
    return PLANETARY_FIELDS if isinstance(stage, PlanetaryStage) else PARALLEL_FIELDS


def _mesh_attributes(stage) -> tuple[str, ...]:
    return ("sun_mesh", "ring_mesh") if isinstance(stage, PlanetaryStage) else ("mesh",)


# ------------------------------------------------------------------ variables
def mesh_variables(prefix: str, title: str, mesh: MeshContact) -> list[Variable]:
    """Parameters of one mesh contact, named ``{prefix}.{field}``."""
    out = [real_parameter(f"{prefix}.{f.suffix}", _real(getattr(mesh, f.attribute)), f.unit, f"{title}: {f.description}")
           for f in MESH_FIELDS]
    out.insert(6, integer_parameter(f"{prefix}.law", CONTACT_LAWS.index(mesh.law),
                                    f"{title}: contact law, {enumeration_text(CONTACT_LAWS)} (eq. 2-4 or eq. 1)"))
    return out


def _real(value: float | None) -> float:
    return -1.0 if value is None else float(value)


def stage_variables(stage) -> list[Variable]:
    """Parameters of one stage and its meshes."""
    title = _stage_title(stage)
    out = [real_parameter(f"{stage.name}.{f.suffix}", getattr(stage, f.attribute), f.unit, f"{title}: {f.description}")
           for f in _fields_of(stage)]
    for attr in _mesh_attributes(stage):
        out += mesh_variables(f"{stage.name}.{attr}", f"{title} {_MESH_ROLES[attr]}", getattr(stage, attr))
    return out


def shaft_variables(shaft: Shaft, role: str) -> list[Variable]:
    """Parameters of one shaft."""
    return [real_parameter(f"{shaft.name}.{f.suffix}", getattr(shaft, f.attribute), f.unit, f"{shaft.name} ({role}): {f.description}")
            for f in SHAFT_FIELDS]


def solver_variables(control: StepControl) -> list[Variable]:
    """Integrator parameters ``solver.*``."""
    out = [real_parameter(f"solver.{f.suffix}", getattr(control, f.attribute), f.unit, f.description) for f in SOLVER_FIELDS]
    out += [integer_parameter(f"solver.{name}", getattr(control, name), text) for name, text in SOLVER_INTEGER_FIELDS]
    return out


def drivetrain_variables(template: Drivetrain) -> list[Variable]:
    """Parameters of every stage, mesh and shaft of ``template`` (its values are the start values)."""
    out: list[Variable] = []
    for stage in template.stages:
        out += stage_variables(stage)
    for k, shaft in enumerate(template.shafts):
        out += shaft_variables(shaft, f"{template.stages[k].name} output to {template.stages[k + 1].name} input")
    out += shaft_variables(template.output_shaft, f"{template.stages[-1].name} output to the generator")
    return out


# ------------------------------------------------------------------ values -> dataclasses
def _renames(fields: tuple[Field, ...], prefix: str) -> dict[str, str]:
    return {f.error_name.format(prefix=prefix): f"{prefix}.{f.suffix}" for f in fields}


def mesh_from_values(prefix: str, value: ValueOf) -> MeshContact:
    """MeshContact from the parameters ``{prefix}.*``."""
    law = value(f"{prefix}.law")
    if not 0 <= law < len(CONTACT_LAWS):
        raise ParameterError(f"{prefix}.law", law, enumeration_text(CONTACT_LAWS))
    kwargs = {f.attribute: value(f"{prefix}.{f.suffix}") for f in MESH_FIELDS}
    if kwargs["impact_damping"] < 0.0:
        kwargs["impact_damping"] = None
    with fmu_parameter_names(_renames(MESH_FIELDS, prefix)):
        return MeshContact(law=CONTACT_LAWS[law], **kwargs)


def stage_from_values(template, value: ValueOf):
    """A stage like ``template`` (same kind, name, planets) with the parameter values."""
    fields = _fields_of(template)
    kwargs = {f.attribute: value(f"{template.name}.{f.suffix}") for f in fields}
    for attr in _mesh_attributes(template):
        kwargs[attr] = mesh_from_values(f"{template.name}.{attr}", value)
    with fmu_parameter_names(_renames(fields, template.name)):
        return replace(template, **kwargs)


def shaft_from_values(template: Shaft, value: ValueOf) -> Shaft:
    """A shaft like ``template`` with the parameter values."""
    with fmu_parameter_names(_renames(SHAFT_FIELDS, template.name)):
        return replace(template, **{f.attribute: value(f"{template.name}.{f.suffix}") for f in SHAFT_FIELDS})


def control_from_values(value: ValueOf) -> StepControl:
    """Integrator tolerances from the parameters ``solver.*``."""
    kwargs = {f.attribute: value(f"solver.{f.suffix}") for f in SOLVER_FIELDS}
    kwargs.update({name: value(f"solver.{name}") for name, _ in SOLVER_INTEGER_FIELDS})
    names = {f.error_name: f"solver.{f.suffix}" for f in SOLVER_FIELDS} | {n: f"solver.{n}" for n, _ in SOLVER_INTEGER_FIELDS}
    with fmu_parameter_names(names):
        return StepControl(**kwargs)


def drivetrain_from_values(template: Drivetrain, value: ValueOf) -> Drivetrain:
    """A drivetrain with the structure of ``template`` and the parameter values (validated)."""
    stages = tuple(stage_from_values(st, value) for st in template.stages)
    shafts = tuple(shaft_from_values(sh, value) for sh in template.shafts)
    output_shaft = shaft_from_values(template.output_shaft, value)
    return replace(template, stages=stages, shafts=shafts, output_shaft=output_shaft)
