"""Drivetrain description files (TOML): any stage list, any number of planets, one source for every tool.

A drivetrain file describes the gearbox from rotor to generator (its tables:
:mod:`orchestrator.inputs.drivetrain_schema`, units: :mod:`orchestrator.inputs.drivetrain_units`,
changed entries for studies: :mod:`orchestrator.inputs.drivetrain_entries`); it is read into
a :class:`~components.model.drivetrain.Drivetrain` (what the Gearbox FMU, the
monolithic reference, ``dtcosim modes`` and studies use) together with the
derived design table (:mod:`components.model.design_table`: which masses were
given and which derived, the geometry checks). Every mistake is a
:class:`DrivetrainFileError` naming the file, the key path, the value and the
expectation, raised while the file is read, before anything is built. The
format in full is in ``docs/drivetrains.md``::

    name = "grc-like"                     # optional, default: file stem
    description = "..."
    density = 7800.0                      # kg/m3, default for derived gear bodies

    [units]                               # optional: SI unless a quantity is named here
    length = "mm"                         # m | mm: radii, module, face width, backlash, bores
    angle = "deg"                         # rad | deg: pressure angles, planet angles
    inertia = "kg.mm2"                    # kg.m2 | kg.mm2
    contact_stiffness = "N/mm^e"          # N/m^e | N/mm^e (k0)
    contact_damping = "N.s/mm2"           # N.s/m2 | N.s/mm2 (c0)
    regularisation = "1/mm"               # 1/m | 1/mm (lambda)
    torsional_stiffness = "N.mm/deg"      # N.m/rad | N.mm/deg
    torsional_damping = "N.mm.s/deg"      # N.m.s/rad | N.mm.s/deg
    torque = "N.mm"                       # N.m | N.mm
    speed = "rpm"                         # rad/s | rpm

    [mesh]                                # contact defaults of every mesh (each mesh may override)
    law = "cfs"                           # cfs | impact
    k0 = 5.0e5
    exponent = 1.5
    c0 = 5.0e4
    lambda = 600.0
    backlash = 0.56

    [[stages]]
    name = "stage1"
    kind = "planetary"                    # ring fixed, carrier in, sun out
    module = 10.0
    pressure_angle = 20.0
    face_width = 50.0
    teeth = { sun = 20, planet = 80, ring = 180 }   # or radii = { sun = ..., ring = ... }
    planets = 3
    # planet_angles = [0.0, 120.0, 240.0]           # default: equally spaced
    carrier_inertia = 0.0                 # extra, on top of the planets' orbital inertia
    sun = { mass = 12.25, inertia = 6.12e4 }
    planet = { disc = "bored", bore_diameter = 100.0 }   # derived from the geometry
    # sun_mesh = { k0 = ... }  ring_mesh = { ... }  mesh = { ... }  (per-mesh contact)

    [[stages]]
    name = "stage3"
    kind = "parallel"
    module = 10.0
    pressure_angle = 20.0
    face_width = 50.0
    teeth = { drive = 20, driven = 16 }
    drive = { mass = 12.25, inertia = 6.12e4 }
    driven = { disc = "solid" }

    [[shafts]]                            # between stages, then one to the generator
    name = "shaft1"
    stiffness = 1.0e9
    damping = 1.0e8

    [generator]                           # or [output] torque = ... (no generator)
    inertia = 1.51e8
    counter_torque = 2.54e7

    [operating_point]
    rotor_speed = 16.0                    # for the design table, FMU start values, reference and modes
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

from components import units
from components.analysis.plausibility import Judgement
from components.errors import ParameterError
from components.model.bearings import Bearing, Gravity, ParallelLateral, PlanetaryLateral, RingSupport
from components.model.contact import MeshContact
from components.model.design_table import BodyRow, DesignTable, design_table
from components.model.drivetrain import Drivetrain
from components.model.gear_geometry import (
    GeometryCheck,
    assembly_check,
    clearance_check,
    disc_body,
    ring_teeth_check,
)
from components.model.generator import GeneratorParameters
from components.model.parameter_map import mesh_prefixes
from components.model.stages import STEEL_DENSITY_KG_M3, ParallelStage, PlanetaryStage, Shaft

from .drivetrain_schema import (
    STAGE_TABLES,
    BearingTable,
    DrivetrainFile,
    DrivetrainFileError,
    GearTable,
    MeshTable,
    ParallelTable,
    PlanetaryTable,
)
from .drivetrain_plausibility import check_file, plausibility_checks
from .drivetrain_units import FileUnits
from .files import find_input_file, packaged_files, read_toml
from .schema import NAME_PATTERN, read_document

#: folder of the packaged drivetrain files (beside ``scenarios/`` and ``studies/``)
FOLDER = "drivetrains"
#: rotor speed of the operating point when the file gives none: the paper's 16 rpm (Sec. 4.2)
DEFAULT_ROTOR_SPEED_RAD_S = units.rpm(16.0)
#: names a stage or shaft may not take (they are other flat parameter prefixes)
RESERVED_NAMES = ("generator", "output_torque", "solver", "wind", "drivetrain")


# ------------------------------------------------------------------ the result
@dataclass(frozen=True)
class DrivetrainSpec:
    """A drivetrain file read and checked.

    Attributes
    ----------
    name : str
    description : str
    drivetrain : Drivetrain
        SI, validated.
    rotor_speed_rad_s : float
        The file's operating point (default 16 rpm).
    bodies : mapping of str -> tuple of BodyRow
        Per stage, each body with where its mass and inertia come from (given or derived).
    checks : mapping of str -> tuple of GeometryCheck
        Per stage, the geometry checks that apply (all passed: a failed one is an error).
    source : str or None
        The file.
    sha256 : str
        SHA-256 of the file's content (hex).
    data : mapping
        The parsed TOML document (studies change entries of it).
    judgements : tuple of Judgement
        Every value judged by physics at the file's rating (:mod:`.drivetrain_plausibility`); the
        implausible ones are those the file allows.
    """

    name: str
    description: str
    drivetrain: Drivetrain
    rotor_speed_rad_s: float
    bodies: Mapping[str, tuple[BodyRow, ...]]
    checks: Mapping[str, tuple[GeometryCheck, ...]]
    source: str | None = None
    sha256: str = ""
    data: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    judgements: tuple[Judgement, ...] = field(default=(), compare=False, repr=False)

    @property
    def origin(self) -> str:
        """What an FMU built from it records as its source: ``"drivetrain file X (sha256 ...)"``."""
        where = Path(self.source).name if self.source else self.name
        return f"drivetrain file {where} (sha256 {self.sha256[:16]})"

    @property
    def key(self) -> str:
        """Folder name of FMUs built from this content: ``<name>-<first 16 hex digits of the SHA-256>``."""
        return f"{self.name}-{self.sha256[:16]}"

    def design_table(self, rotor_speed_rad_s: float | None = None, input_torque_nm: float | None = None) -> DesignTable:
        """The derived design table at the file's operating point (or the given one)."""
        speed = self.rotor_speed_rad_s if rotor_speed_rad_s is None else rotor_speed_rad_s
        return design_table(self.drivetrain, speed, input_torque_nm, self.name, self.bodies, self.checks)

    def cosim_drivetrain(self) -> Drivetrain:
        """The drivetrain, which must have a generator behind an output shaft (a Gearbox FMU's structure).

        Raises
        ------
        DrivetrainFileError
            The file has ``[output]`` instead of ``[generator]``.
        """
        if self.drivetrain.generator is None:
            raise DrivetrainFileError("generator", None, "a [generator] table and a shaft to it: a Gearbox FMU is "
                                      "cut at the generator (this file loads its last stage with [output] torque)",
                                      self.source)
        return self.drivetrain


#: mesh entries with a default, and those every mesh needs (from itself, its stage or [mesh])
_MESH_DEFAULTS = {"law": "cfs", "exponent": 1.5}
_MESH_REQUIRED = ("k0", "c0", "lambda", "backlash")


def _entries(table) -> dict[str, Any]:
    """The given entries of a table by file key (values as read: :class:`~orchestrator.inputs.quantities.Given`)."""
    return {info.alias or name: getattr(table, name) for name, info in type(table).model_fields.items()
            if getattr(table, name) is not None}


class _Reader:
    """Turns the validated tables into the model's dataclasses, naming file keys in every error."""

    def __init__(self, doc: DrivetrainFile, source: str | None) -> None:
        self.doc = doc
        self.source = source
        self.u = FileUnits(doc.units, source)
        self.density = self.u.si("density", doc.density, "density") if doc.density is not None \
            else STEEL_DENSITY_KG_M3
        self.file_keys: dict[str, str] = {}  # flat parameter name -> the file key its value comes from
        self._mesh_keys: dict[str, dict[str, str]] = {}

    def error(self, key: str, value: Any, expected: str) -> DrivetrainFileError:
        return DrivetrainFileError(key, value, expected, self.source)

    # -- meshes
    def mesh(self, key: str, pressure_angle_rad: float, tables: tuple[MeshTable | None, ...],
             keys: tuple[str, ...]) -> MeshContact:
        merged: dict[str, Any] = dict(_MESH_DEFAULTS)
        where: dict[str, str] = {}  # the file key each merged entry comes from
        for table, tkey in zip((self.doc.mesh, *tables), ("mesh", *keys)):
            if table is not None:
                entries = _entries(table)
                merged.update(entries)
                where.update({name: f"{tkey}.{name}" for name in entries})
        for name in _MESH_REQUIRED:
            if name not in merged:
                raise self.error(f"{key}.{name}", None, f"a value for {name} (missing: give it in this mesh, the "
                                 "stage's mesh table or the file's [mesh] table)")
        e = merged["exponent"]
        self._mesh_keys[key] = {name: where.get(name, f"{key}.{name}") for name in merged}

        def si(name: str, dimension: str) -> float:
            return self.u.si(where.get(name, f"{key}.{name}"), merged[name], dimension, e)

        try:
            return MeshContact(
                stiffness=si("k0", "contact_stiffness"), exponent=e, damping=si("c0", "contact_damping"),
                regularisation=si("lambda", "regularisation"), backlash_normal_m=si("backlash", "length"),
                pressure_angle_rad=pressure_angle_rad, law=merged["law"],
                **({"impact_depth_m": si("impact_depth", "length")} if "impact_depth" in merged else {}),
                **({"impact_damping": si("impact_damping", "impact_damping")} if "impact_damping" in merged else {}),
                **{k: merged[k] for k in ("contact_ratio", "stiffness_variation") if k in merged},
            )
        except ParameterError as exc:
            raise self.error(f"{key} ({exc.name})", exc.value, exc.expected) from None

    # -- gear bodies
    def body(self, key: str, body_name: str, table: GearTable, pitch_radius_m: float,
             width_m: float) -> BodyRow:
        given = table.mass is not None or table.inertia is not None
        if given and table.disc is not None:
            raise self.error(f"{key}.disc", table.disc, "no disc when mass and inertia are given (either the "
                             "values or a disc to derive them from)")
        if given:
            for name in ("mass", "inertia"):
                if getattr(table, name) is None:
                    raise self.error(f"{key}.{name}", None, "a value (mass and inertia are given together, "
                                     "or neither with disc = \"solid\" or \"bored\")")
            for name in ("bore_diameter", "density"):
                if getattr(table, name) is not None:
                    raise self.error(f"{key}.{name}", getattr(table, name), "no disc data when mass and inertia "
                                     "are given")
            return BodyRow(body_name, self.u.si(f"{key}.mass", table.mass, "mass"),
                           self.u.si(f"{key}.inertia", table.inertia, "inertia"), "given")
        if table.disc is None:
            raise self.error(key, {k: str(v) for k, v in _entries(table).items()},
                             'mass and inertia, or disc = "solid" or "bored" (with bore_diameter) to derive them')
        if table.disc == "bored" and table.bore_diameter is None:
            raise self.error(f"{key}.bore_diameter", None, 'a bore diameter [length unit] for disc = "bored"')
        if table.disc == "solid" and table.bore_diameter is not None:
            raise self.error(f"{key}.bore_diameter", table.bore_diameter, 'no bore for disc = "solid"')
        bore = 0.5 * self.u.si(f"{key}.bore_diameter", table.bore_diameter, "length") \
            if table.bore_diameter is not None else 0.0
        density = self.u.si(f"{key}.density", table.density, "density") if table.density is not None \
            else self.density
        try:
            disc = disc_body(pitch_radius_m, width_m, density, bore)
        except ParameterError as exc:
            raise self.error(f"{key}.{exc.name}", exc.value, exc.expected) from None
        return BodyRow(body_name, disc.mass_kg, disc.inertia_kgm2, f"derived: {disc.description}")

    # -- stages
    def stage(self, i: int, data: Mapping[str, Any]):
        key = f"stages[{i}]"
        if not isinstance(data, Mapping):
            raise self.error(key, data, "a table")
        kind = data.get("kind")
        if kind not in STAGE_TABLES:
            raise self.error(f"{key}.kind", kind, 'the stage kind: "planetary" or "parallel"'
                             + (" (missing)" if kind is None else ""))
        try:
            table = read_document(STAGE_TABLES[kind], data, DrivetrainFileError, self.source)
        except DrivetrainFileError as exc:
            raise self.error(f"{key}.{exc.key}", exc.value, exc.expected) from None
        name = table.name if table.name is not None else f"stage{i + 1}"
        if not NAME_PATTERN.match(name) or name in RESERVED_NAMES:
            raise self.error(f"{key}.name", name, "a stage name of letters, digits, '_' or '-', not "
                             + ", ".join(RESERVED_NAMES))
        if (table.teeth is None) == (table.radii is None):
            raise self.error(f"{key}.teeth", None if table.teeth is None else "both teeth and radii",
                             "either teeth = {...} or radii = {...} (exactly one)")
        stage, rows, checks = (self.planetary if isinstance(table, PlanetaryTable) else self.parallel)(key, name, table)
        self._record_keys(key, stage, rows)
        return stage, rows, checks

    def _record_keys(self, key: str, stage, rows: tuple[BodyRow, ...]) -> None:
        """The file key of every flat parameter of a stage (what a plausibility finding names)."""
        keys = self.file_keys
        keys[f"{stage.name}.module"], keys[f"{stage.name}.width"] = f"{key}.module", f"{key}.face_width"
        for row in rows:
            body = row.name.split(".", 1)[1]
            if body == "carrier":
                keys[f"{stage.name}.carrier_inertia"] = f"{key}.carrier_inertia"
                continue
            derived = row.source.startswith("derived")
            for name in ("mass", "inertia"):
                keys[f"{stage.name}.{body}_{name}"] = f"{key}.{body}" if derived else f"{key}.{body}.{name}"
        for field, prefix in mesh_prefixes(stage).items():
            for name, where in self._mesh_keys[f"{key}.{field}"].items():
                keys.setdefault(f"{prefix}.{name}", where)

    def common(self, key: str, t) -> tuple[float, float, float]:
        """Module, pressure angle and face width of a stage, SI."""
        u = self.u
        module = u.si(f"{key}.module", t.module, "length")
        alpha = u.si(f"{key}.pressure_angle", t.pressure_angle, "angle")
        if not alpha < 0.5 * math.pi:
            raise self.error(f"{key}.pressure_angle", t.pressure_angle.shown, "an angle below 90 deg")
        return module, alpha, u.si(f"{key}.face_width", t.face_width, "length")

    def planetary(self, key: str, name: str, t: PlanetaryTable):
        u = self.u
        module, alpha, width = self.common(key, t)
        checks: list[GeometryCheck] = []
        angles = None
        if t.planet_angles is not None:
            given = [a.shown for a in t.planet_angles]
            if len(t.planet_angles) != t.planets:
                raise self.error(f"{key}.planet_angles", given, f"{t.planets} angles, one per planet")
            angles = tuple(u.si(f"{key}.planet_angles[{j}]", a, "angle") for j, a in enumerate(t.planet_angles))
            if not all(0.0 <= a < 2.0 * math.pi for a in angles) or any(b <= a for a, b in zip(angles, angles[1:])):
                raise self.error(f"{key}.planet_angles", given,
                                 "strictly increasing angles in [0, 360) deg ([0, 2 pi) rad)")
        if t.teeth is not None:
            z = t.teeth
            r_s, r_p, r_r = (module * n / 2.0 for n in (z.sun, z.planet, z.ring))
            ring = ring_teeth_check(z.sun, z.planet, z.ring)
            if not ring.passed:
                raise self.error(f"{key}.teeth.ring", z.ring, f"Z_sun + 2 Z_planet = {z.sun + 2 * z.planet} for "
                                 f"standard gears ({ring.detail})")
            assembly = assembly_check(z.sun, z.ring, t.planets, angles)
            if not assembly.passed:
                where = "planet_angles" if angles is not None else "planets"
                raise self.error(f"{key}.{where}", [a.shown for a in t.planet_angles] if angles is not None
                                 else t.planets, f"planets that can be assembled: {assembly.detail}")
            checks += [ring, assembly]
        else:
            r = t.radii
            r_s, r_r = u.si(f"{key}.radii.sun", r.sun, "length"), u.si(f"{key}.radii.ring", r.ring, "length")
            if not r_r > r_s:
                raise self.error(f"{key}.radii.ring", r.ring.shown, f"> the sun radius {r.sun.shown:g} ({r_s:g} m)" if r.sun.unit is None else f"> the sun radius {r.sun.text} ({r_s:g} m)")
            r_p = 0.5 * (r_r - r_s)
            if r.planet is not None and not math.isclose(u.si(f"{key}.radii.planet", r.planet, "length"), r_p,
                                                         rel_tol=1e-9):
                raise self.error(f"{key}.radii.planet", r.planet.shown, f"(ring - sun) / 2 = {r_p:g} m "
                                 "(coaxial sun, planet and ring)")
            checks.append(GeometryCheck("ring teeth", None, "radii given: no tooth counts to check"))
            checks.append(GeometryCheck("assembly", None, "radii given: no tooth counts to check"))
        positions = angles if angles is not None else tuple(2.0 * math.pi * i / t.planets for i in range(t.planets))
        clearance = clearance_check(r_s, r_p, module, positions)
        if not clearance.passed:
            raise self.error(f"{key}.planets", t.planets, f"planets that do not overlap ({clearance.detail})")
        checks.append(clearance)
        sun = self.body(f"{key}.sun", f"{name}.sun", t.sun, r_s, width)
        planet = self.body(f"{key}.planet", f"{name}.planet", t.planet, r_p, width)
        carrier = BodyRow(f"{name}.carrier", None, u.si(f"{key}.carrier_inertia", t.carrier_inertia, "inertia"),
                          "given (extra carrier inertia; the planets' orbital inertia n m_p a^2 is added)")
        # precedence: the file's [mesh] < the stage's mesh < its sun_mesh / ring_mesh
        sun_mesh = self.mesh(f"{key}.sun_mesh", alpha, (t.mesh, t.sun_mesh), (f"{key}.mesh", f"{key}.sun_mesh"))
        ring_mesh = self.mesh(f"{key}.ring_mesh", alpha, (t.mesh, t.ring_mesh), (f"{key}.mesh", f"{key}.ring_mesh"))
        lateral = self.planetary_lateral(key, t)
        errors = None
        if t.pin_errors is not None:
            if len(t.pin_errors) != t.planets:
                raise self.error(f"{key}.pin_errors", len(t.pin_errors), f"{t.planets} tables {{radial, tangential}}, "
                                 "one per planet ({} for a planet without error)")
            errors = tuple((u.si(f"{key}.pin_errors[{j}].radial", e.radial, "length"),
                            u.si(f"{key}.pin_errors[{j}].tangential", e.tangential, "length"))
                           for j, e in enumerate(t.pin_errors))
        try:
            stage = PlanetaryStage(
                name=name, sun_radius_m=r_s, ring_radius_m=r_r, n_planets=t.planets,
                sun_mass_kg=sun.mass_kg, sun_inertia_kgm2=sun.inertia_kgm2,
                planet_mass_kg=planet.mass_kg, planet_inertia_kgm2=planet.inertia_kgm2,
                sun_mesh=sun_mesh, ring_mesh=ring_mesh, carrier_inertia_kgm2=carrier.inertia_kgm2,
                width_m=width, module_m=module, planet_angles_rad=angles, lateral=lateral, pin_errors_m=errors,
            )
        except ParameterError as exc:
            raise self.error(f"{key} ({exc.name})", exc.value, exc.expected) from None
        return stage, (carrier, sun, planet), tuple(checks)

    # -- the lateral-torsional model
    def bearing(self, key: str, t: BearingTable) -> Bearing:
        u = self.u
        try:
            return Bearing(u.si(f"{key}.stiffness", t.stiffness, "bearing_stiffness"),
                           u.si(f"{key}.damping", t.damping, "bearing_damping"), t.type,
                           None if t.C is None else u.si(f"{key}.C", t.C, "force"))
        except ParameterError as exc:
            raise self.error(f"{key} ({exc.name})", exc.value, exc.expected) from None

    def only_lateral(self, key: str, t, names: tuple[str, ...]) -> None:
        """Refuse the lateral model's entries in a torsional stage."""
        for name in names:
            if getattr(t, name) is not None:
                raise self.error(f"{key}.{name}", "given", 'model = "lateral" for this entry (the torsional model '
                                 "has no bearings, carrier mass or moving ring)")

    def planetary_lateral(self, key: str, t: PlanetaryTable) -> PlanetaryLateral | None:
        if t.model != "lateral":
            self.only_lateral(key, t, ("bearings", "carrier_mass", "ring"))
            return None
        for name in ("bearings", "carrier_mass"):
            if getattr(t, name) is None:
                raise self.error(f"{key}.{name}", None, f'a value for {name} with model = "lateral" (bearings = '
                                 "{sun, carrier, planet}, carrier_mass)")
        u = self.u
        ring = None
        if t.ring is not None:
            r = t.ring
            try:
                ring = RingSupport(u.si(f"{key}.ring.mass", r.mass, "mass"), u.si(f"{key}.ring.inertia", r.inertia,
                                   "inertia"), self.bearing(f"{key}.ring.support", r.support),
                                   u.si(f"{key}.ring.torsional_stiffness", r.torsional_stiffness, "torsional_stiffness"),
                                   u.si(f"{key}.ring.torsional_damping", r.torsional_damping, "torsional_damping"))
            except ParameterError as exc:
                raise self.error(f"{key}.ring ({exc.name})", exc.value, exc.expected) from None
        b = t.bearings
        return PlanetaryLateral(u.si(f"{key}.carrier_mass", t.carrier_mass, "mass"),
                                self.bearing(f"{key}.bearings.sun", b.sun), self.bearing(f"{key}.bearings.carrier", b.carrier),
                                self.bearing(f"{key}.bearings.planet", b.planet), ring)

    def parallel_lateral(self, key: str, t: ParallelTable) -> ParallelLateral | None:
        if t.model != "lateral":
            self.only_lateral(key, t, ("bearings", "centre_angle"))
            return None
        if t.bearings is None:
            raise self.error(f"{key}.bearings", None, 'bearings = {drive, driven} with model = "lateral"')
        angle = self.u.si(f"{key}.centre_angle", t.centre_angle, "angle") if t.centre_angle is not None else 0.0
        return ParallelLateral(self.bearing(f"{key}.bearings.drive", t.bearings.drive),
                               self.bearing(f"{key}.bearings.driven", t.bearings.driven), angle)

    def parallel(self, key: str, name: str, t: ParallelTable):
        u = self.u
        module, alpha, width = self.common(key, t)
        if t.teeth is not None:
            r1, r2 = (module * n / 2.0 for n in (t.teeth.drive, t.teeth.driven))
        else:
            r1 = u.si(f"{key}.radii.drive", t.radii.drive, "length")
            r2 = u.si(f"{key}.radii.driven", t.radii.driven, "length")
        drive = self.body(f"{key}.drive", f"{name}.drive", t.drive, r1, width)
        driven = self.body(f"{key}.driven", f"{name}.driven", t.driven, r2, width)
        mesh = self.mesh(f"{key}.mesh", alpha, (t.mesh,), (f"{key}.mesh",))
        try:
            stage = ParallelStage(
                name=name, drive_radius_m=r1, driven_radius_m=r2, drive_mass_kg=drive.mass_kg,
                drive_inertia_kgm2=drive.inertia_kgm2, driven_mass_kg=driven.mass_kg,
                driven_inertia_kgm2=driven.inertia_kgm2, mesh=mesh, width_m=width, module_m=module,
                lateral=self.parallel_lateral(key, t),
            )
        except ParameterError as exc:
            raise self.error(f"{key} ({exc.name})", exc.value, exc.expected) from None
        return stage, (drive, driven), ()

    # -- the whole
    def drivetrain(self) -> tuple[Drivetrain, dict, dict]:
        doc = self.doc
        stages, bodies, checks = [], {}, {}
        for i, data in enumerate(doc.stages):
            stage, rows, stage_checks = self.stage(i, data)
            if stage.name in bodies:
                raise self.error(f"stages[{i}].name", stage.name, "a stage name not used by another stage")
            if i > 0 and isinstance(stage, PlanetaryStage) and stage.lateral is not None \
                    and not stage.carrier_inertia_kgm2 > 0.0:
                raise self.error(f"stages[{i}].carrier_inertia", 0.0, '> 0 with model = "lateral" (the planets\' '
                                 "masses are bodies of their own there, not part of the carrier's inertia; only the "
                                 "first stage's carrier turns with the rotor and needs none)")
            stages.append(stage)
            bodies[stage.name] = rows
            checks[stage.name] = stage_checks
        if (doc.generator is None) == (doc.output is None):
            raise self.error("generator", None, "either a [generator] table (with a shaft to it) or an [output] "
                             "table with the counter torque on the last stage (exactly one)")
        n_shafts = len(stages) if doc.generator is not None else len(stages) - 1
        if len(doc.shafts) != n_shafts:
            what = (f"{n_shafts} [[shafts]] for {len(stages)} stage(s) and a generator: one between each pair of "
                    "stages and one to the generator") if doc.generator is not None else (
                    f"{n_shafts} [[shafts]] for {len(stages)} stage(s) without a generator: one between each pair "
                    "of stages")
            raise self.error("shafts", len(doc.shafts), what)
        shafts = []
        taken = set(bodies)
        for k, t in enumerate(doc.shafts):
            name = t.name if t.name is not None else f"shaft{k + 1}"
            if not NAME_PATTERN.match(name) or name in RESERVED_NAMES or name in taken:
                raise self.error(f"shafts[{k}].name", name, "a shaft name of letters, digits, '_' or '-', used by no "
                                 "other stage or shaft, not " + ", ".join(RESERVED_NAMES))
            taken.add(name)
            shafts.append(Shaft(name, self.u.si(f"shafts[{k}].stiffness", t.stiffness, "torsional_stiffness"),
                                self.u.si(f"shafts[{k}].damping", t.damping, "torsional_damping")))
        gravity = None
        if doc.gravity is not None:
            if not any(st.lateral is not None for st in stages):
                raise self.error("gravity", "given", 'a stage with model = "lateral" (gravity acts on the bodies\' '
                                 "translations; the torsional model has none)")
            try:
                gravity = Gravity(self.u.si("gravity.acceleration", doc.gravity.acceleration, "acceleration"),
                                  self.u.si("gravity.shaft_tilt", doc.gravity.shaft_tilt, "angle"))
            except ParameterError as exc:
                raise self.error(exc.name, exc.value, exc.expected) from None
        try:
            if doc.generator is not None:
                gen = GeneratorParameters(self.u.si("generator.inertia", doc.generator.inertia, "inertia"),
                                          self.u.si("generator.counter_torque", doc.generator.counter_torque,
                                                    "torque"))
                dt = Drivetrain(tuple(stages), tuple(shafts[:-1]), generator=gen, output_shaft=shafts[-1],
                                gravity=gravity)
            else:
                dt = Drivetrain(tuple(stages), tuple(shafts), gravity=gravity,
                                output_torque_nm=self.u.si("output.torque", doc.output.torque, "torque"))
        except ParameterError as exc:
            raise self.error(f"(drivetrain) {exc.name}", exc.value, exc.expected) from None
        return dt, bodies, checks


def drivetrain_from_dict(data: Mapping[str, Any], name: str | None = None, source: str | None = None,
                         sha256: str = "", allow: Sequence[str] = ()) -> DrivetrainSpec:
    """Read a parsed drivetrain document.

    ``allow`` adds flat parameter names to the file's ``[plausibility] allow`` (a study's).

    Raises
    ------
    DrivetrainFileError
        Naming the first offending key.
    """
    doc = read_document(DrivetrainFile, data, DrivetrainFileError, source)
    dt_name = doc.name if doc.name is not None else name
    if dt_name is None or not NAME_PATTERN.match(dt_name):
        raise DrivetrainFileError("name", dt_name, "a drivetrain name of letters, digits, '_' or '-'", source)
    reader = _Reader(doc, source)
    drivetrain, bodies, checks = reader.drivetrain()
    speed = reader.u.si("operating_point.rotor_speed", doc.operating_point.rotor_speed, "speed") \
        if doc.operating_point else DEFAULT_ROTOR_SPEED_RAD_S
    allow = [*(doc.plausibility.allow if doc.plausibility is not None else ()), *allow]
    judgements = check_file(drivetrain, speed, allow, reader.file_keys, data, source)
    for stage, rows in plausibility_checks(judgements, allow).items():
        checks[stage] = tuple(checks.get(stage, ())) + rows
    return DrivetrainSpec(dt_name, doc.description, drivetrain, speed, bodies, checks, source, sha256, dict(data),
                          judgements)


def load_drivetrain_file(path: str | Path) -> DrivetrainSpec:
    """Read and check a drivetrain TOML file.

    Raises
    ------
    DrivetrainFileError
        A missing or unreadable file, a TOML syntax error, or any invalid entry.
    """
    path = Path(path)
    data = read_toml(path, DrivetrainFileError)
    sha = hashlib.sha256(path.read_bytes()).hexdigest()
    return drivetrain_from_dict(data, name=path.stem, source=str(path), sha256=sha)


def packaged_drivetrains() -> dict[str, Path]:
    """Drivetrain files shipped with dtcosim, by name (``paper-table6``, ``grc-like``, ...)."""
    return packaged_files(FOLDER)


def find_drivetrain(spec: str | Path) -> Path:
    """A drivetrain file from a path or the name of a packaged one."""
    return find_input_file(spec, FOLDER, DrivetrainFileError, described="a drivetrain file",
                           plural="drivetrain files")
