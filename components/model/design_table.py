"""The derived design table of a drivetrain: ratios, radii, mesh frequencies, static mesh forces per stage.

Quasi-static, lossless power flow at a rotor speed ``omega`` and a rotor (input)
torque ``T``. Stage ``k`` turns with ``omega_k = omega prod_{j<k} R_j`` and carries
``T_k = T / prod_{j<k} R_j`` on its input member. Per mesh, the static normal
force acts on the base radius (eq. 5-7):

* planetary stage (ring fixed): sun torque ``T_sun = T_k / R_k``; sun-planet force
  per planet ``F_sp = T_sun / (n r_b,sun)``; the planet's moment balance gives the
  same ring-planet force ``F_rp = F_sp``; mesh frequency ``Z_ring omega_k / 2 pi``;
* parallel stage: ``F = T_k / r_b,drive``; mesh frequency ``Z_drive omega_k / 2 pi``.

These are the means a run at constant speed and torque settles to (the forces of
the static equilibrium, :mod:`components.analysis.equilibrium`, are these).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Mapping, Sequence

from .drivetrain import Drivetrain
from .gear_geometry import GeometryCheck, base_radius_m, teeth_of
from .stages import PlanetaryStage


@dataclass(frozen=True)
class BodyRow:
    """A body of the design table: ``name`` (``stage1.sun``), mass [kg], inertia [kg m^2], where they come from."""

    name: str
    mass_kg: float | None
    inertia_kgm2: float
    source: str


@dataclass(frozen=True)
class MeshRow:
    """A mesh of the design table.

    Attributes
    ----------
    kind : {"sun_planet", "ring_planet", "parallel"}
    count : int
        Meshes of this kind in the stage (n planets, or 1).
    base_radius_m : float
        Base radius the static force acts on (the sun's for sun-planet, the ring's for ring-planet,
        the drive gear's for a parallel mesh).
    static_force_n : float
        Static normal force per mesh [N].
    """

    kind: str
    count: int
    base_radius_m: float
    static_force_n: float


@dataclass(frozen=True)
class StageRow:
    """A stage of the design table (SI units; teeth real-valued where the radii were given)."""

    name: str
    kind: str
    ratio: float
    module_m: float
    pressure_angle_rad: float
    face_width_m: float
    teeth: Mapping[str, float]
    pitch_radius_m: Mapping[str, float]
    base_radius_m: Mapping[str, float]
    centre_distance_m: float
    n_planets: int | None
    planet_angles_rad: tuple[float, ...] | None
    input_speed_rad_s: float
    input_torque_nm: float
    output_torque_nm: float
    mesh_frequency_hz: float
    meshes: tuple[MeshRow, ...]
    bodies: tuple[BodyRow, ...]
    checks: tuple[GeometryCheck, ...] = ()


@dataclass(frozen=True)
class DesignTable:
    """The whole table: stages, total ratio, the operating point it was evaluated at, shafts and generator."""

    name: str
    ratio: float
    rotor_speed_rad_s: float
    input_torque_nm: float
    stages: tuple[StageRow, ...]
    shafts: tuple[Mapping[str, Any], ...]
    generator: Mapping[str, float] | None
    output_torque_nm: float | None
    notes: tuple[str, ...] = field(default_factory=tuple)

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON data (``dtcosim drivetrain show --json``)."""
        return asdict(self)

    def stage(self, name: str) -> StageRow:
        """The row of stage ``name``."""
        return next(s for s in self.stages if s.name == name)


def default_input_torque_nm(drivetrain: Drivetrain) -> float:
    """Rotor torque [N m] that balances the drivetrain's load: counter torque x total ratio."""
    load = drivetrain.generator.counter_torque_nm if drivetrain.generator is not None else drivetrain.output_torque_nm
    return load * drivetrain.ratio


def _default_bodies(st) -> list[BodyRow]:
    if isinstance(st, PlanetaryStage):
        return [
            BodyRow(f"{st.name}.carrier", None, st.carrier_inertia_kgm2, "given (extra carrier inertia)"),
            BodyRow(f"{st.name}.sun", st.sun_mass_kg, st.sun_inertia_kgm2, "given"),
            BodyRow(f"{st.name}.planet", st.planet_mass_kg, st.planet_inertia_kgm2, "given"),
        ]
    return [
        BodyRow(f"{st.name}.drive", st.drive_mass_kg, st.drive_inertia_kgm2, "given"),
        BodyRow(f"{st.name}.driven", st.driven_mass_kg, st.driven_inertia_kgm2, "given"),
    ]


def design_table(drivetrain: Drivetrain, rotor_speed_rad_s: float, input_torque_nm: float | None = None,
                 name: str = "", bodies: Mapping[str, Sequence[BodyRow]] | None = None,
                 checks: Mapping[str, Sequence[GeometryCheck]] | None = None,
                 notes: Sequence[str] = ()) -> DesignTable:
    """The design table of ``drivetrain`` at a rotor speed and rotor torque.

    Parameters
    ----------
    drivetrain : Drivetrain
    rotor_speed_rad_s : float
        Rotor (stage-1 input) speed [rad/s], for the mesh frequencies.
    input_torque_nm : float, optional
        Rotor torque [N m] (default :func:`default_input_torque_nm`).
    name : str
        Name of the drivetrain (a file's).
    bodies : mapping of stage name -> BodyRow, optional
        The bodies with where their values come from (given or derived); default: all "given".
    checks : mapping of stage name -> GeometryCheck, optional
        Geometry checks of each stage (computed where the teeth are known).
    notes : sequence of str
    """
    torque = default_input_torque_nm(drivetrain) if input_torque_nm is None else float(input_torque_nm)
    speed = float(rotor_speed_rad_s)
    rows = []
    for st in drivetrain.stages:
        alpha = (st.sun_mesh if isinstance(st, PlanetaryStage) else st.mesh).pressure_angle_rad
        t_out = torque / st.ratio
        if isinstance(st, PlanetaryStage):
            radii = {"sun": st.sun_radius_m, "planet": st.planet_radius_m, "ring": st.ring_radius_m}
            base = {k: base_radius_m(r, alpha) for k, r in radii.items()}
            force = t_out / (st.n_planets * base["sun"])  # T_sun / (n r_b,sun)
            meshes = (MeshRow("sun_planet", st.n_planets, base["sun"], force),
                      MeshRow("ring_planet", st.n_planets, base["ring"], force))
            centre, n, angles = st.carrier_radius_m, st.n_planets, st.planet_positions_rad
            frequency = st.mesh_frequency_hz(speed)
        else:
            radii = {"drive": st.drive_radius_m, "driven": st.driven_radius_m}
            base = {k: base_radius_m(r, alpha) for k, r in radii.items()}
            meshes = (MeshRow("parallel", 1, base["drive"], torque / base["drive"]),)
            centre, n, angles = st.drive_radius_m + st.driven_radius_m, None, None
            frequency = st.mesh_frequency_hz(speed)
        rows.append(StageRow(
            name=st.name, kind=st.kind, ratio=st.ratio, module_m=st.module_m, pressure_angle_rad=alpha,
            face_width_m=st.width_m, teeth={k: teeth_of(r, st.module_m) for k, r in radii.items()},
            pitch_radius_m=radii, base_radius_m=base, centre_distance_m=centre, n_planets=n,
            planet_angles_rad=angles, input_speed_rad_s=speed, input_torque_nm=torque, output_torque_nm=t_out,
            mesh_frequency_hz=frequency, meshes=meshes,
            bodies=tuple((bodies or {}).get(st.name) or _default_bodies(st)),
            checks=tuple((checks or {}).get(st.name, ())),
        ))
        speed *= st.ratio
        torque = t_out
    shafts = tuple({"name": sh.name, "stiffness_nm_per_rad": sh.stiffness_nm_per_rad,
                    "damping_nms_per_rad": sh.damping_nms_per_rad} for sh in drivetrain.all_shafts)
    gen = None
    if drivetrain.generator is not None:
        gen = {"inertia_kgm2": drivetrain.generator.inertia_kgm2,
               "counter_torque_nm": drivetrain.generator.counter_torque_nm,
               "speed_rad_s": speed}
    return DesignTable(name, drivetrain.ratio, float(rotor_speed_rad_s),
                       default_input_torque_nm(drivetrain) if input_torque_nm is None else float(input_torque_nm),
                       tuple(rows), shafts, gen, None if drivetrain.generator is not None else drivetrain.output_torque_nm,
                       tuple(notes))


