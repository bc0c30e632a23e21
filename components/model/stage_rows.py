"""The rows each stage adds to an assembly: bodies, mesh rows, bearing rows and external loads.

Every stage kind contributes, in absolute coordinates (the angles and displacements before the
deviation coordinates of :mod:`components.model.assembly` are taken):

* bodies (coordinates with their inertia or mass: a rotation, or a translation in the plane),
* a mesh row ``a`` per mesh, its deflection ``d = a . x + e`` at the pitch circle, signed so that
  normal power flow compresses it (``e``: the constant offset of planet pin position errors),
* spring rows (the bearings and supports of the lateral model): ``s = b . x``, force ``k s + c s'``,
* external loads (gravity, the planets' centrifugal force) as generalised forces per load term.

**Torsional stages** (the paper's model, eq. 8 and 10): pitch radii ``r``, ring fixed,
``d_sp,i = -r_s th_s - r_p th_p,i + (r_s + r_p) th_c``, ``d_rp,i = r_p th_p,i + (r_r - r_p) th_c``,
parallel ``d = r_1 th_1 - r_2 th_2``.

**Lateral-torsional stages** (after Lin and Parker, 1999): the sun, carrier, ring and every
planet also translate; the translations of a planetary stage are taken in the frame that turns
with the carrier's kinematic angle (the meshes and bearings keep their directions there), a
parallel stage's in the housing. Planet ``i`` at carrier angle ``psi_i`` has a radial and a
tangential coordinate (``e_r = (cos psi, sin psi)``, ``e_t = (-sin psi, cos psi)``; the tangential
one is the arc its centre travels, kinematic ratio ``r_c kappa_c``). A mesh force ``F`` acts along
the line of action at the pressure angle ``alpha``, its radial part separating the gears; on the
pitch-circle deflection of the paper (``d = delta / cos(alpha)``, :mod:`components.model.assembly`)
a translation ``u`` of a gear adds ``u . (e_t +- tan(alpha) e_r)``::

    d_sp,i = -r_s th_s - r_p th_p,i + t_i - tan(a_s) r_i + (-e_t + tan(a_s) e_r) . u_s
    d_rp,i =  r_p th_p,i - r_r th_r + t_i + tan(a_r) r_i + (-e_t - tan(a_r) e_r) . u_r
    planet bearing:  radial r_i - e_r . u_c,   tangential t_i - r_c th_c - e_t . u_c
    sun, carrier, ring supports: u_s, u_c, u_r;   ring torsional support: th_r

(``r_i``, ``t_i`` the planet's radial and tangential displacement). With stiff bearings ``t_i -> r_c
th_c`` and the rows are the torsional ones. A parallel stage with the driven gear's centre at
``e = (cos beta, sin beta)`` from the drive gear's: ``d = r_1 th_1 - r_2 th_2 + (e_p + tan(a) e) . u_1
- (e_p + tan(a) e) . u_2`` with ``e_p = (-sin beta, cos beta)``.

A pin position error ``(e_r, e_t)`` of planet ``i`` moves its centre (in both models): the offsets
``e_t - tan(a_s) e_r`` (sun mesh) and ``e_t + tan(a_r) e_r`` (ring mesh). Gravity ``g cos(tilt)``
points down: in a carrier frame turned by ``phi = kappa_c th_in`` its components on a body's
``(x, y)`` are ``-m g (sin phi, cos phi)``, on a planet's radial and tangential coordinate
``-m g sin(phi + psi)`` and ``-m g cos(phi + psi)``; the centrifugal force ``m_p r_c (kappa_c
omega_in)^2`` pushes every planet outward. Coriolis and centripetal stiffness terms of the rotating
frame are left out (``2 Omega / omega_n`` and ``(Omega / omega_n)^2`` of the bearing modes: small at
wind-turbine carrier speeds; docs/physics.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ParameterError
from .bearings import Bearing
from .contact import MeshContact
from .stages import ParallelStage, PlanetaryStage

#: names of the external-load terms: the square of the driver speed, a constant, cos and sin of a frame angle
OMEGA2, CONSTANT, COS, SIN = "omega2", "constant", "cos", "sin"


@dataclass(frozen=True)
class Body:
    """A coordinate of the assembly: a body's rotation, or one of its translations.

    Attributes
    ----------
    name : str
        e.g. ``"stage1.planet[2]"`` (rotation), ``"stage1.sun.x"``, ``"stage1.planet[2].t"`` (translations).
    inertia_kgm2 : float
        Polar inertia [kg m^2] of a rotation (a torsional carrier includes the planets' orbital inertia),
        mass [kg] of a translation.
    stage : str
        Stage name, or ``"generator"``.
    role : str
        ``carrier``, ``sun``, ``planet``, ``ring``, ``drive``, ``driven`` or ``generator``.
    coordinate : str
        ``rotation`` [rad], or a translation [m]: ``x``, ``y`` (a planetary stage's carrier frame, a
        parallel stage's housing), ``radial``, ``tangential`` (a planet).
    """

    name: str
    inertia_kgm2: float
    stage: str
    role: str
    coordinate: str = "rotation"

    @property
    def rotation(self) -> bool:
        """True for a rotation, False for a translation."""
        return self.coordinate == "rotation"


@dataclass(frozen=True)
class SpringElement:
    """A bearing or support of the lateral model: one or two spring rows and what it reports.

    Attributes
    ----------
    name : str
        e.g. ``"stage1.planet_bearing[2]"``, ``"stage1.ring_support"``, ``"stage1.ring_torsion"``.
    kind : str
        ``bearing`` (a rolling bearing: force and relative speed; ISO 281), ``support`` (force only) or
        ``torsion`` (a torsional support: torque [N m]).
    stage, body : str
        Its stage and the body it carries.
    rows : tuple of int
        Its spring rows (two, along ``components``, or one).
    components : tuple of str
        Names of the rows' directions (``x``, ``y`` or ``radial``, ``tangential``; ``torque``).
    speed : tuple of str
        The bodies whose speed difference turns the bearing (inner minus outer ring; ``()``: the
        housing is the outer ring and one body turns it; empty for supports).
    """

    name: str
    kind: str
    stage: str
    body: str
    rows: tuple[int, ...]
    components: tuple[str, ...]
    speed: tuple[str, ...] = ()


@dataclass
class Rows:
    """What the stages add, in absolute coordinates (filled by :func:`planetary_rows` / :func:`parallel_rows`)."""

    bodies: list[Body] = field(default_factory=list)
    mesh_rows: list[dict[int, float]] = field(default_factory=list)
    #: per mesh: (name, stage, kind, contact, body of the phase reference, teeth, phase offset)
    meshes: list[tuple[str, str, str, MeshContact, int, float, float]] = field(default_factory=list)
    mesh_offsets: list[float] = field(default_factory=list)
    spring_rows: list[dict[int, float]] = field(default_factory=list)
    spring_k: list[float] = field(default_factory=list)
    spring_c: list[float] = field(default_factory=list)
    elements: list[SpringElement] = field(default_factory=list)
    #: external loads: (body, term, frame body or -1, coefficient); the term's value times the coefficient
    loads: list[tuple[int, str, int, float]] = field(default_factory=list)

    def body(self, name: str, inertia: float, stage: str, role: str, coordinate: str = "rotation") -> int:
        self.bodies.append(Body(name, float(inertia), stage, role, coordinate))
        return len(self.bodies) - 1

    def mesh(self, row: dict[int, float], name: str, stage: str, kind: str, contact: MeshContact, ref: int,
             teeth: float, phase: float, offset: float = 0.0) -> None:
        self.mesh_rows.append(row)
        self.meshes.append((name, stage, kind, contact, ref, teeth, phase))
        self.mesh_offsets.append(float(offset))

    def spring(self, row: dict[int, float], stiffness: float, damping: float) -> int:
        self.spring_rows.append(row)
        self.spring_k.append(float(stiffness))
        self.spring_c.append(float(damping))
        return len(self.spring_rows) - 1

    def bearing(self, name: str, kind: str, stage: str, body: int, rows: list[dict[int, float]],
                components: tuple[str, ...], bearing: Bearing, speed: tuple[str, ...] = ()) -> None:
        """A two-row (or one-row) isotropic bearing or support on ``rows``."""
        idx = tuple(self.spring(r, bearing.stiffness_n_per_m, bearing.damping_ns_per_m) for r in rows)
        self.elements.append(SpringElement(name, kind, stage, self.bodies[body].name, idx, components, speed))

    def load(self, body: int, term: str, coefficient: float, frame: int = -1) -> None:
        if coefficient != 0.0:
            self.loads.append((body, term, frame, float(coefficient)))


def _translations(rows: Rows, name: str, mass: float, stage: str, role: str) -> tuple[int, int]:
    return rows.body(f"{name}.x", mass, stage, role, "x"), rows.body(f"{name}.y", mass, stage, role, "y")


def _gravity_xy(rows: Rows, xy: tuple[int, int], mass: float, g: float, frame: int) -> None:
    """``-m g (sin phi, cos phi)`` on the x, y of a body in the frame of ``frame`` (-1: the housing, phi = 0)."""
    if frame < 0:
        rows.load(xy[1], CONSTANT, -mass * g)
    else:
        rows.load(xy[0], SIN, -mass * g, frame)
        rows.load(xy[1], COS, -mass * g, frame)


def planetary_rows(rows: Rows, st: PlanetaryStage, gravity: float, driven: bool = False) -> dict[str, int]:
    """Add a planetary stage (torsional, or lateral-torsional with ``st.lateral``); its input and output bodies.

    ``gravity`` is the in-plane gravity [m/s^2] (0: none); ``driven``: the carrier's rotation is the kinematic
    driver's (no inertia of its own needed).
    """
    n = st.name
    r_s, r_p, r_r = st.sun_radius_m, st.planet_radius_m, st.ring_radius_m
    r_c = st.carrier_radius_m
    lat = st.lateral
    z_s = 2.0 * r_s / st.module_m
    z_r = 2.0 * r_r / st.module_m
    t_s, t_r = math.tan(st.sun_mesh.pressure_angle_rad), math.tan(st.ring_mesh.pressure_angle_rad)
    errors = st.pin_errors_m or ((0.0, 0.0),) * st.n_planets
    positions = st.planet_positions_rad
    if lat is None:  # the paper's torsional stage
        c = rows.body(f"{n}.carrier", st.carrier_total_inertia_kgm2, n, "carrier")
        s = rows.body(f"{n}.sun", st.sun_inertia_kgm2, n, "sun")
        planets = [rows.body(f"{n}.planet[{i + 1}]", st.planet_inertia_kgm2, n, "planet") for i in range(st.n_planets)]
        for i, p in enumerate(planets):  # eq. 8
            e_r, e_t = errors[i]
            rows.mesh({s: -r_s, p: -r_p, c: r_c}, f"{n}.F_sp[{i + 1}]", n, "sun_planet", st.sun_mesh, c, z_r,
                      -z_s * positions[i], e_t - t_s * e_r)
        for i, p in enumerate(planets):  # eq. 10, ring fixed
            e_r, e_t = errors[i]
            rows.mesh({p: r_p, c: r_r - r_p}, f"{n}.F_rp[{i + 1}]", n, "ring_planet", st.ring_mesh, c, z_r,
                      z_r * positions[i], e_t + t_r * e_r)
        return {"input": c, "output": s}
    if not (driven or st.carrier_inertia_kgm2 > 0.0):
        raise ParameterError(f"{n}.carrier_inertia", st.carrier_inertia_kgm2, "> 0 in the lateral-torsional model "
                             "(the planets' masses are bodies of their own there, not part of the carrier's inertia)")
    c = rows.body(f"{n}.carrier", st.carrier_inertia_kgm2, n, "carrier")
    cxy = _translations(rows, f"{n}.carrier", lat.carrier_mass_kg, n, "carrier")
    s = rows.body(f"{n}.sun", st.sun_inertia_kgm2, n, "sun")
    sxy = _translations(rows, f"{n}.sun", st.sun_mass_kg, n, "sun")
    ring = lat.ring
    if ring is not None:
        r = rows.body(f"{n}.ring", ring.inertia_kgm2, n, "ring")
        rxy = _translations(rows, f"{n}.ring", ring.mass_kg, n, "ring")
    m_p = st.planet_mass_kg
    for i, psi in enumerate(positions):
        cos_p, sin_p = math.cos(psi), math.sin(psi)
        name = f"{n}.planet[{i + 1}]"
        p = rows.body(name, st.planet_inertia_kgm2, n, "planet")
        pr = rows.body(f"{name}.radial", m_p, n, "planet", "radial")
        pt = rows.body(f"{name}.tangential", m_p, n, "planet", "tangential")
        e_r, e_t = errors[i]
        sun_row = {s: -r_s, p: -r_p, pt: 1.0, pr: -t_s, sxy[0]: sin_p + t_s * cos_p, sxy[1]: -cos_p + t_s * sin_p}
        rows.mesh(sun_row, f"{n}.F_sp[{i + 1}]", n, "sun_planet", st.sun_mesh, c, z_r, -z_s * psi, e_t - t_s * e_r)
        ring_row = {p: r_p, pt: 1.0, pr: t_r}
        if ring is not None:
            ring_row.update({r: -r_r, rxy[0]: sin_p - t_r * cos_p, rxy[1]: -cos_p - t_r * sin_p})
        rows.mesh(ring_row, f"{n}.F_rp[{i + 1}]", n, "ring_planet", st.ring_mesh, c, z_r, z_r * psi, e_t + t_r * e_r)
        rows.bearing(f"{n}.planet_bearing[{i + 1}]", "bearing", n, p,
                     [{pr: 1.0, cxy[0]: -cos_p, cxy[1]: -sin_p}, {pt: 1.0, c: -r_c, cxy[0]: sin_p, cxy[1]: -cos_p}],
                     ("radial", "tangential"), lat.planet_bearing, (name, f"{n}.carrier"))
        rows.load(pr, OMEGA2, m_p * r_c, c)  # centrifugal, times kappa_c^2 (assembly)
        if gravity:
            rows.load(pr, COS, -m_p * gravity * sin_p, c)
            rows.load(pr, SIN, -m_p * gravity * cos_p, c)
            rows.load(pt, COS, -m_p * gravity * cos_p, c)
            rows.load(pt, SIN, m_p * gravity * sin_p, c)
    rows.bearing(f"{n}.sun_bearing", "bearing", n, s, [{sxy[0]: 1.0}, {sxy[1]: 1.0}], ("x", "y"), lat.sun_bearing,
                 (f"{n}.sun",))
    rows.bearing(f"{n}.carrier_bearing", "bearing", n, c, [{cxy[0]: 1.0}, {cxy[1]: 1.0}], ("x", "y"),
                 lat.carrier_bearing, (f"{n}.carrier",))
    if ring is not None:
        rows.bearing(f"{n}.ring_support", "support", n, r, [{rxy[0]: 1.0}, {rxy[1]: 1.0}], ("x", "y"), ring.bearing)
        torsion = Bearing(ring.torsional_stiffness_nm_per_rad, ring.torsional_damping_nms_per_rad)
        rows.bearing(f"{n}.ring_torsion", "torsion", n, r, [{r: 1.0}], ("torque",), torsion)
    if gravity:
        for xy, mass in ((cxy, lat.carrier_mass_kg), (sxy, st.sun_mass_kg)) + (((rxy, ring.mass_kg),) if ring else ()):
            _gravity_xy(rows, xy, mass, gravity, c)
    return {"input": c, "output": s}


def parallel_rows(rows: Rows, st: ParallelStage, gravity: float, driven: bool = False) -> dict[str, int]:
    """Add a parallel stage (torsional, or lateral-torsional with ``st.lateral``); its input and output bodies."""
    n = st.name
    d1 = rows.body(f"{n}.drive", st.drive_inertia_kgm2, n, "drive")
    d2 = rows.body(f"{n}.driven", st.driven_inertia_kgm2, n, "driven")
    row = {d1: st.drive_radius_m, d2: -st.driven_radius_m}
    lat = st.lateral
    if lat is not None:
        beta = lat.centre_angle_rad
        t = math.tan(st.mesh.pressure_angle_rad)
        ax, ay = -math.sin(beta) + t * math.cos(beta), math.cos(beta) + t * math.sin(beta)  # e_p + tan(a) e
        xy1 = _translations(rows, f"{n}.drive", st.drive_mass_kg, n, "drive")
        xy2 = _translations(rows, f"{n}.driven", st.driven_mass_kg, n, "driven")
        row.update({xy1[0]: ax, xy1[1]: ay, xy2[0]: -ax, xy2[1]: -ay})
    rows.mesh(row, f"{n}.F_mesh", n, "parallel", st.mesh, d1, st.drive_teeth, 0.0)
    if lat is not None:
        for member, body, xy, bearing, mass in (("drive", d1, xy1, lat.drive_bearing, st.drive_mass_kg),
                                                ("driven", d2, xy2, lat.driven_bearing, st.driven_mass_kg)):
            rows.bearing(f"{n}.{member}_bearing", "bearing", n, body, [{xy[0]: 1.0}, {xy[1]: 1.0}], ("x", "y"),
                         bearing, (f"{n}.{member}",))
            if gravity:
                _gravity_xy(rows, xy, mass, gravity, -1)
    return {"input": d1, "output": d2}
