"""Drivetrain presets built from the paper's tables, in the paper's own units.

* :func:`table3_parallel` - parallel stage of Table 3 (the Table 2 case).
* :func:`table5_planetary` - planetary stage of Table 5 (the Table 4 case).
* :func:`table6_gearbox` - three-stage gearbox of Table 6, ratio 100, with the
  generator rotor of Sec. 4.2.
* :func:`sensitivity_variant` - the Sec. 4.1 variant: R1 real in [6, 10],
  R2 = 100 / (R1 R3), stage-2 masses and inertias scaled by 10 / R1.
"""

from __future__ import annotations

from dataclasses import replace

from .. import units
from ..errors import ParameterError
from ..validation import in_range, positive
from .contact import MeshContact
from .drivetrain import Drivetrain
from .generator import GeneratorParameters
from .stages import ParallelStage, PlanetaryStage, Shaft

PRESETS = ("table3", "table5", "table6")
TOTAL_RATIO = 100.0
STAGE3_RATIO = 1.25


def _table35_contact(c0_ns_per_mm2: float = 5.0e3, lambda_per_mm: float = 10.0) -> MeshContact:
    # Table 3 / 5: k0 = 5e4 N/mm^e, c0 = 5e3 N s/mm^2, lambda = 10, j_n = 0.5 mm, alpha = 20 deg
    return MeshContact.from_paper(5.0e4, c0_ns_per_mm2, lambda_per_mm, 0.5, 20.0)


def _table6_contact(lambda_per_mm: float = 600.0) -> MeshContact:
    # Table 6: k0 = 5e5 N/mm^e, c0 = 5e4 N s/mm^2, lambda = 600, j_n = 0.56 mm, alpha = 20 deg
    return MeshContact.from_paper(5.0e5, 5.0e4, lambda_per_mm, 0.56, 20.0)


def table3_parallel(output_torque_nm: float = 1000.0, c0_ns_per_mm2: float = 5.0e3) -> Drivetrain:
    """Parallel stage of Table 3: drive Z = 32, driven Z = 22, module 10 mm, width 40 mm.

    Parameters
    ----------
    output_torque_nm : float
        Counter torque on the driven gear [N m] (Table 2: 1 kN m).
    c0_ns_per_mm2 : float
        Contact damping [N s/mm^2].
    """
    mesh = _table35_contact(c0_ns_per_mm2)
    stage = ParallelStage(
        name="stage1",
        drive_radius_m=units.mm(10.0 * 32 / 2),
        driven_radius_m=units.mm(10.0 * 22 / 2),
        drive_mass_kg=24.2,
        drive_inertia_kgm2=units.kgmm2(3.16e5),
        driven_mass_kg=11.06,
        driven_inertia_kgm2=units.kgmm2(7.13e4),
        mesh=mesh,
        width_m=units.mm(40.0),
        module_m=units.mm(10.0),
    )
    return Drivetrain(stages=(stage,), output_torque_nm=output_torque_nm)


def table5_planetary(output_torque_nm: float = 1000.0, c0_ns_per_mm2: float = 5.0e3, n_planets: int = 3) -> Drivetrain:
    """Planetary stage of Table 5: Z_sun 22, Z_planet 32, Z_ring 86, module 10 mm, 3 planets.

    Parameters
    ----------
    output_torque_nm : float
        Counter torque on the sun [N m] (Table 4: 1 kN m; Fig. 10-11: 1 N m).
    c0_ns_per_mm2 : float
        Contact damping [N s/mm^2] (Fig. 10-11: 50).
    n_planets : int
        Number of planets.
    """
    mesh = _table35_contact(c0_ns_per_mm2)
    r_s, r_r = PlanetaryStage.radii_from_teeth("stage1", 10.0, 22, 86)
    stage = PlanetaryStage(
        name="stage1",
        sun_radius_m=r_s,
        ring_radius_m=r_r,
        n_planets=n_planets,
        sun_mass_kg=11.06,
        sun_inertia_kgm2=units.kgmm2(7.13e4),
        planet_mass_kg=24.2,
        planet_inertia_kgm2=units.kgmm2(3.16e5),
        sun_mesh=mesh,
        ring_mesh=mesh,
        width_m=units.mm(40.0),
        module_m=units.mm(10.0),
    )
    return Drivetrain(stages=(stage,), output_torque_nm=output_torque_nm)


def _table6_stages(r1: float, lambda_per_mm: float) -> tuple[PlanetaryStage, PlanetaryStage, ParallelStage]:
    mesh = _table6_contact(lambda_per_mm)
    r_sun = units.mm(10.0 * 20 / 2)  # Z_sun = 20, module 10 mm (both planetary stages)
    r2 = TOTAL_RATIO / (r1 * STAGE3_RATIO)
    s1_sun, s1_ring = PlanetaryStage.radii_from_ratio("stage1", r1, r_sun)
    s2_sun, s2_ring = PlanetaryStage.radii_from_ratio("stage2", r2, r_sun)
    stage1 = PlanetaryStage(
        name="stage1",
        sun_radius_m=s1_sun,
        ring_radius_m=s1_ring,
        n_planets=3,
        sun_mass_kg=12.25,
        sun_inertia_kgm2=units.kgmm2(6.12e4),
        planet_mass_kg=196.06,
        planet_inertia_kgm2=units.kgmm2(1.56e7),
        sun_mesh=mesh,
        ring_mesh=mesh,
        width_m=units.mm(50.0),
        module_m=units.mm(10.0),
    )
    stage2 = PlanetaryStage(
        name="stage2",
        sun_radius_m=s2_sun,
        ring_radius_m=s2_ring,
        n_planets=3,
        sun_mass_kg=12.25,
        sun_inertia_kgm2=units.kgmm2(6.12e4),
        planet_mass_kg=11.02,
        planet_inertia_kgm2=units.kgmm2(4.96e5),
        sun_mesh=mesh,
        ring_mesh=mesh,
        width_m=units.mm(5.0),
        module_m=units.mm(10.0),
    )
    stage3 = ParallelStage(
        name="stage3",
        drive_radius_m=units.mm(10.0 * 20 / 2),  # Z_drive = 20
        driven_radius_m=units.mm(10.0 * 16 / 2),  # Z_driven = 16 (R3 = 1.25)
        drive_mass_kg=12.25,
        drive_inertia_kgm2=units.kgmm2(6.12e4),
        driven_mass_kg=7.84,
        driven_inertia_kgm2=units.kgmm2(2.50e4),
        mesh=mesh,
        width_m=units.mm(50.0),
        module_m=units.mm(10.0),
    )
    return stage1, stage2, stage3


def _table6_shafts() -> tuple[Shaft, Shaft, Shaft]:
    return (
        Shaft.from_paper("shaft1", 1.0e9, 1.0e8),  # stage-1 sun -> stage-2 carrier
        Shaft.from_paper("shaft2", 1.0e8, 1.0e7),  # stage-2 sun -> parallel drive gear
        Shaft.from_paper("shaft3", 1.0e5, 1.0e4),  # parallel driven gear -> generator
    )


def table6_gearbox(generator: GeneratorParameters | None = None, lambda_per_mm: float = 600.0) -> Drivetrain:
    """Three-stage gearbox of Table 6 (R1 = 10, R2 = 8, R3 = 1.25) with the generator rotor.

    Parameters
    ----------
    generator : GeneratorParameters, optional
        Generator rotor; default Table 6 / Sec. 4.2: 151 kg m^2, 25.4 kN m.
    lambda_per_mm : float
        Backlash regularisation factor [1/mm] (Table 6: 600).
    """
    stages = _table6_stages(10.0, lambda_per_mm)
    s1, s2, s3 = _table6_shafts()
    return Drivetrain(
        stages=stages,
        shafts=(s1, s2),
        generator=generator if generator is not None else GeneratorParameters(),
        output_shaft=s3,
    )


def sensitivity_variant(r1: float, lambda_per_mm: float, output_torque_nm: float = 1000.0) -> Drivetrain:
    """The Sec. 4.1 variant of the Table 6 gearbox, without generator.

    R1 is a real number in [6, 10], R2 = 100 / (R1 * 1.25), stage-2 masses and
    inertias are scaled by 10 / R1, and ``output_torque_nm`` loads the parallel
    stage's driven gear directly (Sec. 4.1: 1 kN m).

    Parameters
    ----------
    r1 : float
        Stage-1 ratio [-].
    lambda_per_mm : float
        Regularisation factor [1/mm].
    output_torque_nm : float
        Counter torque on the output gear [N m].
    """
    r1 = in_range("R1", r1, 6.0, 10.0)
    positive("lambda", lambda_per_mm)
    s1, s2, s3 = _table6_stages(r1, lambda_per_mm)
    s2 = s2.scaled(10.0 / r1)
    sh1, sh2, _ = _table6_shafts()
    return Drivetrain(stages=(s1, s2, s3), shafts=(sh1, sh2), output_torque_nm=output_torque_nm)


def preset(name: str, **kwargs) -> Drivetrain:
    """Drivetrain preset by name: ``table3``, ``table5`` or ``table6``."""
    builders = {"table3": table3_parallel, "table5": table5_planetary, "table6": table6_gearbox}
    if name not in builders:
        raise ParameterError("preset", name, "one of " + ", ".join(PRESETS))
    return builders[name](**kwargs)


def with_stage(drivetrain: Drivetrain, index: int, **changes) -> Drivetrain:
    """Copy of a drivetrain with one stage's fields changed."""
    stages = list(drivetrain.stages)
    stages[index] = replace(stages[index], **changes)
    return replace(drivetrain, stages=tuple(stages))


def cosim_preset(name: str) -> Drivetrain:
    """A preset with an output shaft and a generator, ready to be cut for co-simulation.

    ``table6`` is the paper's drivetrain. ``table3`` and ``table5`` (single stages)
    get Table 6's shaft 3 and generator rotor so the same FMU interface applies;
    every value is an FMU parameter afterwards.
    """
    dt = preset(name)
    if dt.generator is not None:
        return dt
    return replace(dt, generator=GeneratorParameters(), output_shaft=_table6_shafts()[2], output_torque_nm=0.0)
