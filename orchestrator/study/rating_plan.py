"""What a load-case set rates, decided before anything runs: the gear meshes (ISO 6336) and bearings (ISO 281).

Everything here comes from the Gearbox FMU's declarations and record, never from a
variable's name:

* **meshes**: every output declared ``contact_force`` (with ``stage``, ``mesh`` and ``planet``),
  rated with the geometry of that stage in the record's drivetrain (module, teeth ``2 r / m``,
  face width, the mesh's pressure angle; :mod:`components.model.stages`) and the set's
  ``[gear_rating]``. Its load cycles per gear are counted by the load revolution distribution of
  the force (:mod:`orchestrator.study.run_data`): a gear's tooth meets the mesh once per
  revolution relative to the carrier (ISO 6336-6), so each gear of a mesh gets a revolution
  count from a declared body speed (``body_speed``) times a kinematic factor of the record's
  drivetrain (:attr:`components.model.assembly.Assembly.kinematic_ratio_all`)::

      n_gear = |kappa_gear - kappa_carrier| / |kappa_ref| x revolutions of the reference body

  with the reference the gear itself where its speed is declared (the ring, fixed, has
  ``kappa = 0``: the carrier's, or the sun's, speed stands in). So over one carrier revolution the
  sun meets each planet ``r_ring / r_sun`` times, a planet meets the sun and the ring ``r_ring /
  r_planet`` times each, the ring meets each planet once; a parallel stage's gears count their own
  revolutions.
* **bearings**: every output declared ``bearing_force`` (info ``bearing``), its revolutions from
  the output declared ``bearing_speed`` of the same bearing (inner ring relative to outer ring),
  its type and dynamic load rating C from the bearing of that name in the record's drivetrain
  (:func:`bearing_data`), its reliability and a_ISO from the set's ``[bearing_life]``.

A gearbox without a record (a foreign FMU) has no geometry: its meshes are not rated, which the
report says in one line; a gearbox that declares no bearing forces has no ``bearing_life.csv``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from components.analysis.bearing_life import LIFE_EXPONENTS, LifeModification
from components.analysis.gear_mesh import MeshGeometry
from components.analysis.gear_rating import GearInputs, GearMaterial, GearStress, mesh_stresses
from components.errors import ParameterError
from components.model.assembly import Assembly
from components.model.stages import PlanetaryStage

from ..errors import suggestion
from ..inputs.load_cases import LoadCaseError, LoadCaseSet
from .run_data import Channel

#: the signal kinds of a bearing's outputs (the Gearbox FMU's declarations)
BEARING_FORCE, BEARING_SPEED = "bearing_force", "bearing_speed"
#: the members of a planetary and a parallel stage that gears are named by
PLANETARY_MEMBERS, PARALLEL_MEMBERS = ("sun", "planet", "ring"), ("drive", "driven")


@dataclass(frozen=True)
class MeshPlan:
    """One mesh force to rate.

    Attributes
    ----------
    column : str
        The force's recorded column.
    stage, mesh : str
        Declared stage and mesh kind (``sun_planet``, ``ring_planet``, ``parallel``).
    planet : str
        Declared planet ("" for a parallel stage).
    geometry : MeshGeometry
    members : (str, str)
        Pinion's and wheel's member (``sun``, ``planet``, ``ring``, ``drive``, ``driven``).
    stresses : (GearStress, GearStress)
        Pinion and wheel (their ``gear`` names the LRD entries of the force).
    material : GearMaterial
    speeds : tuple of (str, str)
        ``(gear, speed column)`` for the force's load revolution distribution.
    factors : tuple of float
        Load cycles per revolution of each speed column.
    """

    column: str
    stage: str
    mesh: str
    planet: str
    geometry: MeshGeometry
    members: tuple[str, str]
    stresses: tuple[GearStress, GearStress]
    material: GearMaterial
    speeds: tuple[tuple[str, str], ...]
    factors: tuple[float, ...]


@dataclass(frozen=True)
class BearingPlan:
    """One bearing force to rate.

    Attributes
    ----------
    column, name : str
        Its force column and bearing name.
    info : mapping
        The declared details.
    speed_column : str or None
        Its declared ``bearing_speed`` (None: not declared, not rated).
    bearing_type : str or None
        ``"ball"`` or ``"roller"`` from the record (None: not given).
    rating_n : float or None
        C [N] from the record (None: not given).
    modification : LifeModification
    """

    column: str
    name: str
    info: Mapping[str, str]
    speed_column: str | None
    bearing_type: str | None
    rating_n: float | None
    modification: LifeModification

    @property
    def problem(self) -> str:
        """Why the bearing cannot be rated ("" if it can)."""
        if self.speed_column is None:
            return f"no bearing_speed output declared for bearing {self.name}"
        if self.bearing_type not in LIFE_EXPONENTS:
            return f"no bearing type (ball or roller) given for {self.name} in the drivetrain"
        if self.rating_n is None:
            return f"no dynamic load rating C given for {self.name} in the drivetrain"
        return ""


@dataclass(frozen=True)
class RatingPlan:
    """The meshes and bearings of a load-case set, and why either is missing.

    Attributes
    ----------
    meshes : tuple of MeshPlan
    bearings : tuple of BearingPlan
    gear_note, bearing_note : str
        "" where rated, else one sentence why not.
    description : str
        The gear rating's material and S-N curve choice.
    """

    meshes: tuple[MeshPlan, ...] = ()
    bearings: tuple[BearingPlan, ...] = ()
    gear_note: str = ""
    bearing_note: str = ""
    description: str = ""

    def mesh(self, column: str) -> MeshPlan | None:
        """The plan of a force column (None if it is not rated)."""
        return next((m for m in self.meshes if m.column == column), None)


def bearing_data(bearing: Any) -> tuple[str, str | None, float | None]:
    """``(name, type, C [N])`` of a bearing of the record's drivetrain.

    The drivetrain's bearings (``Drivetrain.bearings``, frozen dataclasses) carry ``name``,
    ``type`` (``"ball"`` / ``"roller"``) and the dynamic load rating ``dynamic_load_rating_n``
    (None when not given): the one place that reads them.
    """
    return str(bearing.name), getattr(bearing, "type", None), getattr(bearing, "dynamic_load_rating_n", None)


def _kinematics(drivetrain) -> tuple[dict[str, float], dict[str, dict[str, list[str]]]]:
    """kappa of every body (the ring of a planetary stage: 0) and each stage's bodies by role."""
    assembly = Assembly(drivetrain)
    kappa = {b.name: float(k) for b, k in zip(assembly.bodies, assembly.kinematic_ratio_all)}
    roles: dict[str, dict[str, list[str]]] = {}
    for b in assembly.bodies:
        roles.setdefault(b.stage, {}).setdefault(b.role, []).append(b.name)
    for st in drivetrain.stages:
        if isinstance(st, PlanetaryStage):
            ring = f"{st.name}.ring"
            kappa.setdefault(ring, 0.0)  # fixed (a body of its own in a model where it turns)
            roles.setdefault(st.name, {}).setdefault("ring", [ring])
    return kappa, roles


def _speed_of(gear: str, carrier: str | None, stage_bodies: list[str], kappa: Mapping[str, float],
              declared: Mapping[str, str]) -> tuple[str, float] | None:
    """(speed column, load cycles per revolution of it) of a gear meeting a mesh (module docstring)."""
    rate = abs(kappa[gear] - (kappa[carrier] if carrier else 0.0))
    for ref in [gear] + stage_bodies + list(declared):
        if ref in declared and abs(kappa.get(ref, 0.0)) > 0.0:
            return declared[ref], rate / abs(kappa[ref])
    return None


def _stage_inputs(lcs: LoadCaseSet, drivetrain) -> None:
    """``[gear_rating.stages]`` names a stage of the drivetrain, members of its kind (LoadCaseError otherwise)."""
    stages = {st.name: st for st in drivetrain.stages}
    for name, rating in lcs.gear_rating.stages.items():
        if name not in stages:
            raise LoadCaseError(f"gear_rating.stages.{name}", name, f"a stage of the gearbox: {', '.join(stages)}"
                                f"{suggestion(name, list(stages))}", lcs.source)
        members = PLANETARY_MEMBERS if isinstance(stages[name], PlanetaryStage) else PARALLEL_MEMBERS
        for member in rating.gears:
            if member not in members:
                raise LoadCaseError(f"gear_rating.stages.{name}.gears.{member}", member,
                                    f"a member of a {stages[name].kind} stage: {', '.join(members)}", lcs.source)


def _mesh_plan(sig, column: str, drivetrain, lcs: LoadCaseSet, kappa, roles, declared) -> MeshPlan | None:
    stage_name, kind, planet = sig.info.get("stage", ""), sig.info.get("mesh", ""), sig.info.get("planet", "")
    stage = next((st for st in drivetrain.stages if st.name == stage_name), None)
    if stage is None:
        return None
    bodies = roles.get(stage_name, {})
    m = stage.module_m
    if isinstance(stage, PlanetaryStage):
        planets = bodies.get("planet", [])
        k = int(planet) - 1 if planet.isdigit() else -1
        if not 0 <= k < len(planets):
            return None
        carrier, z_s, z_p, z_r = bodies["carrier"][0], 2 * stage.sun_radius_m / m, 2 * stage.planet_radius_m / m, \
            2 * stage.ring_radius_m / m
        if kind == "sun_planet":
            pair = [("sun", bodies["sun"][0], z_s), ("planet", planets[k], z_p)]
            pair.sort(key=lambda g: g[2])  # the pinion has fewer teeth
            alpha = stage.sun_mesh.pressure_angle_rad
        elif kind == "ring_planet":
            pair = [("planet", planets[k], z_p), ("ring", bodies["ring"][0], -z_r)]
            alpha = stage.ring_mesh.pressure_angle_rad
        else:
            return None
    elif kind == "parallel":
        carrier = None
        pair = [("drive", bodies["drive"][0], 2 * stage.drive_radius_m / m),
                ("driven", bodies["driven"][0], 2 * stage.driven_radius_m / m)]
        pair.sort(key=lambda g: g[2])
        alpha = stage.mesh.pressure_angle_rad
    else:
        return None
    rating = lcs.gear_rating.stage(stage_name)
    inputs = tuple(rating.gears.get(member, GearInputs()) for member, _, _ in pair)
    key = f"gear_rating.stages.{stage_name}"
    try:
        geometry = MeshGeometry(pair[0][2], pair[1][2], m, stage.width_m, alpha, inputs[0].profile_shift,
                                inputs[1].profile_shift)
        material = lcs.gear_rating.materials[rating.material]
        stresses = mesh_stresses(geometry, (pair[0][1], pair[1][1]), material, rating.factors, inputs,
                                 tuple(member == "planet" for member, _, _ in pair), lcs.gear_rating.beyond_knee)
    except ParameterError as exc:
        raise LoadCaseError(key, f"{kind} mesh {column}", f"a mesh ISO 6336 can rate: {exc} (or [gear_rating] "
                            "enabled = false)", lcs.source) from None
    speeds, factors = [], []
    stage_bodies = [b for role in ("sun", "carrier", "driven", "drive") for b in bodies.get(role, [])]
    for _, gear, _ in pair:
        found = _speed_of(gear, carrier, stage_bodies, kappa, declared)
        if found is None:
            return None
        speeds.append((gear, found[0]))
        factors.append(found[1])
    return MeshPlan(column, stage_name, kind, planet, geometry, (pair[0][0], pair[1][0]), stresses, material,
                    tuple(speeds), tuple(factors))


def plan_ratings(system, gearbox, lcs: LoadCaseSet) -> RatingPlan:
    """The meshes and bearings of the base scenario's gearbox to rate (module docstring).

    Parameters
    ----------
    system : ResolvedSystem
        The base scenario.
    gearbox : ComponentRole
        Its gearbox.
    lcs : LoadCaseSet

    Raises
    ------
    LoadCaseError
        ``[gear_rating]`` or ``[bearing_life]`` naming a stage or bearing the gearbox does not have,
        or a mesh ISO 6336 cannot rate.
    """
    from ..cosim.physics_view import PhysicsUnavailable, gearbox_drivetrain

    comp = gearbox.component
    try:
        drivetrain = gearbox_drivetrain(system, comp)
    except PhysicsUnavailable:
        drivetrain = None
    declared = {s.info.get("body"): f"{comp}.{s.variable}" for s in gearbox.of_kind("body_speed") if s.info.get("body")}
    meshes: list[MeshPlan] = []
    gear_note = ""
    if not lcs.gear_rating.enabled:
        gear_note = "gear ratings off ([gear_rating] enabled = false)"
    elif drivetrain is None:
        gear_note = (f"no gear ratings: the gearbox (component {comp}) has no dtcosim record of its drivetrain "
                     "(no geometry to rate)")
    else:
        _stage_inputs(lcs, drivetrain)
        kappa, roles = _kinematics(drivetrain)
        for sig in gearbox.of_kind("contact_force"):
            plan = _mesh_plan(sig, f"{comp}.{sig.variable}", drivetrain, lcs, kappa, roles, declared)
            if plan is not None:
                meshes.append(plan)
        if not meshes:
            gear_note = (f"no gear ratings: the gearbox (component {comp}) declares no contact force of a stage of its "
                         "drivetrain")
    record = {}
    for b in getattr(drivetrain, "bearings", ()) or ():
        name, kind, rating = bearing_data(b)
        record[name] = (kind, rating)
    speeds = {s.info.get("bearing"): f"{comp}.{s.variable}" for s in gearbox.of_kind(BEARING_SPEED)}
    bearings = []
    for sig in gearbox.of_kind(BEARING_FORCE):
        name = sig.info.get("bearing") or sig.variable
        kind, rating = record.get(name, (None, None))
        bearings.append(BearingPlan(f"{comp}.{sig.variable}", name, dict(sig.info), speeds.get(name), kind,
                                    None if rating is None else float(rating), lcs.bearing_life.of(name)))
    names = [b.name for b in bearings]
    for name in lcs.bearing_life.bearings:
        if name not in names:
            raise LoadCaseError(f"bearing_life.bearings.{name}", name, "a bearing whose force the gearbox declares: "
                                + (", ".join(names) + suggestion(name, names) if names else
                                   f"component {comp} declares no bearing_force output"), lcs.source)
    bearing_note = "" if bearings else (f"bearing_life.csv not written: the gearbox (component {comp}) declares no "
                                        "bearing forces (no bearing_force outputs)")
    return RatingPlan(tuple(meshes), tuple(bearings), gear_note, bearing_note, lcs.gear_rating.describe())


def mesh_channel(plan: RatingPlan, column: str, unit: str, kind: str, info: Mapping[str, str]) -> Channel:
    """The load channel of a contact force: with its gears' load cycles where the mesh is rated."""
    mesh = plan.mesh(column)
    if mesh is None:
        return Channel(column, unit, kind, dict(info))
    return Channel(column, unit, kind, dict(info), mesh.speeds, mesh.factors)


def bearing_channels(plan: RatingPlan, units: Mapping[str, str]) -> list[Channel]:
    """A load channel per declared bearing force (its revolutions where its speed is declared)."""
    out = []
    for b in plan.bearings:
        var = b.column.partition(".")[2]
        gears = ((b.name, b.speed_column),) if b.speed_column else ()
        out.append(Channel(b.column, units.get(var, "N"), BEARING_FORCE, dict(b.info), gears))
    return out
