"""Spur-gear geometry of the stages: pitch and base radii, disc bodies, the checks of a planetary stage.

Pure functions in SI units (the drivetrain files of the orchestrator give their
numbers to these). Standard full-depth involute gears are assumed: pitch radius
``r = m z / 2``, base radius ``r_b = r cos(alpha)`` (the moment arm of the
normal mesh force, paper eq. 5-7), addendum ``h_a = m`` (tip radius ``r + m``).

Planetary stage (ring fixed, carrier in, sun out, paper Fig. 14):

* coaxiality of standard gears: ``Z_ring = Z_sun + 2 Z_planet``;
* assembly condition for equally spaced planets: ``(Z_sun + Z_ring) / n`` integer;
  for planets at explicit carrier angles ``psi_i``: ``(Z_sun + Z_ring) psi_i / (2 pi)``
  integer for every planet (the meshing of planet i matches that of planet 1);
* neighbour condition: adjacent planets do not touch, the distance of their centres
  ``2 a sin(delta_psi / 2)`` (``a = r_sun + r_planet`` the centre distance) exceeds a
  planet's tip diameter ``2 (r_planet + m)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

from ..errors import ParameterError
from ..validation import non_negative, positive

#: addendum of a standard full-depth tooth in modules (tip radius = pitch radius + ADDENDUM * module)
ADDENDUM_MODULES = 1.0
#: tolerance on the integer conditions when planet angles are given in degrees (rounded angles)
INTEGER_TOLERANCE = 1e-6


def pitch_radius_m(module_m: float, teeth: float) -> float:
    """Pitch radius ``m z / 2`` [m]."""
    return positive("module", module_m) * positive("teeth", teeth) / 2.0


def base_radius_m(pitch_radius: float, pressure_angle_rad: float) -> float:
    """Base radius ``r cos(alpha)`` [m], the moment arm of the normal mesh force (eq. 5-7)."""
    return pitch_radius * math.cos(pressure_angle_rad)


def teeth_of(radius_m: float, module_m: float) -> float:
    """Tooth count ``2 r / m`` [-] (real-valued when the radii do not come from teeth)."""
    return 2.0 * radius_m / module_m


def is_whole(value: float, tolerance: float = INTEGER_TOLERANCE) -> bool:
    """Whether ``value`` is an integer within ``tolerance``."""
    return abs(value - round(value)) <= tolerance


@dataclass(frozen=True)
class DiscBody:
    """Mass and polar inertia of a steel disc: a gear body of the pitch diameter and the face width.

    Attributes
    ----------
    mass_kg, inertia_kgm2 : float
        ``m = rho pi (r_o^2 - r_i^2) b``, ``J = m (r_o^2 + r_i^2) / 2``.
    outer_radius_m, bore_radius_m, width_m, density_kg_m3 : float
        The disc.
    """

    mass_kg: float
    inertia_kgm2: float
    outer_radius_m: float
    bore_radius_m: float
    width_m: float
    density_kg_m3: float

    @property
    def description(self) -> str:
        """``"solid disc d = 210 mm, b = 227.5 mm, 7800 kg/m3"`` or ``"bored disc ..."``."""
        kind = f"bored disc (bore {2e3 * self.bore_radius_m:g} mm)" if self.bore_radius_m > 0 else "solid disc"
        return (f"{kind} d = {2e3 * self.outer_radius_m:g} mm, b = {1e3 * self.width_m:g} mm, "
                f"{self.density_kg_m3:g} kg/m3")


def disc_body(outer_radius_m: float, width_m: float, density_kg_m3: float, bore_radius_m: float = 0.0) -> DiscBody:
    """A solid (``bore_radius_m = 0``) or bored disc.

    Raises
    ------
    ParameterError
        A radius, width or density that is not positive, or a bore not smaller than the disc.
    """
    r_o = positive("outer_radius", outer_radius_m)
    b = positive("width", width_m)
    rho = positive("density", density_kg_m3)
    r_i = non_negative("bore_radius", bore_radius_m)
    if not r_i < r_o:
        raise ParameterError("bore_diameter", 2.0 * r_i, f"< the pitch diameter {2.0 * r_o:g} m")
    mass = rho * math.pi * (r_o**2 - r_i**2) * b
    return DiscBody(mass, 0.5 * mass * (r_o**2 + r_i**2), r_o, r_i, b, rho)


@dataclass(frozen=True)
class GeometryCheck:
    """One geometry condition of a stage.

    Attributes
    ----------
    name : str
        ``"ring teeth"``, ``"assembly"`` or ``"planet clearance"``.
    passed : bool or None
        None: not applicable (e.g. radii given instead of teeth).
    detail : str
        The condition with its numbers.
    """

    name: str
    passed: bool | None
    detail: str


def ring_teeth_check(z_sun: int, z_planet: int, z_ring: int) -> GeometryCheck:
    """Coaxiality of standard gears: ``Z_ring = Z_sun + 2 Z_planet``."""
    expected = z_sun + 2 * z_planet
    return GeometryCheck("ring teeth", z_ring == expected,
                         f"Z_ring = {z_ring}, Z_sun + 2 Z_planet = {z_sun} + 2 x {z_planet} = {expected}")


def assembly_check(z_sun: int, z_ring: int, n_planets: int,
                   planet_angles_rad: Sequence[float] | None = None) -> GeometryCheck:
    """Assembly condition: ``(Z_sun + Z_ring) / n`` integer, or ``(Z_sun + Z_ring) psi_i / 2 pi`` for given angles."""
    total = z_sun + z_ring
    if planet_angles_rad is None:
        value = total / n_planets
        return GeometryCheck("assembly", is_whole(value, 0.0),
                             f"(Z_sun + Z_ring) / n = {total} / {n_planets} = {value:.6g} (integer needed)")
    values = [total * psi / (2.0 * math.pi) for psi in planet_angles_rad]
    bad = [i + 1 for i, v in enumerate(values) if not is_whole(v)]
    text = ", ".join(f"{v:.6g}" for v in values)
    return GeometryCheck("assembly", not bad, f"(Z_sun + Z_ring) psi_i / 2 pi = {text} (integers needed"
                         + (f"; planet(s) {', '.join(map(str, bad))} fail)" if bad else ")"))


def planet_clearance_m(sun_radius_m: float, planet_radius_m: float, module_m: float,
                       planet_angles_rad: Sequence[float]) -> float:
    """Smallest gap between the tip circles of adjacent planets [m] (negative: they overlap).

    One planet alone has no neighbour: ``inf``.
    """
    angles = sorted(planet_angles_rad)
    if len(angles) < 2:
        return math.inf
    a = sun_radius_m + planet_radius_m
    gaps = [b - c for c, b in zip(angles, angles[1:])] + [2.0 * math.pi - angles[-1] + angles[0]]
    tip = planet_radius_m + ADDENDUM_MODULES * module_m
    return min(2.0 * a * math.sin(0.5 * g) for g in gaps) - 2.0 * tip


def clearance_check(sun_radius_m: float, planet_radius_m: float, module_m: float,
                    planet_angles_rad: Sequence[float]) -> GeometryCheck:
    """Neighbour condition: adjacent planets' tip circles do not overlap."""
    gap = planet_clearance_m(sun_radius_m, planet_radius_m, module_m, planet_angles_rad)
    if math.isinf(gap):
        return GeometryCheck("planet clearance", True, "one planet: no neighbour")
    return GeometryCheck("planet clearance", gap > 0.0,
                         f"smallest gap between adjacent planet tip circles {1e3 * gap:.4g} mm (> 0 needed)")
