"""A stated region-2 / region-3 law: the drivetrain's operating point at a mean wind speed.

The drivetrain model is driven by a prescribed rotor speed (eq. 13-14: mean
``omega0``, fluctuation ``sigma``, spectral level ``a``) against a generator
counter torque. For a variable-speed, pitch-regulated turbine (rated values:
wind speed ``V_r``, rotor speed ``omega_r``, generator torque ``T_r``,
fluctuation ``sigma_r``, spectral level ``a_r``, e.g. the paper's Sec. 4.2
point 16 rpm, 25.4 kN m, sigma 0.12 rpm, a 0.02):

Region 2 (``V < V_r``), constant optimal tip-speed ratio
    ``omega0 = max(omega_r V / V_r, omega_min)``; the aerodynamic torque grows
    with ``V^2``, so the generator torque is ``T = T_r (V / V_r)^2`` (``= k omega0^2``,
    the optimal-mode gain law of :class:`components.analysis.load_law.LoadLaw`,
    wherever the speed is not held at ``omega_min``); the rotor speed follows
    the wind's fluctuations, ``sigma = sigma_r omega0 / omega_r`` (a constant
    relative intensity).
Region 3 (``V >= V_r``), pitch control at rated
    ``omega0 = omega_r``, ``T = T_r``, ``sigma = sigma_r``.

In both regions the spectral level scales with ``sigma^2``, ``a = a_r (sigma /
sigma_r)^2``, which keeps the decay ``a / sigma^2`` of eq. 14 (the time scale
of the fluctuation) and scales only its intensity.
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import units
from ..errors import ParameterError
from ..validation import non_negative, positive


@dataclass(frozen=True)
class OperatingPoint:
    """The drivetrain's operating point in one wind-speed bin, SI units.

    Attributes
    ----------
    wind_speed_m_s : float
        Bin centre [m/s].
    rotor_speed_rad_s : float or None
        Mean rotor speed omega0 [rad/s] (None: the base scenario's).
    generator_torque_nm : float or None
        Generator counter torque [N m] (None: the base scenario's).
    sigma_rad_s : float or None
        Rotor-speed fluctuation intensity [rad/s] (None: the base scenario's).
    spectrum_level : float or None
        Spectral level a [(rad/s)^2 / (rad/s)] (None: the base scenario's).
    region : str
        ``"2"``, ``"3"`` or ``"table"`` (given, not derived).
    """

    wind_speed_m_s: float
    rotor_speed_rad_s: float | None = None
    generator_torque_nm: float | None = None
    sigma_rad_s: float | None = None
    spectrum_level: float | None = None
    region: str = "table"


@dataclass(frozen=True)
class OperatingLaw:
    """Region-2 / region-3 operating law (module docstring), SI units.

    Parameters
    ----------
    rated_wind_speed_m_s : float
        V_r [m/s].
    rated_rotor_speed_rad_s : float
        omega_r [rad/s] (paper: 16 rpm).
    rated_torque_nm : float
        T_r [N m] (paper: 25.4 kN m).
    rated_sigma_rad_s : float
        sigma_r [rad/s] (paper: 0.12 rpm).
    rated_spectrum_level : float
        a_r [(rad/s)^2 / (rad/s)] (paper: 0.02 in rpm units).
    minimum_rotor_speed_rad_s : float
        omega_min [rad/s] (0: none).
    """

    rated_wind_speed_m_s: float
    rated_rotor_speed_rad_s: float = units.rpm(16.0)
    rated_torque_nm: float = 25.4e3
    rated_sigma_rad_s: float = units.rpm(0.12)
    rated_spectrum_level: float = 0.02 * units.RPM_TO_RAD_PER_S ** 2
    minimum_rotor_speed_rad_s: float = 0.0

    def __post_init__(self) -> None:
        positive("operating_law.rated_wind_speed", self.rated_wind_speed_m_s)
        positive("operating_law.rated_rotor_speed", self.rated_rotor_speed_rad_s)
        positive("operating_law.rated_torque", self.rated_torque_nm)
        positive("operating_law.rated_sigma", self.rated_sigma_rad_s)
        positive("operating_law.rated_spectrum_level", self.rated_spectrum_level)
        non_negative("operating_law.minimum_rotor_speed", self.minimum_rotor_speed_rad_s)
        if self.minimum_rotor_speed_rad_s > self.rated_rotor_speed_rad_s:
            raise ParameterError("operating_law.minimum_rotor_speed", self.minimum_rotor_speed_rad_s,
                                 f"<= the rated rotor speed {self.rated_rotor_speed_rad_s:g} rad/s")

    def at(self, wind_speed_m_s: float) -> OperatingPoint:
        """The operating point at a mean wind speed [m/s] (> 0)."""
        v = positive("wind_speed", wind_speed_m_s)
        ratio = v / self.rated_wind_speed_m_s
        if ratio >= 1.0:
            speed, torque, sigma, region = self.rated_rotor_speed_rad_s, self.rated_torque_nm, self.rated_sigma_rad_s, "3"
        else:
            speed = max(self.rated_rotor_speed_rad_s * ratio, self.minimum_rotor_speed_rad_s)
            torque = self.rated_torque_nm * ratio**2
            sigma = self.rated_sigma_rad_s * speed / self.rated_rotor_speed_rad_s
            region = "2"
        level = self.rated_spectrum_level * (sigma / self.rated_sigma_rad_s) ** 2
        return OperatingPoint(v, speed, torque, sigma, level, region)

    def describe(self) -> str:
        """One line for reports."""
        text = (f"region 2 below {self.rated_wind_speed_m_s:g} m/s (speed ~ V, torque ~ V^2, sigma ~ speed), "
                f"region 3 at rated ({units.rad_per_s_to_rpm(self.rated_rotor_speed_rad_s):g} rpm, "
                f"{self.rated_torque_nm / 1e3:g} kN m, sigma {units.rad_per_s_to_rpm(self.rated_sigma_rad_s):g} rpm)")
        if self.minimum_rotor_speed_rad_s:
            text += f"; speed >= {units.rad_per_s_to_rpm(self.minimum_rotor_speed_rad_s):g} rpm"
        return text
