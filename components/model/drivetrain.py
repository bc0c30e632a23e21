"""The drivetrain topology: a sequence of stages joined by shafts.

Stage ``k``'s output member is joined to stage ``k+1``'s input member by
``shafts[k]``; the first stage's input member is driven kinematically by the
rotor speed. The output is either a generator rotor (joined to the last stage
by ``output_shaft``) or, without a generator, a counter torque applied directly
to the last stage's output member (the single-stage cases of Tables 2 and 4 and
the sensitivity study of Sec. 4.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..errors import ParameterError
from ..validation import finite, set_fields
from .bearings import Gravity, NamedBearing
from .contact import MeshContact
from .generator import GeneratorParameters, LoadEvent, TorqueSchedule
from .stages import ParallelStage, PlanetaryStage, Shaft, Stage


@dataclass(frozen=True)
class Drivetrain:
    """A complete drivetrain.

    Parameters
    ----------
    stages : tuple of PlanetaryStage | ParallelStage
        Gear stages from rotor to generator.
    shafts : tuple of Shaft
        ``len(stages) - 1`` shafts; ``shafts[k]`` joins stage k's output to stage k+1's input.
    generator : GeneratorParameters or None
        Generator rotor at the output, or None.
    output_shaft : Shaft or None
        Shaft from the last stage's output member to the generator (required with a generator).
    output_torque_nm : float
        Counter torque [N m] on the last stage's output member when there is no generator.
    output_events : tuple of LoadEvent
        Load events on that counter torque (no generator).
    gravity : Gravity or None
        Gravity on the bodies of lateral-torsional stages (None: none).
    """

    stages: tuple[Stage, ...]
    shafts: tuple[Shaft, ...] = ()
    generator: GeneratorParameters | None = None
    output_shaft: Shaft | None = None
    output_torque_nm: float = 0.0
    output_events: tuple[LoadEvent, ...] = field(default_factory=tuple)
    gravity: Gravity | None = None

    def __post_init__(self) -> None:
        stages = tuple(self.stages)
        shafts = tuple(self.shafts)
        set_fields(
            self,
            stages=stages,
            shafts=shafts,
            output_events=tuple(self.output_events),
            output_torque_nm=finite("output_torque_nm", self.output_torque_nm),
        )
        if not stages:
            raise ParameterError("stages", stages, "at least one stage")
        for i, st in enumerate(stages):
            if not isinstance(st, (PlanetaryStage, ParallelStage)):
                raise ParameterError(f"stages[{i}]", st, "a PlanetaryStage or ParallelStage")
        names = [st.name for st in stages]
        if len(set(names)) != len(names):
            raise ParameterError("stages.name", names, "unique stage names")
        if len(shafts) != len(stages) - 1:
            raise ParameterError("shafts", len(shafts), f"{len(stages) - 1} shafts for {len(stages)} stages")
        for i, sh in enumerate(shafts):
            if not isinstance(sh, Shaft):
                raise ParameterError(f"shafts[{i}]", sh, "a Shaft")
        if self.generator is not None:
            if not isinstance(self.generator, GeneratorParameters):
                raise ParameterError("generator", self.generator, "a GeneratorParameters")
            if not isinstance(self.output_shaft, Shaft):
                raise ParameterError("output_shaft", self.output_shaft, "a Shaft joining the last stage to the generator")
            if self.output_torque_nm != 0.0 or self.output_events:
                raise ParameterError(
                    "output_torque_nm", self.output_torque_nm, "0 with a generator (its counter torque loads the output)"
                )
        elif self.output_shaft is not None:
            raise ParameterError("output_shaft", self.output_shaft, "None without a generator")
        if self.gravity is not None and not isinstance(self.gravity, Gravity):
            raise ParameterError("gravity", self.gravity, "a Gravity or None")

    @property
    def lateral(self) -> bool:
        """True if any stage is modelled lateral-torsionally."""
        return any(st.lateral is not None for st in self.stages)

    @property
    def bearings(self) -> tuple[NamedBearing, ...]:
        """Every rolling bearing of the lateral-torsional stages, by name (for the ISO 281 lives)."""
        return tuple(b for st in self.stages for b in st.bearings)

    @property
    def ratio(self) -> float:
        """Total speed ratio output / rotor [-]."""
        r = 1.0
        for st in self.stages:
            r *= st.ratio
        return r

    @property
    def all_shafts(self) -> tuple[Shaft, ...]:
        """Inter-stage shafts followed by the output shaft, if any."""
        return self.shafts + ((self.output_shaft,) if self.output_shaft is not None else ())

    def load_schedule(self) -> TorqueSchedule:
        """Counter torque on the output body (generator or last output member) [N m]."""
        if self.generator is not None:
            return self.generator.schedule()
        return TorqueSchedule.from_events(self.output_torque_nm, self.output_events)

    def with_meshes(self, **changes) -> "Drivetrain":
        """Copy with every mesh's contact parameters changed (e.g. ``law="impact"``, ``regularisation=...``)."""
        def upd(m: MeshContact) -> MeshContact:
            return replace(m, **changes)

        stages = []
        for st in self.stages:
            if isinstance(st, PlanetaryStage):
                stages.append(replace(st, sun_mesh=upd(st.sun_mesh), ring_mesh=upd(st.ring_mesh)))
            else:
                stages.append(replace(st, mesh=upd(st.mesh)))
        return replace(self, stages=tuple(stages))

    def with_generator(self, **changes) -> "Drivetrain":
        """Copy with generator parameters changed (e.g. ``counter_torque_nm``, ``events``)."""
        if self.generator is None:
            raise ParameterError("generator", None, "a drivetrain with a generator")
        return replace(self, generator=replace(self.generator, **changes))
