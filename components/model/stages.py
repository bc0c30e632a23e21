"""Parameter sets of gear stages and shafts (frozen, validated, SI units).

Geometry is given by pitch radii; ``from_teeth`` builds them from module and
tooth counts as in the paper's tables, ``from_ratio`` from a real-valued stage
ratio (Sec. 4.1 sweeps ratios, not integer teeth).

Stage members and connections (Fig. 14 as read in DESIGN.md):

* planetary stage: input member = carrier, output member = sun, ring fixed;
  speed ratio ``1 + r_ring / r_sun``.
* parallel stage: input member = drive gear, output member = driven gear;
  speed ratio ``r_drive / r_driven``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .. import units
from ..errors import ParameterError
from ..validation import finite, integer_at_least, non_negative, positive, set_fields
from .bearings import NamedBearing, ParallelLateral, PlanetaryLateral, pin_errors
from .contact import MeshContact

STEEL_DENSITY_KG_M3 = 7800.0


def _radius_from_teeth(name: str, module_mm: float, teeth: float) -> float:
    m = positive(f"{name}.module", module_mm)
    z = positive(f"{name}.teeth", teeth)
    return units.mm(m * z / 2.0)


@dataclass(frozen=True)
class PlanetaryStage:
    """A planetary stage with ``n_planets`` equally spaced identical planets.

    Parameters
    ----------
    name : str
        Stage name used in variable names, e.g. ``"stage1"``.
    sun_radius_m, ring_radius_m : float
        Pitch radii [m]; the planet radius is ``(r_ring - r_sun) / 2``.
    n_planets : int
        Number of planets (>= 1).
    sun_mass_kg, sun_inertia_kgm2 : float
        Sun gear mass [kg] and polar moment of inertia [kg m^2].
    planet_mass_kg, planet_inertia_kgm2 : float
        Mass [kg] and spin inertia [kg m^2] of one planet.
    carrier_inertia_kgm2 : float
        Carrier inertia [kg m^2] *in addition to* the planets' orbital inertia
        ``n m_p r_c^2``, which is always included. The paper gives none: default 0.
    sun_mesh, ring_mesh : MeshContact
        Contact parameters of the sun-planet and ring-planet meshes.
    width_m : float
        Face width [m] (informational; used by the solid-disc mass check).
    module_m : float
        Gear module [m] (tooth counts ``2 r / m`` for the mesh frequency and phasing).
    planet_angles_rad : tuple of float, optional
        Carrier angle ``psi_i`` [rad] of each planet, increasing in ``[0, 2 pi)``; None
        (default) means equally spaced, ``psi_i = 2 pi (i - 1) / n``. The torsional model
        uses them for the mesh phasing only (:mod:`components.model.mesh_stiffness`), the
        lateral one for the directions of the meshes and planet bearings too.
    lateral : PlanetaryLateral or None
        The lateral-torsional model (bearings, carrier mass, ring support); None (default): torsional.
    pin_errors_m : tuple of (float, float) or None
        Position error of each planet's pin on the carrier, ``(radial, tangential)`` [m] (tangential
        positive in the direction of normal rotation); in both models. None: none.
    """

    name: str
    sun_radius_m: float
    ring_radius_m: float
    n_planets: int
    sun_mass_kg: float
    sun_inertia_kgm2: float
    planet_mass_kg: float
    planet_inertia_kgm2: float
    sun_mesh: MeshContact
    ring_mesh: MeshContact
    carrier_inertia_kgm2: float = 0.0
    width_m: float = 0.05
    module_m: float = 0.01
    planet_angles_rad: tuple[float, ...] | None = None
    lateral: PlanetaryLateral | None = None
    pin_errors_m: tuple[tuple[float, float], ...] | None = None

    kind = "planetary"

    def __post_init__(self) -> None:
        n = self.name
        set_fields(
            self,
            sun_radius_m=positive(f"{n}.sun_radius_m", self.sun_radius_m),
            ring_radius_m=positive(f"{n}.ring_radius_m", self.ring_radius_m),
            n_planets=integer_at_least(f"{n}.n_planets", self.n_planets, 1),
            sun_mass_kg=positive(f"{n}.sun_mass_kg", self.sun_mass_kg),
            sun_inertia_kgm2=positive(f"{n}.sun_inertia_kgm2", self.sun_inertia_kgm2),
            planet_mass_kg=positive(f"{n}.planet_mass_kg", self.planet_mass_kg),
            planet_inertia_kgm2=positive(f"{n}.planet_inertia_kgm2", self.planet_inertia_kgm2),
            carrier_inertia_kgm2=non_negative(f"{n}.carrier_inertia_kgm2", self.carrier_inertia_kgm2),
            width_m=positive(f"{n}.width_m", self.width_m),
            module_m=positive(f"{n}.module_m", self.module_m),
        )
        if not self.ring_radius_m > self.sun_radius_m:
            raise ParameterError(
                f"{n}.ring_radius_m", self.ring_radius_m, f"> sun radius {self.sun_radius_m:g} m (ring larger than sun)"
            )
        for field_name in ("sun_mesh", "ring_mesh"):
            if not isinstance(getattr(self, field_name), MeshContact):
                raise ParameterError(f"{n}.{field_name}", getattr(self, field_name), "a MeshContact")
        if self.planet_angles_rad is not None:
            set_fields(self, planet_angles_rad=_planet_angles(n, self.planet_angles_rad, self.n_planets))
        if self.lateral is not None and not isinstance(self.lateral, PlanetaryLateral):
            raise ParameterError(f"{n}.lateral", self.lateral, "a PlanetaryLateral or None (torsional)")
        if self.pin_errors_m is not None:
            errors = pin_errors(n, self.pin_errors_m, self.n_planets)
            worst = max(abs(x) for pair in errors for x in pair)
            if worst > 0.1 * self.module_m:  # a tenth of a module: far beyond any manufacturing tolerance
                raise ParameterError(f"{n}.pin_errors_m", worst, f"at most a tenth of the module "
                                     f"({0.1 * self.module_m:g} m): a pin position error, not a geometry change")
            set_fields(self, pin_errors_m=errors)

    @staticmethod
    def radii_from_teeth(name: str, module_mm: float, z_sun: float, z_ring: float) -> tuple[float, float]:
        """Pitch radii (sun, ring) [m] from module [mm] and tooth counts."""
        r_s = _radius_from_teeth(f"{name}.sun", module_mm, z_sun)
        r_r = _radius_from_teeth(f"{name}.ring", module_mm, z_ring)
        return r_s, r_r

    @staticmethod
    def radii_from_ratio(name: str, ratio: float, sun_radius_m: float) -> tuple[float, float]:
        """Pitch radii (sun, ring) [m] for a real stage ratio ``1 + r_r / r_s`` (> 2)."""
        R = positive(f"{name}.ratio", ratio)
        if not R > 2.0:
            raise ParameterError(f"{name}.ratio", ratio, "> 2 (planet radius must be positive)")
        r_s = positive(f"{name}.sun_radius_m", sun_radius_m)
        return r_s, (R - 1.0) * r_s

    @property
    def planet_positions_rad(self) -> tuple[float, ...]:
        """Carrier angle psi_i [rad] of every planet (the given ones, else equally spaced)."""
        if self.planet_angles_rad is not None:
            return self.planet_angles_rad
        return tuple(2.0 * math.pi * i / self.n_planets for i in range(self.n_planets))

    @property
    def bearings(self) -> tuple[NamedBearing, ...]:
        """The stage's rolling bearings by name (lateral model; none in the torsional one)."""
        lat = self.lateral
        if lat is None:
            return ()
        named = [(f"{self.name}.sun_bearing", lat.sun_bearing), (f"{self.name}.carrier_bearing", lat.carrier_bearing)]
        named += [(f"{self.name}.planet_bearing[{i + 1}]", lat.planet_bearing) for i in range(self.n_planets)]
        return tuple(NamedBearing(name, b.bearing_type, b.dynamic_load_rating_n) for name, b in named)

    @property
    def planet_radius_m(self) -> float:
        """Planet pitch radius [m]."""
        return 0.5 * (self.ring_radius_m - self.sun_radius_m)

    @property
    def carrier_radius_m(self) -> float:
        """Distance sun centre - planet centre [m]."""
        return self.sun_radius_m + self.planet_radius_m

    @property
    def ratio(self) -> float:
        """Speed ratio sun / carrier with the ring fixed [-]."""
        return 1.0 + self.ring_radius_m / self.sun_radius_m

    @property
    def carrier_total_inertia_kgm2(self) -> float:
        """Carrier inertia including the planets' orbital inertia [kg m^2]."""
        return self.carrier_inertia_kgm2 + self.n_planets * self.planet_mass_kg * self.carrier_radius_m**2

    @property
    def ring_teeth(self) -> float:
        """Number of ring teeth ``2 r_ring / module`` [-] (real-valued for swept ratios)."""
        return 2.0 * self.ring_radius_m / self.module_m

    def mesh_frequency_hz(self, carrier_speed_rad_s: float) -> float:
        """Gear-mesh frequency [Hz] at a carrier speed, ring fixed: ``Z_ring |omega_c| / (2 pi)``."""
        return self.ring_teeth * abs(carrier_speed_rad_s) / (2.0 * math.pi)

    def scaled(self, factor: float, name: str | None = None) -> "PlanetaryStage":
        """Copy with masses and inertias multiplied by ``factor`` (Sec. 4.1)."""
        f = positive("mass_scale", factor)
        return PlanetaryStage(
            name=name or self.name,
            sun_radius_m=self.sun_radius_m,
            ring_radius_m=self.ring_radius_m,
            n_planets=self.n_planets,
            sun_mass_kg=self.sun_mass_kg * f,
            sun_inertia_kgm2=self.sun_inertia_kgm2 * f,
            planet_mass_kg=self.planet_mass_kg * f,
            planet_inertia_kgm2=self.planet_inertia_kgm2 * f,
            sun_mesh=self.sun_mesh,
            ring_mesh=self.ring_mesh,
            carrier_inertia_kgm2=self.carrier_inertia_kgm2 * f,
            width_m=self.width_m,
            module_m=self.module_m,
            planet_angles_rad=self.planet_angles_rad,
            lateral=self.lateral,
            pin_errors_m=self.pin_errors_m,
        )


def _planet_angles(stage: str, angles, n_planets: int) -> tuple[float, ...]:
    """Validated planet angles: ``n_planets`` finite values, strictly increasing in ``[0, 2 pi)``."""
    name = f"{stage}.planet_angles_rad"
    if not isinstance(angles, (tuple, list)) or len(angles) != n_planets:
        raise ParameterError(name, angles, f"{n_planets} angles [rad], one per planet")
    out = tuple(float(finite(f"{name}[{i}]", a)) for i, a in enumerate(angles))
    if not all(0.0 <= a < 2.0 * math.pi for a in out) or any(b <= a for a, b in zip(out, out[1:])):
        raise ParameterError(name, list(out), "strictly increasing angles in [0, 2 pi) rad")
    return out


@dataclass(frozen=True)
class ParallelStage:
    """A parallel (external spur) stage.

    Parameters
    ----------
    name : str
        Stage name, e.g. ``"stage3"``.
    drive_radius_m, driven_radius_m : float
        Pitch radii [m] of the drive (input) and driven (output) gear.
    drive_mass_kg, drive_inertia_kgm2, driven_mass_kg, driven_inertia_kgm2 : float
        Masses [kg] and inertias [kg m^2].
    mesh : MeshContact
        Contact parameters.
    width_m : float
        Face width [m] (informational).
    lateral : ParallelLateral or None
        The lateral-torsional model (the gears' bearings); None (default): torsional.
    """

    name: str
    drive_radius_m: float
    driven_radius_m: float
    drive_mass_kg: float
    drive_inertia_kgm2: float
    driven_mass_kg: float
    driven_inertia_kgm2: float
    mesh: MeshContact
    width_m: float = 0.05
    module_m: float = 0.01
    lateral: ParallelLateral | None = None

    kind = "parallel"

    def __post_init__(self) -> None:
        n = self.name
        set_fields(
            self,
            drive_radius_m=positive(f"{n}.drive_radius_m", self.drive_radius_m),
            driven_radius_m=positive(f"{n}.driven_radius_m", self.driven_radius_m),
            drive_mass_kg=positive(f"{n}.drive_mass_kg", self.drive_mass_kg),
            drive_inertia_kgm2=positive(f"{n}.drive_inertia_kgm2", self.drive_inertia_kgm2),
            driven_mass_kg=positive(f"{n}.driven_mass_kg", self.driven_mass_kg),
            driven_inertia_kgm2=positive(f"{n}.driven_inertia_kgm2", self.driven_inertia_kgm2),
            width_m=positive(f"{n}.width_m", self.width_m),
            module_m=positive(f"{n}.module_m", self.module_m),
        )
        if not isinstance(self.mesh, MeshContact):
            raise ParameterError(f"{n}.mesh", self.mesh, "a MeshContact")
        if self.lateral is not None and not isinstance(self.lateral, ParallelLateral):
            raise ParameterError(f"{n}.lateral", self.lateral, "a ParallelLateral or None (torsional)")

    @property
    def bearings(self) -> tuple[NamedBearing, ...]:
        """The stage's rolling bearings by name (lateral model; none in the torsional one)."""
        lat = self.lateral
        if lat is None:
            return ()
        return tuple(NamedBearing(f"{self.name}.{member}_bearing", b.bearing_type, b.dynamic_load_rating_n)
                     for member, b in (("drive", lat.drive_bearing), ("driven", lat.driven_bearing)))

    @property
    def ratio(self) -> float:
        """Speed ratio driven / drive [-]."""
        return self.drive_radius_m / self.driven_radius_m

    @property
    def drive_teeth(self) -> float:
        """Number of drive-gear teeth ``2 r_drive / module`` [-]."""
        return 2.0 * self.drive_radius_m / self.module_m

    def mesh_frequency_hz(self, drive_speed_rad_s: float) -> float:
        """Gear-mesh frequency [Hz] at a drive-gear speed: ``Z_drive |omega| / (2 pi)``."""
        return self.drive_teeth * abs(drive_speed_rad_s) / (2.0 * math.pi)


@dataclass(frozen=True)
class Shaft:
    """Torsional spring-damper joining two members.

    Parameters
    ----------
    name : str
        Shaft name, e.g. ``"shaft1"``.
    stiffness_nm_per_rad : float
        Torsional stiffness [N m/rad].
    damping_nms_per_rad : float
        Torsional damping [N m s/rad].
    """

    name: str
    stiffness_nm_per_rad: float
    damping_nms_per_rad: float = 0.0

    def __post_init__(self) -> None:
        set_fields(
            self,
            stiffness_nm_per_rad=positive(f"{self.name}.stiffness_nm_per_rad", self.stiffness_nm_per_rad),
            damping_nms_per_rad=non_negative(f"{self.name}.damping_nms_per_rad", self.damping_nms_per_rad),
        )

    @classmethod
    def from_paper(cls, name: str, k_nmm_per_deg: float, c_nmms_per_deg: float) -> "Shaft":
        """Build from Table 6 units: stiffness [N mm/deg], damping [N mm s/deg]."""
        return cls(
            name,
            units.torsional_stiffness(positive(f"{name}.stiffness", k_nmm_per_deg)),
            units.torsional_damping(non_negative(f"{name}.damping", c_nmms_per_deg)),
        )


def solid_disc(radius_m: float, width_m: float, density_kg_m3: float = STEEL_DENSITY_KG_M3) -> tuple[float, float]:
    """Mass [kg] and polar inertia [kg m^2] of a solid disc."""
    mass = density_kg_m3 * math.pi * radius_m**2 * width_m
    return mass, 0.5 * mass * radius_m**2


Stage = PlanetaryStage | ParallelStage
