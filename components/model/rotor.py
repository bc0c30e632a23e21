"""Torque-driven wind-turbine rotor: an inertia between the aerodynamic torque and the gearbox's reaction.

``J_r omega_r' = T_aero - T_shaft``. Without a main shaft (``shaft_stiffness = 0``) the rotor
drives the stage-1 carrier rigidly, ``T_shaft = T_gearbox`` (the Gearbox's ``torque_rotor``:
what the rotor applies to the gearbox, the carrier's inertia included) and the outputs are the
rotor's motion. With a main shaft of stiffness ``k`` and damping ``c`` the outputs are the motion
of its gearbox end, a lumped inertia ``J_c`` (``carrier_inertia``) with
``J_c omega_c' = T_shaft - T_gearbox``, ``T_shaft = k (phi_r - phi_c) + c (omega_r - omega_c)``.

Both torques are held over a communication step; the rotor (and shaft) are integrated exactly
for held torques: the rigid case in closed form, the shaft case by the matrix exponential of
the two-inertia system (evaluated with a scaled Taylor series, numpy only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping

import numpy as np

from ..errors import ParameterError
from ..validation import finite, non_negative, positive, set_fields


@dataclass(frozen=True)
class RotorParameters:
    """Rotor and main-shaft parameters, SI.

    Parameters
    ----------
    inertia_kgm2 : float
        Rotor inertia about the shaft axis [kg m^2] (NREL 5-MW: hub 115 926 + three blades, 38 759 228).
    shaft_stiffness_nm_rad : float
        Main-shaft torsional stiffness [N m/rad]; 0: rigid (the rotor drives the carrier directly).
    shaft_damping_nms_rad : float
        Main-shaft damping [N m s/rad].
    carrier_inertia_kgm2 : float
        Inertia lumped at the gearbox end of the main shaft [kg m^2] (used only with a shaft; > 0 then).
    """

    inertia_kgm2: float = 38759228.0
    shaft_stiffness_nm_rad: float = 0.0
    shaft_damping_nms_rad: float = 0.0
    carrier_inertia_kgm2: float = 0.0

    def __post_init__(self) -> None:
        set_fields(
            self,
            inertia_kgm2=positive("rotor.inertia", self.inertia_kgm2),
            shaft_stiffness_nm_rad=non_negative("rotor.shaft_stiffness", self.shaft_stiffness_nm_rad),
            shaft_damping_nms_rad=non_negative("rotor.shaft_damping", self.shaft_damping_nms_rad),
            carrier_inertia_kgm2=non_negative("rotor.carrier_inertia", self.carrier_inertia_kgm2),
        )
        if self.has_shaft and not self.carrier_inertia_kgm2 > 0.0:
            raise ParameterError("rotor.carrier_inertia", self.carrier_inertia_kgm2, "> 0 with a main shaft (stiffness > 0)")

    @property
    def has_shaft(self) -> bool:
        return self.shaft_stiffness_nm_rad > 0.0


#: flat (FMU) parameter name -> field of :class:`RotorParameters`
ROTOR_FIELDS = {"inertia": "inertia_kgm2", "shaft_stiffness": "shaft_stiffness_nm_rad",
                "shaft_damping": "shaft_damping_nms_rad", "carrier_inertia": "carrier_inertia_kgm2"}


def rotor_from_values(values: Mapping[str, float], template: RotorParameters) -> RotorParameters:
    """``template`` with the flat values that ``values`` has (:data:`ROTOR_FIELDS`); errors name the flat parameter.

    Used by the Rotor FMU and by the host's checks before running.
    """
    try:
        return replace(template, **{f: values[k] for k, f in ROTOR_FIELDS.items() if k in values})
    except ParameterError as exc:  # RotorParameters names them rotor.<flat name>
        raise ParameterError(exc.name.removeprefix("rotor."), exc.value, exc.expected, exc.bounds) from None


def _expm(a: np.ndarray) -> np.ndarray:
    """Matrix exponential by scaling and squaring of a Taylor series (small matrices)."""
    norm = float(np.max(np.sum(np.abs(a), axis=1)))
    s = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0.5 else 0
    x = a / 2.0 ** s
    out = np.eye(a.shape[0])
    term = np.eye(a.shape[0])
    for k in range(1, 20):
        term = term @ x / k
        out = out + term
    for _ in range(s):
        out = out @ out
    return out


class Rotor:
    """The rotor (and main shaft) as a stepping component.

    Parameters
    ----------
    params : RotorParameters
    initial_speed_rad_s, initial_angle_rad : float
        Rotor (and, at rest in the shaft, carrier-end) motion at the start.
    initial_shaft_torque_nm : float
        With a shaft: its initial torque (twist ``T / k``), e.g. the initial aerodynamic torque.
    """

    def __init__(self, params: RotorParameters, initial_speed_rad_s: float, initial_angle_rad: float = 0.0,
                 initial_shaft_torque_nm: float = 0.0) -> None:
        if not isinstance(params, RotorParameters):
            raise ParameterError("rotor", params, "a RotorParameters")
        self.params = params
        w = finite("initial_speed", initial_speed_rad_s)
        phi = finite("initial_angle", initial_angle_rad)
        twist = finite("initial_shaft_torque", initial_shaft_torque_nm) / params.shaft_stiffness_nm_rad if params.has_shaft else 0.0
        # state [phi_r, omega_r, phi_c, omega_c]
        self.state = np.array([phi, w, phi - twist, w])
        self._cache: tuple | None = None

    @property
    def speed_rad_s(self) -> float:
        """Speed of the output end (carrier end with a shaft, else the rotor) [rad/s]."""
        return float(self.state[3] if self.params.has_shaft else self.state[1])

    @property
    def angle_rad(self) -> float:
        """Angle of the output end [rad]."""
        return float(self.state[2] if self.params.has_shaft else self.state[0])

    @property
    def rotor_speed_rad_s(self) -> float:
        return float(self.state[1])

    @property
    def shaft_torque_nm(self) -> float:
        """Main-shaft torque [N m] (0 without a shaft)."""
        p = self.params
        if not p.has_shaft:
            return 0.0
        s = self.state
        return float(p.shaft_stiffness_nm_rad * (s[0] - s[2]) + p.shaft_damping_nms_rad * (s[1] - s[3]))

    def _propagator(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        if self._cache is not None and self._cache[0] == h:
            return self._cache[1], self._cache[2]
        p = self.params
        k, c, jr, jc = p.shaft_stiffness_nm_rad, p.shaft_damping_nms_rad, p.inertia_kgm2, p.carrier_inertia_kgm2
        a = np.zeros((5, 5))  # augmented with a constant 1 carrying nothing (forcing added separately)
        a[0, 1] = a[2, 3] = 1.0
        a[1] = [-k / jr, -c / jr, k / jr, c / jr, 0.0]
        a[3] = [k / jc, c / jc, -k / jc, -c / jc, 0.0]
        big = np.zeros((7, 7))
        big[:5, :5] = a
        big[1, 5] = 1.0 / jr  # forcing T_aero on the rotor
        big[3, 6] = -1.0 / jc  # reaction T_gearbox on the carrier end
        e = _expm(big * h)
        self._cache = (h, e[:4, :4], e[:4, 5:7])
        return e[:4, :4], e[:4, 5:7]

    def step(self, h: float, aero_torque_nm: float, gearbox_torque_nm: float) -> None:
        """Advance by ``h`` [s] with both torques held [N m] (exact)."""
        p = self.params
        if not p.has_shaft:
            acc = (aero_torque_nm - gearbox_torque_nm) / p.inertia_kgm2
            s = self.state
            s[0] += s[1] * h + 0.5 * acc * h * h
            s[1] += acc * h
            s[2], s[3] = s[0], s[1]
            return
        phi_m, force_m = self._propagator(h)
        self.state = phi_m @ self.state + force_m @ np.array([aero_torque_nm, gearbox_torque_nm])
