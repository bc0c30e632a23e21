"""Bearings, supports, pin position errors and gravity: the parameters of the lateral-torsional stage model.

A stage is torsional (the paper's model: every body turns about a fixed axis) unless it carries
one of the lateral tables below; then its bodies also translate in the plane of the gears
(:mod:`components.model.lateral`, after Lin and Parker, 1999):

* :class:`PlanetaryLateral` - the carrier's mass, the bearings of sun, carrier and planets and,
  optionally, a ring that moves on a translational and a torsional support (else the ring is
  rigidly fixed, as in the torsional model);
* :class:`ParallelLateral` - the bearings of the drive and driven gear and the direction of the
  line of centres.

A :class:`Bearing` is an isotropic spring-damper in the plane (the same stiffness in every
radial direction) with, for the bearing life of ISO 281, its type and dynamic load rating C.
Planet pin position errors (:attr:`~components.model.stages.PlanetaryStage.pin_errors_m`) apply
to the torsional model too; gravity (:class:`Gravity`) acts on the translating bodies only.
All values SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError
from ..validation import finite, in_range, non_negative, positive, set_fields

#: bearing types of ISO 281 (life exponent 3 and 10/3)
BEARING_TYPES = ("ball", "roller")


@dataclass(frozen=True)
class Bearing:
    """An isotropic radial bearing (or support): stiffness and damping in every radial direction.

    Parameters
    ----------
    stiffness_n_per_m : float
        Radial stiffness [N/m] (>= 0; 0 leaves the body floating on its meshes).
    damping_ns_per_m : float
        Radial damping [N s/m].
    bearing_type : {"ball", "roller"} or None
        ISO 281 type (life exponent 3 or 10/3); None: no life is rated.
    dynamic_load_rating_n : float or None
        ISO 281 basic dynamic load rating C [N]; None: no life is rated.
    """

    stiffness_n_per_m: float
    damping_ns_per_m: float = 0.0
    bearing_type: str | None = None
    dynamic_load_rating_n: float | None = None

    def __post_init__(self) -> None:
        set_fields(self, stiffness_n_per_m=non_negative("bearing.stiffness", self.stiffness_n_per_m),
                   damping_ns_per_m=non_negative("bearing.damping", self.damping_ns_per_m))
        if self.bearing_type is not None and self.bearing_type not in BEARING_TYPES:
            raise ParameterError("bearing.type", self.bearing_type, '"ball" or "roller" (ISO 281)')
        if self.dynamic_load_rating_n is not None:
            set_fields(self, dynamic_load_rating_n=positive("bearing.dynamic_load_rating", self.dynamic_load_rating_n))


@dataclass(frozen=True)
class RingSupport:
    """A ring gear that moves: its mass and inertia on a translational and a torsional support.

    Parameters
    ----------
    mass_kg, inertia_kgm2 : float
        Ring mass [kg] and polar inertia [kg m^2].
    bearing : Bearing
        Translational support to the housing (the ring does not turn: no life is rated).
    torsional_stiffness_nm_per_rad, torsional_damping_nms_per_rad : float
        Torsional support to the housing [N m/rad], [N m s/rad].
    """

    mass_kg: float
    inertia_kgm2: float
    bearing: Bearing
    torsional_stiffness_nm_per_rad: float
    torsional_damping_nms_per_rad: float = 0.0

    def __post_init__(self) -> None:
        set_fields(self, mass_kg=positive("ring.mass", self.mass_kg),
                   inertia_kgm2=positive("ring.inertia", self.inertia_kgm2),
                   torsional_stiffness_nm_per_rad=positive("ring.torsional_stiffness",
                                                           self.torsional_stiffness_nm_per_rad),
                   torsional_damping_nms_per_rad=non_negative("ring.torsional_damping",
                                                              self.torsional_damping_nms_per_rad))
        if not isinstance(self.bearing, Bearing):
            raise ParameterError("ring.bearing", self.bearing, "a Bearing")


@dataclass(frozen=True)
class PlanetaryLateral:
    """The lateral-torsional model of a planetary stage (Lin and Parker, 1999).

    Parameters
    ----------
    carrier_mass_kg : float
        Carrier mass [kg] (its translation; the planets' masses are their own bodies).
    sun_bearing, carrier_bearing : Bearing
        Supports of sun and carrier to the housing.
    planet_bearing : Bearing
        Each planet's bearing on its carrier pin.
    ring : RingSupport or None
        A ring that moves on its supports; None: rigidly fixed.
    """

    carrier_mass_kg: float
    sun_bearing: Bearing
    carrier_bearing: Bearing
    planet_bearing: Bearing
    ring: RingSupport | None = None

    def __post_init__(self) -> None:
        set_fields(self, carrier_mass_kg=positive("carrier_mass", self.carrier_mass_kg))
        for name in ("sun_bearing", "carrier_bearing", "planet_bearing"):
            if not isinstance(getattr(self, name), Bearing):
                raise ParameterError(name, getattr(self, name), "a Bearing")
        if self.ring is not None and not isinstance(self.ring, RingSupport):
            raise ParameterError("ring", self.ring, "a RingSupport or None (fixed)")


@dataclass(frozen=True)
class ParallelLateral:
    """The lateral-torsional model of a parallel stage.

    Parameters
    ----------
    drive_bearing, driven_bearing : Bearing
        Supports of the drive and driven gear to the housing.
    centre_angle_rad : float
        Direction of the line of centres, drive gear to driven gear, from the horizontal [rad]
        (counter-clockwise seen from the rotor; gravity points down).
    """

    drive_bearing: Bearing
    driven_bearing: Bearing
    centre_angle_rad: float = 0.0

    def __post_init__(self) -> None:
        for name in ("drive_bearing", "driven_bearing"):
            if not isinstance(getattr(self, name), Bearing):
                raise ParameterError(name, getattr(self, name), "a Bearing")
        set_fields(self, centre_angle_rad=finite("centre_angle", self.centre_angle_rad))


@dataclass(frozen=True)
class Gravity:
    """Gravity on the translating bodies, with the rotor shaft tilted up by ``shaft_tilt_rad``.

    The plane of the gears is normal to the shaft, so it sees ``g cos(tilt)`` (the rest acts
    along the shaft, which the planar model has no coordinate for).

    Parameters
    ----------
    acceleration_m_s2 : float
        g [m/s^2].
    shaft_tilt_rad : float
        Rotor shaft tilt [rad], in [0, pi/2).
    """

    acceleration_m_s2: float = 9.80665
    shaft_tilt_rad: float = 0.0

    def __post_init__(self) -> None:
        set_fields(self, acceleration_m_s2=non_negative("gravity.acceleration", self.acceleration_m_s2))
        tilt = in_range("gravity.shaft_tilt", self.shaft_tilt_rad, 0.0, 0.5 * math.pi)
        if tilt >= 0.5 * math.pi:
            raise ParameterError("gravity.shaft_tilt", tilt, "below 90 deg (the gear plane is not horizontal)")
        set_fields(self, shaft_tilt_rad=tilt)

    @property
    def in_plane_m_s2(self) -> float:
        """The part of g in the plane of the gears [m/s^2]."""
        return self.acceleration_m_s2 * math.cos(self.shaft_tilt_rad)


@dataclass(frozen=True)
class NamedBearing:
    """A bearing of a drivetrain by name (what the ISO 281 ratings read from an FMU's record).

    Attributes
    ----------
    name : str
        e.g. ``"stage1.planet_bearing[2]"``.
    type : str or None
        ``"ball"`` or ``"roller"``.
    dynamic_load_rating_n : float or None
        C [N].
    """

    name: str
    type: str | None
    dynamic_load_rating_n: float | None


def pin_errors(stage: str, errors, n_planets: int) -> tuple[tuple[float, float], ...]:
    """Validated pin position errors: ``n_planets`` pairs ``(radial, tangential)`` [m], finite."""
    name = f"{stage}.pin_errors_m"
    if not isinstance(errors, (tuple, list)) or len(errors) != n_planets:
        raise ParameterError(name, errors, f"{n_planets} pairs (radial, tangential) [m], one per planet")
    out = []
    for i, pair in enumerate(errors):
        if not isinstance(pair, (tuple, list)) or len(pair) != 2:
            raise ParameterError(f"{name}[{i}]", pair, "a pair (radial, tangential) [m]")
        out.append((finite(f"{name}[{i}].radial", pair[0]), finite(f"{name}[{i}].tangential", pair[1])))
    return tuple(out)
