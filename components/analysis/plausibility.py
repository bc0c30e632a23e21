"""Plausibility by physics: could a real gearbox have these values?

A value can pass every type and sign check and still be no gearbox's: a backlash of
0.3 m meant in mm, a module read in metres, an inertia in kg mm^2 read as kg m^2.
This module judges each value against what physics bounds it by, in SI; the
inputs' edge (:mod:`orchestrator.inputs.drivetrain_plausibility`,
:mod:`orchestrator.cosim.plausibility_checks`) reports what fails, naming the file,
key, value, bound and reason, before anything runs, and lets a deliberate study
keep a value by naming its key (``[plausibility] allow``, ``--allow-implausible``).

Every rule gives a :class:`Judgement` per value it bounds, passed or not, keyed by
the value's flat parameter name (:mod:`components.model.parameter_map`:
``stage1.backlash``, ``stage2.sun_mass``, ``stage3.k0``). The rules are a table
(:data:`RULES`, :func:`judge`); a new parameter joins with a rule of its own.

Rules of a stage (spur gears, ISO 53 rack: tooth height 2.25 m)
--------------------------------------------------------------
``module``
    Each gear of the stage has ``z = 2 r / m`` teeth within [:data:`MIN_TEETH`,
    :data:`MAX_TEETH`], and ``m`` within [:data:`MIN_MODULE_M`, :data:`MAX_MODULE_M`].
``face_width``
    ``b`` at least the tooth height ``2.25 m`` (a narrower face is no gear face) and at
    most :data:`MAX_WIDTH_TO_DIAMETER` times the stage's smallest pitch diameter.
``backlash``
    The normal backlash ``j_n`` (eq. 3-4) is what the two teeth's thickness reductions leave
    between them: the circular backlash ``j_n / cos(alpha)`` at most :data:`MAX_BACKLASH_PITCH`
    of the circular pitch ``pi m``, i.e. each tooth thinned by at most that share of its
    thickness ``pi m / 2`` (tooth-thickness allowances of real gears are hundredths of a module).
``masses``
    A gear body's mass and polar inertia within [:data:`BODY_LOW`, :data:`BODY_HIGH`] of the
    solid steel disc (:data:`STEEL_DENSITY_KG_M3`) of its pitch diameter and the face width,
    and its radius of gyration ``sqrt(J / m)`` at most its tip radius ``r + m`` (no mass outside
    the gear). Bored planets, rim-and-web wheels (down to a few tenths of the disc) and pinions
    integral with their shafts (a few discs) lie well inside; a unit mistake (g, kg mm^2) lies
    three or six decades outside. The carrier's extra inertia (beyond the planets' orbital one) is
    at most :data:`BODY_HIGH` solid discs of the ring's pitch diameter and the face width.
``mesh_stiffness``
    The secant stiffness per face width of the contact law (eq. 2, ``F = k0 d^e``) at the rated
    static mesh force ``F`` (design table: ``T / (n r_b)``), ``c = F / (d b) = k0^(1/e)
    F^(1 - 1/e) / b``, within a factor :data:`STIFFNESS_TOLERANCE` of ISO 6336-1's mesh stiffness
    ``c_gamma_alpha`` of the mesh's geometry (method B, solid blanks,
    :meth:`components.analysis.gear_mesh.MeshGeometry.mesh_stiffness`: 12-28 N/(mm um) for
    standard spur gears). The factor covers rims (ISO's C_R down to about 0.7), reading a
    nonlinear law by its secant instead of its tangent (a factor e) and contact ratios between
    1.2 and 2. Without a rated load a nonlinear law has no stiffness to judge.

Rules of operation (:func:`judge_operation`)
--------------------------------------------
Rotor speeds within :data:`MAX_SPEED_FACTOR` x the drivetrain's rated rotor speed (a turbine's
overspeed protection trips at 1.1-1.3 x rated); torques on the generator side within
:data:`MAX_TORQUE_FACTOR` x the rated load torque (a generator's breakdown torque is 2-3 x rated,
and the gears and shafts are sized for the rating).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Iterable, Mapping

from ..errors import ParameterError
from ..model.design_table import design_table
from ..model.drivetrain import Drivetrain
from ..model.gear_geometry import ADDENDUM_MODULES
from ..model.parameter_map import mesh_prefixes
from ..model.stages import STEEL_DENSITY_KG_M3, PlanetaryStage
from .gear_mesh import RACK_ADDENDUM, RACK_DEDENDUM, MeshGeometry

#: fewest and most teeth of a gear (17 avoid undercut at 20 deg; fewer only with profile shift; girth gears
#: of mills have a few hundred)
MIN_TEETH, MAX_TEETH = 8.0, 1000.0
#: modules of ISO 54 span 1 to 50 mm; fine-pitch gears go down to 0.1 mm, mill gears up to about 100 mm
MIN_MODULE_M, MAX_MODULE_M = 1.0e-4, 0.1
#: widest face per smallest pitch diameter of a stage (designs stay below about 1.5: shaft bending and
#: torsion spoil the load along a longer face, ISO 6336-1 K_Hbeta)
MAX_WIDTH_TO_DIAMETER = 2.0
#: largest circular backlash as a share of the circular pitch pi m
MAX_BACKLASH_PITCH = 0.1
#: a gear body's mass and inertia per those of the solid steel disc of its pitch diameter and face width
BODY_LOW, BODY_HIGH = 0.1, 5.0
#: the model's secant mesh stiffness per ISO 6336-1's c_gamma_alpha, either way
STIFFNESS_TOLERANCE = 3.0
#: largest rotor speed and generator-side torque per rated
MAX_SPEED_FACTOR, MAX_TORQUE_FACTOR = 1.5, 3.0
#: units of the judged values, by the last part of their flat name
_UNITS = {"module": "m", "width": "m", "backlash": "m", "mass": "kg", "inertia": "kg m^2", "k0": "N/m^e"}


@dataclass(frozen=True)
class Rating:
    """What a drivetrain is rated for.

    Attributes
    ----------
    rotor_speed_rad_s : float
        Rated rotor speed [rad/s] (a drivetrain file's operating point).
    torque_nm : float
        Rated load torque [N m]: the generator's counter torque, or the output gear's without a generator.
    """

    rotor_speed_rad_s: float
    torque_nm: float

    @classmethod
    def of(cls, drivetrain: Drivetrain, rotor_speed_rad_s: float) -> "Rating":
        """The rating of ``drivetrain`` at its operating point: its load torque as given."""
        gen = drivetrain.generator
        return cls(float(rotor_speed_rad_s), float(gen.counter_torque_nm if gen is not None
                                                   else drivetrain.output_torque_nm))


@dataclass(frozen=True)
class Judgement:
    """One value against its physical bound.

    Attributes
    ----------
    rule : str
        The rule's name (:data:`RULES`, ``"speed"``, ``"torque"``).
    key : str
        The value's flat parameter name (``stage1.backlash``; ``wind.omega0`` for operation).
    value : float
        SI.
    low, high : float or None
        The plausible range (SI; None: unbounded).
    unit : str
        The SI unit of value and bounds.
    reason : str
        Why the bound is where it is, with the numbers it comes from.
    """

    rule: str
    key: str
    value: float
    low: float | None
    high: float | None
    unit: str
    reason: str

    @property
    def passed(self) -> bool:
        """The value lies in [low, high]."""
        return (self.low is None or self.value >= self.low) and (self.high is None or self.value <= self.high)

    @property
    def bound(self) -> str:
        """``"<= 0.00295 m"``, ``">= 0.0225 m"`` or ``"within [1, 5] kg"``: the side(s) that bound."""
        u = f" {self.unit}" if self.unit else ""
        if self.low is not None and self.high is not None:
            return f"within [{self.low:.4g}, {self.high:.4g}]{u}"
        return f"<= {self.high:.4g}{u}" if self.low is None else f">= {self.low:.4g}{u}"

    @property
    def expected(self) -> str:
        """The bound and its reason, for an error message."""
        return f"a plausible value {self.bound} ({self.reason})"

    @property
    def in_si(self) -> str:
        """The value with its SI unit for a message: ``"0.3 m"``, ``"1e+30"`` (dimensionless)."""
        return f"{self.value:.6g} {self.unit}".rstrip()


def _judgement(rule: str, key: str, value: float, low: float | None, high: float | None, reason: str) -> Judgement:
    return Judgement(rule, key, float(value), low, high, _UNITS.get(key.rsplit(".", 1)[-1].split("_")[-1], ""),
                     reason)


# ----------------------------------------------------------------- the rules
def _radii(stage) -> dict[str, float]:
    """Pitch radius of every gear of a stage [m]."""
    if isinstance(stage, PlanetaryStage):
        return {"sun": stage.sun_radius_m, "planet": stage.planet_radius_m, "ring": stage.ring_radius_m}
    return {"drive": stage.drive_radius_m, "driven": stage.driven_radius_m}


def _module(stage, forces: Mapping[str, float]) -> Iterable[Judgement]:
    m, radii = stage.module_m, _radii(stage)
    small, large = min(radii, key=radii.get), max(radii, key=radii.get)
    low = max(MIN_MODULE_M, 2.0 * radii[large] / MAX_TEETH)
    high = min(MAX_MODULE_M, 2.0 * radii[small] / MIN_TEETH)
    teeth = ", ".join(f"{k} {2.0 * r / m:.4g}" for k, r in radii.items())
    yield _judgement("module", f"{stage.name}.module", m, low, high,
                     f"each gear between {MIN_TEETH:g} and {MAX_TEETH:g} teeth z = 2 r / m (here {teeth}) and a "
                     f"module between {1e3 * MIN_MODULE_M:g} and {1e3 * MAX_MODULE_M:g} mm")


def _face_width(stage, forces: Mapping[str, float]) -> Iterable[Judgement]:
    m, radii = stage.module_m, _radii(stage)
    height = (RACK_ADDENDUM + RACK_DEDENDUM) * m
    small = min(radii, key=radii.get)
    yield _judgement("face_width", f"{stage.name}.width", stage.width_m, height,
                     MAX_WIDTH_TO_DIAMETER * 2.0 * radii[small],
                     f"at least the tooth height 2.25 m = {1e3 * height:.4g} mm and at most "
                     f"{MAX_WIDTH_TO_DIAMETER:g} x the {small}'s pitch diameter {2e3 * radii[small]:.4g} mm")


def _backlash(stage, forces: Mapping[str, float]) -> Iterable[Judgement]:
    m = stage.module_m
    for field, prefix in mesh_prefixes(stage).items():
        mesh = getattr(stage, field)
        high = MAX_BACKLASH_PITCH * math.pi * m * math.cos(mesh.pressure_angle_rad)
        yield _judgement("backlash", f"{prefix}.backlash", mesh.backlash_normal_m, 0.0, high,
                         f"{high / m:.3g} modules: the circular backlash j_n / cos(alpha) at most "
                         f"{MAX_BACKLASH_PITCH:.0%} of the circular pitch pi m = {1e3 * math.pi * m:.4g} mm, the "
                         "teeth thinned by at most that share of their thickness")


def _disc(radius_m: float, width_m: float) -> tuple[float, float]:
    mass = STEEL_DENSITY_KG_M3 * math.pi * radius_m**2 * width_m
    return mass, 0.5 * mass * radius_m**2


def _bodies(stage) -> Iterable[tuple[str, float, float, float]]:
    """(body, pitch radius, mass, inertia) of every gear body of a stage."""
    if isinstance(stage, PlanetaryStage):
        yield "sun", stage.sun_radius_m, stage.sun_mass_kg, stage.sun_inertia_kgm2
        yield "planet", stage.planet_radius_m, stage.planet_mass_kg, stage.planet_inertia_kgm2
    else:
        yield "drive", stage.drive_radius_m, stage.drive_mass_kg, stage.drive_inertia_kgm2
        yield "driven", stage.driven_radius_m, stage.driven_mass_kg, stage.driven_inertia_kgm2


def _masses(stage, forces: Mapping[str, float]) -> Iterable[Judgement]:
    b, m = stage.width_m, stage.module_m
    for body, r, mass, inertia in _bodies(stage):
        disc_m, disc_j = _disc(r, b)
        disc = (f"the solid steel disc of the {body}'s pitch diameter {2e3 * r:.4g} mm and the face width "
                f"{1e3 * b:.4g} mm ({STEEL_DENSITY_KG_M3:g} kg/m3)")
        yield _judgement("masses", f"{stage.name}.{body}_mass", mass, BODY_LOW * disc_m, BODY_HIGH * disc_m,
                         f"{BODY_LOW:g} to {BODY_HIGH:g} x the {disc_m:.4g} kg of {disc}")
        tip = r + ADDENDUM_MODULES * m
        yield _judgement("masses", f"{stage.name}.{body}_inertia", inertia, BODY_LOW * disc_j,
                         min(BODY_HIGH * disc_j, mass * tip**2),
                         f"{BODY_LOW:g} to {BODY_HIGH:g} x the {disc_j:.4g} kg m^2 of {disc}, and at most m r_a^2 = "
                         f"{mass * tip**2:.4g} kg m^2: no mass outside the tip radius {1e3 * tip:.4g} mm (m = "
                         f"{mass:.4g} kg)")
    if isinstance(stage, PlanetaryStage):
        _, disc_j = _disc(stage.ring_radius_m, b)
        yield _judgement("masses", f"{stage.name}.carrier_inertia", stage.carrier_inertia_kgm2, 0.0,
                         BODY_HIGH * disc_j,
                         f"the carrier lies inside the ring: its inertia beyond the planets' orbital one at most "
                         f"{BODY_HIGH:g} x the {disc_j:.4g} kg m^2 of the solid steel disc of the ring's pitch diameter "
                         f"{2e3 * stage.ring_radius_m:.4g} mm and the face width")


def _mesh_geometry(stage, field: str) -> MeshGeometry:
    """The mesh ``field`` of a stage for ISO 6336 (pinion first; the ring internal)."""
    m = stage.module_m
    z = {k: 2.0 * r / m for k, r in _radii(stage).items()}
    if field == "mesh":
        pair = sorted((z["drive"], z["driven"]))
    elif field == "sun_mesh":
        pair = sorted((z["sun"], z["planet"]))
    else:
        pair = [z["planet"], -z["ring"]]
    return MeshGeometry(pair[0], pair[1], m, stage.width_m, getattr(stage, field).pressure_angle_rad)


_MESH_NAMES = {"mesh": "mesh", "sun_mesh": "sun-planet mesh", "ring_mesh": "ring-planet mesh"}


def _mesh_stiffness(stage, forces: Mapping[str, float]) -> Iterable[Judgement]:
    b = stage.width_m
    for field, prefix in mesh_prefixes(stage).items():
        mesh = getattr(stage, field)
        force, e = abs(forces.get(field, 0.0)), mesh.exponent
        if force == 0.0 and e != 1.0:
            continue  # a nonlinear law has no stiffness without a load
        try:
            iso = _mesh_geometry(stage, field).mesh_stiffness(force / b)
        except ParameterError:
            continue  # a geometry ISO 6336 cannot judge: the module and width rules say why
        per_k0 = force ** (1.0 - 1.0 / e) / b  # c = k0^(1/e) F^(1 - 1/e) / b
        low, high = ((iso / STIFFNESS_TOLERANCE / per_k0) ** e, (iso * STIFFNESS_TOLERANCE / per_k0) ** e)
        model = mesh.stiffness ** (1.0 / e) * per_k0
        yield _judgement("mesh_stiffness", f"{prefix}.k0", mesh.stiffness, low, high,
                         f"the {_MESH_NAMES[field]}'s secant stiffness per face width at the rated force "
                         f"{force:.4g} N, k0^(1/e) F^(1-1/e) / b = {model / 1e9:.3g} N/(mm um), within "
                         f"{STIFFNESS_TOLERANCE:g}x of ISO 6336-1's c_gamma_alpha {iso / 1e9:.3g} N/(mm um) of its "
                         "geometry")


@dataclass(frozen=True)
class Rule:
    """A rule of :data:`RULES`: ``judge(stage, rated static force per mesh field) -> judgements``."""

    name: str
    title: str
    judge: Callable[[object, Mapping[str, float]], Iterable[Judgement]]


#: every rule of a stage, in the order they are reported
RULES: tuple[Rule, ...] = (
    Rule("module", "module against the gear size", _module),
    Rule("face_width", "face width against module and gear size", _face_width),
    Rule("backlash", "backlash against module and tooth thickness", _backlash),
    Rule("masses", "masses and inertias against the steel disc", _masses),
    Rule("mesh_stiffness", "mesh stiffness against ISO 6336-1", _mesh_stiffness),
)


def rated_mesh_forces(drivetrain: Drivetrain, rating: Rating) -> dict[str, dict[str, float]]:
    """Stage name -> mesh field -> static normal force per mesh [N] at the rated torque (design table)."""
    table = design_table(drivetrain, rating.rotor_speed_rad_s, rating.torque_nm * drivetrain.ratio)
    out = {}
    for stage, row in zip(drivetrain.stages, table.stages):
        fields = ("sun_mesh", "ring_mesh") if isinstance(stage, PlanetaryStage) else ("mesh",)
        out[stage.name] = {f: m.static_force_n for f, m in zip(fields, row.meshes)}
    return out


def judge(drivetrain: Drivetrain, rating: Rating) -> tuple[Judgement, ...]:
    """Every rule of :data:`RULES` on every stage of ``drivetrain``, stage by stage."""
    forces = rated_mesh_forces(drivetrain, rating)
    return tuple(j for stage in drivetrain.stages for rule in RULES for j in rule.judge(stage, forces[stage.name]))


def judge_operation(rating: Rating, speeds: Mapping[str, float] | None = None,
                    torques: Mapping[str, float] | None = None,
                    torque_factors: Mapping[str, tuple[float, float]] | None = None) -> tuple[Judgement, ...]:
    """Rotor speeds and generator-side torques (by key) against the rating (module docstring).

    Parameters
    ----------
    rating : Rating
    speeds : mapping of str -> float
        Rotor speeds [rad/s] by key (a wind source's mean speed).
    torques : mapping of str -> float
        Torques on the generator side [N m] by key (a counter torque, a controller's rated torque).
    torque_factors : mapping of str -> (float, float)
        ``(factor, base torque [N m])`` by key: a load event's torque ``factor x base``, judged as the factor.
    """
    out = []
    w = MAX_SPEED_FACTOR * abs(rating.rotor_speed_rad_s)
    rated_speed = f"{rating.rotor_speed_rad_s * 30.0 / math.pi:.4g} rpm"
    for key, value in (speeds or {}).items():
        out.append(Judgement("speed", key, float(value), -w, w, "rad/s",
                             f"at most {MAX_SPEED_FACTOR:g} x the drivetrain's rated rotor speed {rated_speed}: "
                             "overspeed protection trips at 1.1-1.3 x rated"))
    t = MAX_TORQUE_FACTOR * abs(rating.torque_nm)
    if t == 0.0:
        return tuple(out)  # no rated torque to judge a torque by
    why = (f"at most {MAX_TORQUE_FACTOR:g} x the drivetrain's rated torque {rating.torque_nm:.4g} N m: a generator's "
           "breakdown torque is 2-3 x rated")
    for key, value in (torques or {}).items():
        out.append(Judgement("torque", key, float(value), -t, t, "N m", why))
    for key, (factor, base) in (torque_factors or {}).items():
        if base != 0.0:
            out.append(Judgement("torque", key, float(factor), -t / abs(base), t / abs(base), "",
                                 f"a torque factor x {base:.4g} N m {why}"))
    return tuple(out)


def implausible(judgements: Iterable[Judgement], allow: Iterable[str] = (), base: Iterable[Judgement] = (),
                given: Iterable[str] | None = None) -> tuple[Judgement, ...]:
    """The judgements that fail and are neither allowed nor inherited.

    Parameters
    ----------
    judgements : iterable of Judgement
    allow : iterable of str
        Keys kept although implausible (a deliberate study).
    base : iterable of Judgement
        The judgements of what the values were changed from (an FMU's drivetrain as built, checked where
        it was defined): a failure of the same rule and key there is inherited, not introduced ...
    given : iterable of str, optional
        ... unless its key is among the values given now (None: no base, everything counts).
    """
    allowed = set(allow)
    inherited = {(j.rule, j.key) for j in base if not j.passed}
    given = set(given or ())
    return tuple(j for j in judgements if not j.passed and j.key not in allowed
                 and (j.key in given or (j.rule, j.key) not in inherited))

