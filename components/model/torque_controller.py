"""Generator torque law of the NREL 5-MW baseline controller's variable-speed part (Jonkman et al. 2009, Sec. 7).

Regions over the filtered generator speed ``w`` [rad/s]:

* 1 (``w <= cut_in``): zero torque;
* 1.5 (``cut_in < w < region2_start``): linear from 0 to ``k region2_start^2``;
* 2 (``region2_start <= w < transition``): ``k w^2`` (optimal tip-speed ratio);
* 2.5 (``transition <= w < rated``): the line through ``(sync, 0)`` and ``(rated, P / rated)``, with
  ``sync = rated / (1 + slip/100)``; ``transition`` is where it meets ``k w^2`` (region 2 ends there);
* 3 (``w >= rated``, or blade pitch ``>= region3_min_pitch``): constant power ``P / w`` or constant
  torque ``rated_torque`` (``region3_mode``).

The torque is limited to ``max_torque`` and its rate to ``max_rate`` (as the baseline's
``VS_MaxTq``, ``VS_MaxRat``). The measured speed passes a first-order low-pass filter with
corner frequency ``filter_corner`` [rad/s] (the baseline's ``CornerFreq``), discretised
exactly for a speed held over a step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping

from ..errors import ParameterError
from ..validation import choice_bounds, finite, is_number, non_negative, one_of, positive, set_fields

REGION3_MODES = ("constant_power", "constant_torque")
#: flat (FMU) parameter name -> field of :class:`TorqueLawParameters` (``region3_mode`` is an Integer code)
CONTROLLER_FIELDS = {
    "cut_in_speed": "cut_in_speed_rad_s", "region2_start": "region2_start_rad_s", "optimal_gain": "optimal_gain_nm_s2",
    "rated_speed": "rated_speed_rad_s", "rated_power": "rated_power_w", "slip_percent": "slip_percent",
    "rated_torque": "rated_torque_nm", "region3_min_pitch": "region3_min_pitch_rad", "max_torque": "max_torque_nm",
    "max_rate": "max_rate_nm_s", "filter_corner": "filter_corner_rad_s",
}


@dataclass(frozen=True)
class TorqueLawParameters:
    """Constants of the torque law, SI (defaults: the NREL 5-MW baseline, ``DISCON`` values).

    Parameters
    ----------
    cut_in_speed_rad_s : float
        ``VS_CtInSp`` = 70.16224 rad/s (generator speed).
    region2_start_rad_s : float
        ``VS_Rgn2Sp`` = 91.21091 rad/s.
    optimal_gain_nm_s2 : float
        ``VS_Rgn2K`` = 2.332287 N m/(rad/s)^2.
    rated_speed_rad_s : float
        ``VS_RtGnSp`` = 121.6805 rad/s.
    rated_power_w : float
        ``VS_RtPwr`` = 5296610 W (mechanical power at the HSS).
    slip_percent : float
        ``VS_SlPc`` = 10 %: synchronous speed of the region-2.5 line, ``rated / 1.1``.
    rated_torque_nm : float
        Region-3 torque in the constant-torque mode (default ``rated_power / rated_speed``).
    region3_mode : {"constant_power", "constant_torque"}
    region3_min_pitch_rad : float
        ``VS_Rgn3MP`` = 0.01745329 rad: from this blade pitch on, region 3 regardless of speed.
    max_torque_nm : float
        ``VS_MaxTq`` = 47402.91 N m.
    max_rate_nm_s : float
        ``VS_MaxRat`` = 15000 N m/s (at most 1e30: a huge value means no limit).
    filter_corner_rad_s : float
        ``CornerFreq`` = 1.570796 rad/s (at most 1e30: a huge value means no filter).
    """

    cut_in_speed_rad_s: float = 70.16224
    region2_start_rad_s: float = 91.21091
    optimal_gain_nm_s2: float = 2.332287
    rated_speed_rad_s: float = 121.6805
    rated_power_w: float = 5296610.0
    slip_percent: float = 10.0
    rated_torque_nm: float = 5296610.0 / 121.6805
    region3_mode: str = "constant_power"
    region3_min_pitch_rad: float = 0.01745329
    max_torque_nm: float = 47402.91
    max_rate_nm_s: float = 15000.0
    filter_corner_rad_s: float = 1.570796

    def __post_init__(self) -> None:
        set_fields(
            self,
            cut_in_speed_rad_s=non_negative("controller.cut_in_speed", self.cut_in_speed_rad_s),
            region2_start_rad_s=positive("controller.region2_start", self.region2_start_rad_s),
            optimal_gain_nm_s2=non_negative("controller.optimal_gain", self.optimal_gain_nm_s2),
            rated_speed_rad_s=positive("controller.rated_speed", self.rated_speed_rad_s),
            rated_power_w=positive("controller.rated_power", self.rated_power_w),
            slip_percent=positive("controller.slip_percent", self.slip_percent),
            rated_torque_nm=positive("controller.rated_torque", self.rated_torque_nm),
            region3_mode=one_of("controller.region3_mode", self.region3_mode, REGION3_MODES),
            region3_min_pitch_rad=finite("controller.region3_min_pitch", self.region3_min_pitch_rad),
            max_torque_nm=positive("controller.max_torque", self.max_torque_nm),
            max_rate_nm_s=positive("controller.max_rate", self.max_rate_nm_s),
            filter_corner_rad_s=positive("controller.filter_corner", self.filter_corner_rad_s),
        )
        if not self.cut_in_speed_rad_s < self.region2_start_rad_s < self.rated_speed_rad_s:
            raise ParameterError("controller.region2_start", self.region2_start_rad_s,
                                 f"cut_in_speed ({self.cut_in_speed_rad_s:g}) < region2_start < rated_speed "
                                 f"({self.rated_speed_rad_s:g}) [rad/s]")
        s25, k = self.slope25_nm_s, self.optimal_gain_nm_s2
        if (not self.sync_speed_rad_s > self.region2_start_rad_s or s25 * (s25 - 4.0 * k * self.sync_speed_rad_s) < 0.0
                or not self.transition_speed_rad_s < self.rated_speed_rad_s):
            raise ParameterError("controller.slip_percent", self.slip_percent,
                                 "a slip whose region-2.5 line meets k w^2 between region2_start and rated_speed")

    @property
    def sync_speed_rad_s(self) -> float:
        """Speed where the region-2.5 line has zero torque (``VS_SySp``)."""
        return self.rated_speed_rad_s / (1.0 + 0.01 * self.slip_percent)

    @property
    def slope25_nm_s(self) -> float:
        """Slope of the region-2.5 line (``VS_Slope25``) [N m s/rad]."""
        return (self.rated_power_w / self.rated_speed_rad_s) / (self.rated_speed_rad_s - self.sync_speed_rad_s)

    @property
    def slope15_nm_s(self) -> float:
        """Slope of the region-1.5 line (``VS_Slope15``) [N m s/rad]."""
        return self.optimal_gain_nm_s2 * self.region2_start_rad_s ** 2 / (self.region2_start_rad_s - self.cut_in_speed_rad_s)

    @property
    def transition_speed_rad_s(self) -> float:
        """Where the region-2.5 line meets ``k w^2`` (``VS_TrGnSp``; the sync speed when k = 0)."""
        k, s, sy = self.optimal_gain_nm_s2, self.slope25_nm_s, self.sync_speed_rad_s
        if k == 0.0:
            return sy
        return (s - math.sqrt(s * (s - 4.0 * k * sy))) / (2.0 * k)


def controller_from_values(values: Mapping[str, float | int], template: TorqueLawParameters) -> TorqueLawParameters:
    """``template`` with the flat values that ``values`` has (:data:`CONTROLLER_FIELDS`, ``region3_mode`` code).

    Used by the TorqueController FMU and by the host's checks before running; errors name the flat parameter.
    """
    changes = {f: values[k] for k, f in CONTROLLER_FIELDS.items() if k in values}
    if "region3_mode" in values:
        code = values["region3_mode"]
        text = ", ".join(f"{i} = {m}" for i, m in enumerate(REGION3_MODES))
        if not (is_number(code) and float(code).is_integer() and 0 <= int(code) < len(REGION3_MODES)):
            raise ParameterError("region3_mode", code, text, choice_bounds(REGION3_MODES, text))
        changes["region3_mode"] = REGION3_MODES[int(code)]
    try:
        return replace(template, **changes)
    except ParameterError as exc:  # TorqueLawParameters names them controller.<flat name>
        raise ParameterError(exc.name.removeprefix("controller."), exc.value, exc.expected, exc.bounds) from None


def region_of(p: TorqueLawParameters, speed_rad_s: float, pitch_rad: float = 0.0) -> str:
    """The region (``"1"``, ``"1.5"``, ``"2"``, ``"2.5"``, ``"3"``) of a filtered speed and a blade pitch."""
    if speed_rad_s >= p.rated_speed_rad_s or pitch_rad >= p.region3_min_pitch_rad:
        return "3"
    if speed_rad_s <= p.cut_in_speed_rad_s:
        return "1"
    if speed_rad_s < p.region2_start_rad_s:
        return "1.5"
    if speed_rad_s < p.transition_speed_rad_s:
        return "2"
    return "2.5"


def law_torque_nm(p: TorqueLawParameters, speed_rad_s: float, pitch_rad: float = 0.0) -> float:
    """The torque law before the rate limit [N m] (limited to ``[0, max_torque]``)."""
    region = region_of(p, speed_rad_s, pitch_rad)
    w = speed_rad_s
    if region == "3":
        torque = p.rated_power_w / w if p.region3_mode == "constant_power" and w > 0.0 else p.rated_torque_nm
    elif region == "1":
        torque = 0.0
    elif region == "1.5":
        torque = p.slope15_nm_s * (w - p.cut_in_speed_rad_s)
    elif region == "2":
        torque = p.optimal_gain_nm_s2 * w * w
    else:
        torque = p.slope25_nm_s * (w - p.sync_speed_rad_s)
    return min(max(torque, 0.0), p.max_torque_nm)


class TorqueController:
    """The torque law as a stepping component: filter state and rate-limited torque.

    Parameters
    ----------
    params : TorqueLawParameters
    initial_speed_rad_s : float
        Filter state at the start (the measured generator speed there).
    initial_pitch_rad : float
        Blade pitch at the start; with the speed it sets the initial torque (no rate limit at start).
    """

    def __init__(self, params: TorqueLawParameters, initial_speed_rad_s: float, initial_pitch_rad: float = 0.0) -> None:
        if not isinstance(params, TorqueLawParameters):
            raise ParameterError("controller", params, "a TorqueLawParameters")
        self.params = params
        self.filtered_speed_rad_s = finite("initial_speed", initial_speed_rad_s)
        self.torque_nm = law_torque_nm(params, self.filtered_speed_rad_s, finite("pitch", initial_pitch_rad))

    def step(self, h: float, speed_rad_s: float, pitch_rad: float = 0.0) -> None:
        """Advance by ``h`` [s] with the measured speed and pitch held: filter exactly, then the rate-limited law."""
        p = self.params
        alpha = 1.0 - math.exp(-p.filter_corner_rad_s * h) if math.isfinite(p.filter_corner_rad_s) else 1.0
        self.filtered_speed_rad_s += alpha * (speed_rad_s - self.filtered_speed_rad_s)
        target = law_torque_nm(p, self.filtered_speed_rad_s, pitch_rad)
        limit = p.max_rate_nm_s * h
        self.torque_nm += min(max(target - self.torque_nm, -limit), limit)
