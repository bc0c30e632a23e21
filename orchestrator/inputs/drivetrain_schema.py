"""The shape of a drivetrain description file (TOML), as the schema layer's strict tables.

See :mod:`orchestrator.inputs.drivetrain_file` for the format and ``docs/drivetrains.md``.
The numbers are checked here for their type and sign; what they mean together
(geometry, shaft count, ...) is checked while the file is read into the model.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from components.model.contact import CONTACT_LAWS

from ..errors import EntryError
from .quantities import Given, amount
from .schema import PlausibilityTable, Table


class DrivetrainFileError(EntryError):
    """A drivetrain file is invalid (key, value, expected, source)."""

    kind = "drivetrain"


class UnitsTable(Table):
    """``[units]``: the unit of the bare numbers of each dimension (any unit of it, e.g. ``length = "mm"``).

    Named every dimension whose bare numbers the file uses, or none (then they are SI); a value
    written with its unit (``backlash = "0.56 mm"``) needs no entry (:mod:`orchestrator.inputs.drivetrain_units`).
    """

    length: str | None = Field(None, description="a length unit such as \"mm\" or \"m\"")
    angle: str | None = Field(None, description="an angle unit such as \"deg\" or \"rad\"")
    mass: str | None = Field(None, description="a mass unit such as \"kg\"")
    density: str | None = Field(None, description="a density unit such as \"kg/m3\"")
    inertia: str | None = Field(None, description="an inertia unit such as \"kg.mm2\" or \"kg m^2\"")
    contact_stiffness: str | None = Field(None, description="a unit of k0 such as \"N/mm^e\" (e: the force exponent)")
    contact_damping: str | None = Field(None, description="a unit of c0 such as \"N.s/mm2\"")
    regularisation: str | None = Field(None, description="a unit of lambda such as \"1/mm\"")
    impact_damping: str | None = Field(None, description="a unit of c_max such as \"N.s/mm\"")
    torsional_stiffness: str | None = Field(None, description="a unit such as \"N.mm/deg\" or \"N.m/rad\"")
    torsional_damping: str | None = Field(None, description="a unit such as \"N.mm.s/deg\" or \"N.m.s/rad\"")
    torque: str | None = Field(None, description="a torque unit such as \"N.mm\" or \"kN m\"")
    speed: str | None = Field(None, description="a speed unit such as \"rpm\" or \"rad/s\"")
    bearing_stiffness: str | None = Field(None, description="a unit of a bearing's stiffness such as \"N/m\" or \"kN/mm\"")
    bearing_damping: str | None = Field(None, description="a unit of a bearing's damping such as \"N.s/m\"")
    force: str | None = Field(None, description="a force unit such as \"N\" or \"kN\" (dynamic load ratings)")
    acceleration: str | None = Field(None, description="an acceleration unit such as \"m/s2\" (gravity)")


class MeshTable(Table):
    """Contact law and parameters of a mesh; missing entries come from the file's ``[mesh]``."""

    law: Literal[CONTACT_LAWS] | None = None  # the laws of components.model.kernel.contact
    k0: amount(gt=0) | None = Field(None, description="a number > 0: contact stiffness k0 [contact_stiffness unit]")
    exponent: float | None = Field(None, ge=1, le=3, description="a number in [1, 3]: the force exponent e")
    c0: amount(ge=0) | None = Field(None, description="a number >= 0: contact damping c0 [contact_damping unit]")
    lambda_: amount(gt=0) | None = Field(None, alias="lambda",
                                  description="a number > 0: backlash regularisation lambda [regularisation unit]")
    backlash: amount(ge=0) | None = Field(None, description="a number >= 0: normal backlash j_n [length unit]")
    impact_depth: amount(gt=0) | None = Field(None, description="a number > 0: impact penetration d_max [length unit]")
    impact_damping: amount(ge=0) | None = Field(None, description="a number >= 0: impact damping c_max")
    contact_ratio: float | None = Field(None, ge=1, le=10, description="a number in [1, 10]")
    stiffness_variation: float | None = Field(None, ge=0, le=0.9, description="a number in [0, 0.9]")


class GearTable(Table):
    """A gear body: ``mass`` and ``inertia`` given, or ``disc = "solid" | "bored"`` derived from the geometry."""

    mass: amount(gt=0) | None = Field(None, description="a number > 0 [mass unit]")
    inertia: amount(gt=0) | None = Field(None, description="a number > 0 [inertia unit]")
    disc: Literal["solid", "bored"] | None = None
    bore_diameter: amount(gt=0) | None = Field(None, description="a number > 0 [length unit]")
    density: amount(gt=0) | None = Field(None, description="a number > 0 [density unit]")


class PlanetaryTeeth(Table):
    sun: int = Field(gt=0, description="a whole number of teeth > 0")
    planet: int = Field(gt=0, description="a whole number of teeth > 0")
    ring: int = Field(gt=0, description="a whole number of teeth > 0")


class PlanetaryRadii(Table):
    sun: amount(gt=0) = Field(description="a pitch radius > 0 [length unit]")
    ring: amount(gt=0) = Field(description="a pitch radius > 0 [length unit]")
    planet: amount(gt=0) | None = Field(None, description="a pitch radius > 0 [length unit]")


class ParallelTeeth(Table):
    drive: int = Field(gt=0, description="a whole number of teeth > 0")
    driven: int = Field(gt=0, description="a whole number of teeth > 0")


class ParallelRadii(Table):
    drive: amount(gt=0) = Field(description="a pitch radius > 0 [length unit]")
    driven: amount(gt=0) = Field(description="a pitch radius > 0 [length unit]")


class BearingTable(Table):
    """A bearing or support of the lateral-torsional model: isotropic radial stiffness and damping; ISO 281 data."""

    stiffness: amount(ge=0) = Field(description="a number >= 0: radial stiffness [bearing_stiffness unit]")
    damping: amount(ge=0) = Field(Given(0.0, "N.s/m"), description="a number >= 0: radial damping [bearing_damping unit]")
    type: Literal["ball", "roller"] | None = Field(None, description='"ball" or "roller" (ISO 281)')
    C: amount(gt=0) | None = Field(None, description="a number > 0: ISO 281 dynamic load rating [force unit]")


class PlanetaryBearings(Table):
    """``bearings`` of a lateral planetary stage: sun and carrier supports, each planet's bearing."""

    sun: BearingTable
    carrier: BearingTable
    planet: BearingTable


class ParallelBearings(Table):
    """``bearings`` of a lateral parallel stage."""

    drive: BearingTable
    driven: BearingTable


class RingTable(Table):
    """``ring`` of a lateral planetary stage: a ring that moves on its supports (absent: rigidly fixed)."""

    mass: amount(gt=0) = Field(description="a number > 0 [mass unit]")
    inertia: amount(gt=0) = Field(description="a number > 0 [inertia unit]")
    support: BearingTable
    torsional_stiffness: amount(gt=0) = Field(description="a number > 0 [torsional_stiffness unit]")
    torsional_damping: amount(ge=0) = Field(Given(0.0, "N.m.s/rad"),
                                            description="a number >= 0 [torsional_damping unit]")


class PinErrorTable(Table):
    """A planet pin's position error on the carrier (tangential: in the direction of normal rotation)."""

    radial: amount() = Field(Given(0.0, "m"), description="a number [length unit]")
    tangential: amount() = Field(Given(0.0, "m"), description="a number [length unit]")


class GravityTable(Table):
    """``[gravity]``: gravity on the bodies of lateral-torsional stages, the rotor shaft tilted up by ``shaft_tilt``."""

    acceleration: amount(ge=0) = Field(Given(9.80665, "m/s^2"), description="a number >= 0 [acceleration unit]")
    shaft_tilt: amount(ge=0) = Field(Given(0.0, "deg"), description="a number >= 0: rotor shaft tilt [angle unit]")


class _StageCommon(Table):
    name: str | None = Field(None, description="a stage name (letters, digits, '_', '-')")
    module: amount(gt=0) = Field(description="a number > 0: the gear module [length unit]")
    pressure_angle: amount(gt=0) = Field(description="a number > 0: the pressure angle [angle unit]")
    face_width: amount(gt=0) = Field(description="a number > 0: the face width [length unit]")


class PlanetaryTable(_StageCommon):
    """``[[stages]]`` with ``kind = "planetary"`` (ring fixed, carrier in, sun out)."""

    kind: Literal["planetary"]
    teeth: PlanetaryTeeth | None = None
    radii: PlanetaryRadii | None = None
    planets: int = Field(ge=1, description="a whole number of planets >= 1")
    planet_angles: list[amount()] | None = Field(None, description="a list of planet carrier angles [angle unit]")
    carrier_inertia: amount(ge=0) = Field(Given(0.0), description="a number >= 0: extra carrier inertia [inertia unit]")
    sun: GearTable
    planet: GearTable
    mesh: MeshTable | None = None
    sun_mesh: MeshTable | None = None
    ring_mesh: MeshTable | None = None
    model: Literal["torsional", "lateral"] = Field("torsional", description='"torsional" (default) or "lateral"')
    bearings: PlanetaryBearings | None = None
    carrier_mass: amount(gt=0) | None = Field(None, description="a number > 0 [mass unit] (lateral model)")
    ring: RingTable | None = None
    pin_errors: list[PinErrorTable] | None = Field(None, description="a list of tables {radial, tangential}, one "
                                                                    "per planet")


class ParallelTable(_StageCommon):
    """``[[stages]]`` with ``kind = "parallel"`` (drive gear in, driven gear out)."""

    kind: Literal["parallel"]
    teeth: ParallelTeeth | None = None
    radii: ParallelRadii | None = None
    drive: GearTable
    driven: GearTable
    mesh: MeshTable | None = None
    model: Literal["torsional", "lateral"] = Field("torsional", description='"torsional" (default) or "lateral"')
    bearings: ParallelBearings | None = None
    centre_angle: amount() | None = Field(None, description="a number: direction drive -> driven centre from the "
                                                            "horizontal [angle unit] (lateral model; default 0)")


class ShaftTable(Table):
    name: str | None = Field(None, description="a shaft name (letters, digits, '_', '-')")
    stiffness: amount(gt=0) = Field(description="a number > 0: torsional stiffness [torsional_stiffness unit]")
    damping: amount(ge=0) = Field(Given(0.0), description="a number >= 0: torsional damping [torsional_damping unit]")


class GeneratorTable(Table):
    inertia: amount(gt=0) = Field(description="a number > 0: generator rotor inertia [inertia unit]")
    counter_torque: amount() = Field(description="a number: generator counter torque [torque unit]")


class OutputTable(Table):
    torque: amount() = Field(description="a number: counter torque on the last stage's output member [torque unit]")


class OperatingPointTable(Table):
    rotor_speed: amount(gt=0) = Field(description="a number > 0: rotor speed [speed unit]")


class DrivetrainFile(Table):
    """The shape of a drivetrain TOML document (see the module docstring)."""

    name: str | None = Field(None, description="a drivetrain name (letters, digits, '_', '-')")
    description: str = Field("", description="a string")
    density: amount(gt=0) | None = Field(None, description="a number > 0 [density unit] (default: steel, 7800 kg/m3)")
    units: UnitsTable = Field(default_factory=UnitsTable, description="a [units] table")
    plausibility: PlausibilityTable | None = Field(None, description="a [plausibility] table with allow = [...]")
    mesh: MeshTable = Field(default_factory=MeshTable, description="a [mesh] table of contact defaults")
    stages: list[dict[str, Any]] = Field(min_length=1, description="an array of tables [[stages]], at least one")
    shafts: list[ShaftTable] = Field(default_factory=list, description="an array of tables [[shafts]]")
    generator: GeneratorTable | None = Field(None, description="a [generator] table with inertia, counter_torque")
    output: OutputTable | None = Field(None, description="an [output] table with torque")
    operating_point: OperatingPointTable | None = Field(None, description="an [operating_point] table")
    gravity: GravityTable | None = Field(None, description="a [gravity] table (lateral-torsional stages)")


#: the table of each stage kind
STAGE_TABLES = {"planetary": PlanetaryTable, "parallel": ParallelTable}
