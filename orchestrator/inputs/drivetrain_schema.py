"""The shape of a drivetrain description file (TOML), as the schema layer's strict tables.

See :mod:`orchestrator.inputs.drivetrain_file` for the format and ``docs/drivetrains.md``.
The numbers are checked here for their type and sign; what they mean together
(geometry, shaft count, ...) is checked while the file is read into the model.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from components.model.contact import CONTACT_LAWS
from components.model.stages import STEEL_DENSITY_KG_M3

from ..errors import EntryError
from .schema import Table


class DrivetrainFileError(EntryError):
    """A drivetrain file is invalid (key, value, expected, source)."""

    kind = "drivetrain"


class UnitsTable(Table):
    """``[units]``: the unit of each quantity; SI unless named here."""

    length: Literal["m", "mm"] = "m"
    angle: Literal["rad", "deg"] = "rad"
    inertia: Literal["kg.m2", "kg.mm2"] = "kg.m2"
    contact_stiffness: Literal["N/m^e", "N/mm^e"] = "N/m^e"
    contact_damping: Literal["N.s/m2", "N.s/mm2"] = "N.s/m2"
    regularisation: Literal["1/m", "1/mm"] = "1/m"
    impact_damping: Literal["N.s/m", "N.s/mm"] = "N.s/m"
    torsional_stiffness: Literal["N.m/rad", "N.mm/deg"] = "N.m/rad"
    torsional_damping: Literal["N.m.s/rad", "N.mm.s/deg"] = "N.m.s/rad"
    torque: Literal["N.m", "N.mm"] = "N.m"
    speed: Literal["rad/s", "rpm"] = "rad/s"


class MeshTable(Table):
    """Contact law and parameters of a mesh; missing entries come from the file's ``[mesh]``."""

    law: Literal[CONTACT_LAWS] | None = None  # the laws of components.model.kernel.contact
    k0: float | None = Field(None, gt=0, description="a number > 0: contact stiffness k0 [contact_stiffness unit]")
    exponent: float | None = Field(None, ge=1, le=3, description="a number in [1, 3]: the force exponent e")
    c0: float | None = Field(None, ge=0, description="a number >= 0: contact damping c0 [contact_damping unit]")
    lambda_: float | None = Field(None, alias="lambda", gt=0,
                                  description="a number > 0: backlash regularisation lambda [regularisation unit]")
    backlash: float | None = Field(None, ge=0, description="a number >= 0: normal backlash j_n [length unit]")
    impact_depth: float | None = Field(None, gt=0, description="a number > 0: impact penetration d_max [length unit]")
    impact_damping: float | None = Field(None, ge=0, description="a number >= 0: impact damping c_max")
    contact_ratio: float | None = Field(None, ge=1, le=10, description="a number in [1, 10]")
    stiffness_variation: float | None = Field(None, ge=0, le=0.9, description="a number in [0, 0.9]")


class GearTable(Table):
    """A gear body: ``mass`` and ``inertia`` given, or ``disc = "solid" | "bored"`` derived from the geometry."""

    mass: float | None = Field(None, gt=0, description="a number > 0 [kg]")
    inertia: float | None = Field(None, gt=0, description="a number > 0 [inertia unit]")
    disc: Literal["solid", "bored"] | None = None
    bore_diameter: float | None = Field(None, gt=0, description="a number > 0 [length unit]")
    density: float | None = Field(None, gt=0, description="a number > 0 [kg/m3]")


class PlanetaryTeeth(Table):
    sun: int = Field(gt=0, description="a whole number of teeth > 0")
    planet: int = Field(gt=0, description="a whole number of teeth > 0")
    ring: int = Field(gt=0, description="a whole number of teeth > 0")


class PlanetaryRadii(Table):
    sun: float = Field(gt=0, description="a pitch radius > 0 [length unit]")
    ring: float = Field(gt=0, description="a pitch radius > 0 [length unit]")
    planet: float | None = Field(None, gt=0, description="a pitch radius > 0 [length unit]")


class ParallelTeeth(Table):
    drive: int = Field(gt=0, description="a whole number of teeth > 0")
    driven: int = Field(gt=0, description="a whole number of teeth > 0")


class ParallelRadii(Table):
    drive: float = Field(gt=0, description="a pitch radius > 0 [length unit]")
    driven: float = Field(gt=0, description="a pitch radius > 0 [length unit]")


class _StageCommon(Table):
    name: str | None = Field(None, description="a stage name (letters, digits, '_', '-')")
    module: float = Field(gt=0, description="a number > 0: the gear module [length unit]")
    pressure_angle: float = Field(gt=0, description="a number > 0: the pressure angle [angle unit]")
    face_width: float = Field(gt=0, description="a number > 0: the face width [length unit]")


class PlanetaryTable(_StageCommon):
    """``[[stages]]`` with ``kind = "planetary"`` (ring fixed, carrier in, sun out)."""

    kind: Literal["planetary"]
    teeth: PlanetaryTeeth | None = None
    radii: PlanetaryRadii | None = None
    planets: int = Field(ge=1, description="a whole number of planets >= 1")
    planet_angles: list[float] | None = Field(None, description="a list of planet carrier angles [angle unit]")
    carrier_inertia: float = Field(0.0, ge=0, description="a number >= 0: extra carrier inertia [inertia unit]")
    sun: GearTable
    planet: GearTable
    mesh: MeshTable | None = None
    sun_mesh: MeshTable | None = None
    ring_mesh: MeshTable | None = None


class ParallelTable(_StageCommon):
    """``[[stages]]`` with ``kind = "parallel"`` (drive gear in, driven gear out)."""

    kind: Literal["parallel"]
    teeth: ParallelTeeth | None = None
    radii: ParallelRadii | None = None
    drive: GearTable
    driven: GearTable
    mesh: MeshTable | None = None


class ShaftTable(Table):
    name: str | None = Field(None, description="a shaft name (letters, digits, '_', '-')")
    stiffness: float = Field(gt=0, description="a number > 0: torsional stiffness [torsional_stiffness unit]")
    damping: float = Field(0.0, ge=0, description="a number >= 0: torsional damping [torsional_damping unit]")


class GeneratorTable(Table):
    inertia: float = Field(gt=0, description="a number > 0: generator rotor inertia [inertia unit]")
    counter_torque: float = Field(description="a number: generator counter torque [torque unit]")


class OutputTable(Table):
    torque: float = Field(description="a number: counter torque on the last stage's output member [torque unit]")


class OperatingPointTable(Table):
    rotor_speed: float = Field(gt=0, description="a number > 0: rotor speed [speed unit]")


class DrivetrainFile(Table):
    """The shape of a drivetrain TOML document (see the module docstring)."""

    name: str | None = Field(None, description="a drivetrain name (letters, digits, '_', '-')")
    description: str = Field("", description="a string")
    density: float = Field(STEEL_DENSITY_KG_M3, gt=0, description="a number > 0 [kg/m3]")
    units: UnitsTable = Field(default_factory=UnitsTable, description="a [units] table")
    mesh: MeshTable = Field(default_factory=MeshTable, description="a [mesh] table of contact defaults")
    stages: list[dict[str, Any]] = Field(min_length=1, description="an array of tables [[stages]], at least one")
    shafts: list[ShaftTable] = Field(default_factory=list, description="an array of tables [[shafts]]")
    generator: GeneratorTable | None = Field(None, description="a [generator] table with inertia, counter_torque")
    output: OutputTable | None = Field(None, description="an [output] table with torque")
    operating_point: OperatingPointTable | None = Field(None, description="an [operating_point] table")


#: the table of each stage kind
STAGE_TABLES = {"planetary": PlanetaryTable, "parallel": ParallelTable}
