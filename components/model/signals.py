"""What the drivetrain model's variables are - SI unit, signal kind and its details - declared where they are made.

The Gearbox FMU declares its contact forces, shaft torques and body speeds from
:func:`gearbox_signals` (units into ``modelDescription.xml``, kinds and details into
its record: :mod:`fmus.slaves.gearbox`), and the monolithic reference declares every
series of its result from the same functions
(:attr:`components.reference.results.SimulationResult.signals`). An analysis of either
reads which series are contact forces or shaft torques and their units from these
declarations, never from a variable's name.

The kinds are those of a Gearbox FMU's record (``fmus.slaves.record.SIGNALS``) and, for
the series only the monolithic model has in one piece (rotor, generator), those of the
wind source and generator roles.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover - typing only
    from .assembly import Assembly

CONTACT_FORCE = "contact_force"
SHAFT_TORQUE = "shaft_torque"
BODY_SPEED = "body_speed"
OUTPUT_SPEED = "output_speed"
ROTOR_TORQUE = "rotor_torque"
ROTOR_SPEED, ROTOR_ANGLE = "rotor_speed", "rotor_angle"
GENERATOR_SPEED, GENERATOR_ANGLE, GENERATOR_TORQUE = "generator_speed", "generator_angle", "generator_torque"
#: what a lateral-torsional stage adds (:mod:`components.model.bearings`): a translation's displacement, a
#: bearing's (or ring support's) radial force magnitude, a bearing's speed, a ring's torsional support torque
BODY_DISPLACEMENT, BEARING_FORCE, SUPPORT_FORCE = "body_displacement", "bearing_force", "support_force"
BEARING_SPEED, SUPPORT_TORQUE = "bearing_speed", "support_torque"

#: a mesh kind of :class:`~components.model.assembly.Mesh` -> its words in a description
MESH_KIND_WORDS = {"sun_planet": "sun-planet mesh", "ring_planet": "ring-planet mesh",
                   "parallel": "parallel-stage mesh"}


@dataclass(frozen=True)
class Signal:
    """One variable of the model as declared.

    Attributes
    ----------
    unit : str
        SI unit in FMI notation (``"N"``, ``"N.m"``, ``"rad/s"``).
    description : str
    kind : str
        What it is in the drivetrain (:data:`CONTACT_FORCE`, :data:`SHAFT_TORQUE`, ...); ``""``: nothing
        an analysis selects.
    info : tuple of (str, str)
        Details of the kind: ``(("stage", "stage1"), ("mesh", "sun_planet"), ("planet", "1"))`` of a
        contact force, ``(("shaft", "shaft1"), ("upstream", ...), ("downstream", ...))`` of a shaft
        torque, ``(("body", ...),)`` of a body speed.
    """

    unit: str
    description: str
    kind: str = ""
    info: tuple[tuple[str, str], ...] = ()

    def detail(self, key: str) -> str:
        """The detail ``key`` of :attr:`info` (``""`` if it has none)."""
        return dict(self.info).get(key, "")


def _planet_of(mesh_name: str) -> tuple[tuple[str, str], ...]:
    """``(("planet", "2"),)`` for the planet mesh the assembly names ``stage1.F_sp[2]``, ``()`` for a parallel one."""
    inside = mesh_name.rpartition("[")[2].rstrip("]") if mesh_name.endswith("]") else ""
    return (("planet", inside),) if inside else ()


def gearbox_signals(assembly: Assembly) -> dict[str, Signal]:
    """Every contact force, shaft torque, body speed and bearing output of an assembly, by variable name.

    In the order of :attr:`components.model.gearbox_model.GearboxModel.output_names`: the contact
    forces, the shaft torques, the speeds of the rotations, the displacements of the translations
    (lateral-torsional stages), per bearing or support its force components (and a bearing's
    speed), then every bearing's and support's force magnitude. The names are those the assembly
    gives (``stage1.F_sp[1]``, ``shaft1.torque``, ``stage1.sun.omega``, ``stage1.sun.x``,
    ``stage1.planet_bearing[2].F``): the Gearbox FMU's output names and the reference's series names.
    """
    out: dict[str, Signal] = {}
    for mesh in assembly.meshes:
        out[mesh.name] = Signal("N", f"contact force of the {mesh.stage} {MESH_KIND_WORDS[mesh.kind]} {mesh.name}",
                                CONTACT_FORCE, (("stage", mesh.stage), ("mesh", mesh.kind), *_planet_of(mesh.name)))
    for shaft in assembly.shafts:
        out[f"{shaft.name}.torque"] = Signal(
            "N.m", f"torque of {shaft.name} ({shaft.upstream} -> {shaft.downstream})", SHAFT_TORQUE,
            (("shaft", shaft.name), ("upstream", shaft.upstream), ("downstream", shaft.downstream)))
    bodies = [assembly.bodies[j] for j in assembly.free]
    for body in bodies:
        if body.rotation:
            out[f"{body.name}.omega"] = Signal("rad/s", f"absolute speed of {body.name}", BODY_SPEED,
                                               (("body", body.name),))
    for body in bodies:
        if not body.rotation:
            out[body.name] = Signal("m", f"{body.coordinate} displacement of {body.name.rpartition('.')[0]} (a "
                                    "planetary stage's carrier frame, a parallel stage's housing)", BODY_DISPLACEMENT,
                                    (("body", body.name),))
    def where(e) -> tuple[tuple[str, str], ...]:
        return (("bearing", e.name), ("stage", e.stage), ("body", e.body))

    for e in assembly.elements:
        what = {"bearing": "bearing", "support": "support", "torsion": "torsional support"}[e.kind]
        for c in e.components:
            if c == "torque":
                out[f"{e.name}.torque"] = Signal("N.m", f"torque of the {what} {e.name} on {e.body}", SUPPORT_TORQUE,
                                                 where(e))
            else:
                out[f"{e.name}.F_{c}"] = Signal("N", f"{c} force of the {what} {e.name} on {e.body}")
        if e.speed:
            relative = f" relative to {e.speed[1]}" if len(e.speed) > 1 else ""
            out[f"{e.name}.omega"] = Signal("rad/s", f"speed of {e.speed[0]}{relative} (turns the bearing {e.name})",
                                            BEARING_SPEED, where(e))
    for e in assembly.elements:
        if e.kind != "torsion":
            out[f"{e.name}.F"] = Signal("N", f"radial force magnitude of the {e.kind} {e.name} on {e.body}",
                                        BEARING_FORCE if e.kind == "bearing" else SUPPORT_FORCE, where(e))
    return out


def deflection_name(mesh_name: str) -> str:
    """The mesh deflection series of the monolithic reference for the contact force ``mesh_name``
    (``stage1.F_sp[1]`` -> ``stage1.d_sp[1]``)."""
    return mesh_name.replace(".F_", ".d_")


def deflection_signal(mesh_name: str) -> Signal:
    """The declaration of :func:`deflection_name`'s series (a deflection: no kind an analysis selects)."""
    return Signal("m", f"mesh deflection of {mesh_name}")
