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
    """Every contact force, shaft torque and body speed of an assembly, in that order, by variable name.

    The names are those the assembly gives (``stage1.F_sp[1]``, ``shaft1.torque``,
    ``stage1.sun.omega``): the Gearbox FMU's output names and the reference's series names.
    """
    out: dict[str, Signal] = {}
    for mesh in assembly.meshes:
        out[mesh.name] = Signal("N", f"contact force of the {mesh.stage} {MESH_KIND_WORDS[mesh.kind]} {mesh.name}",
                                CONTACT_FORCE, (("stage", mesh.stage), ("mesh", mesh.kind), *_planet_of(mesh.name)))
    for shaft in assembly.shafts:
        out[f"{shaft.name}.torque"] = Signal(
            "N.m", f"torque of {shaft.name} ({shaft.upstream} -> {shaft.downstream})", SHAFT_TORQUE,
            (("shaft", shaft.name), ("upstream", shaft.upstream), ("downstream", shaft.downstream)))
    for body in assembly.dof_names:
        out[f"{body}.omega"] = Signal("rad/s", f"absolute speed of {body}", BODY_SPEED, (("body", body),))
    return out


def deflection_name(mesh_name: str) -> str:
    """The mesh deflection series of the monolithic reference for the contact force ``mesh_name``
    (``stage1.F_sp[1]`` -> ``stage1.d_sp[1]``)."""
    return mesh_name.replace(".F_", ".d_")


def deflection_signal(mesh_name: str) -> Signal:
    """The declaration of :func:`deflection_name`'s series (a deflection: no kind an analysis selects)."""
    return Signal("m", f"mesh deflection of {mesh_name}")
