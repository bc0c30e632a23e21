"""TorqueController FMU: the NREL 5-MW baseline variable-speed torque law (:mod:`components.model.torque_controller`).

Inputs ``generator_speed`` [rad/s] (measured, low-pass filtered inside) and ``pitch`` [rad] (blade
pitch: region 3 from ``region3_min_pitch`` on, as the baseline controller; leave unconnected = 0
for a speed-only law). Output ``generator_torque`` [N m], the demand for the GeneratorRotor's
``counter_torque_input``; ``filtered_speed``. Every constant of the law is a parameter (defaults:
the 5-MW baseline's).
"""

from __future__ import annotations

import math
from typing import Any, Hashable, Iterable, Mapping

from components.errors import ParameterError, SolverError
from components.model.description import build
from components.model.torque_controller import REGION3_MODES, TorqueController as ControllerComponent
from components.model.torque_controller import CONTROLLER_FIELDS, controller_from_values

from .base import DtcosimSlave
from .interface import Variable, enumeration_text, integer_parameter, real_input, real_output, real_parameter

#: FMU parameter -> (field, unit, description)
PARAMETERS = {
    "cut_in_speed": ("cut_in_speed_rad_s", "rad/s", "generator speed below which the torque is zero (VS_CtInSp)"),
    "region2_start": ("region2_start_rad_s", "rad/s", "start of region 2, k w^2 (VS_Rgn2Sp)"),
    "optimal_gain": ("optimal_gain_nm_s2", "N.m.s2/rad2", "k of the region-2 law k w^2 (VS_Rgn2K)"),
    "rated_speed": ("rated_speed_rad_s", "rad/s", "rated generator speed, start of region 3 (VS_RtGnSp)"),
    "rated_power": ("rated_power_w", "W", "rated mechanical power (VS_RtPwr)"),
    "slip_percent": ("slip_percent", "1", "slip of the region-2.5 line [%] (VS_SlPc)"),
    "rated_torque": ("rated_torque_nm", "N.m", "region-3 torque in the constant-torque mode"),
    "region3_min_pitch": ("region3_min_pitch_rad", "rad", "blade pitch from which region 3 applies (VS_Rgn3MP)"),
    "max_torque": ("max_torque_nm", "N.m", "torque limit (VS_MaxTq)"),
    "max_rate": ("max_rate_nm_s", "N.m/s", "torque rate limit (VS_MaxRat)"),
    "filter_corner": ("filter_corner_rad_s", "rad/s", "corner frequency of the speed filter (CornerFreq)"),
}


class TorqueController(DtcosimSlave):
    """Generator torque demand from the filtered generator speed, as an FMU."""

    description = "dtcosim TorqueController: NREL 5-MW baseline variable-speed generator torque law (SI)"
    eager_output_groups = frozenset({"torque"})

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        p = build(model["controller"], "model.controller")
        variables = [real_parameter(name, getattr(p, f), unit, text) for name, (f, unit, text) in PARAMETERS.items()]
        variables += [
            integer_parameter("region3_mode", REGION3_MODES.index(p.region3_mode),
                              f"region 3: {enumeration_text(REGION3_MODES)}"),
            real_input("generator_speed", float(model["initial_speed_rad_s"]), "rad/s", "measured generator speed"),
            real_input("pitch", 0.0, "rad", "blade pitch angle (region-3 criterion)"),
            real_output("generator_torque", "N.m", "generator torque demand", "generator_torque_demand"),
            real_output("filtered_speed", "rad/s", "low-pass filtered generator speed", "filtered_generator_speed"),
        ]
        return variables

    def output_group(self, name: str) -> Hashable:
        return "torque"

    def _configure(self) -> None:
        names = (*CONTROLLER_FIELDS, "region3_mode")
        self.params = controller_from_values({n: self.value(n) for n in names},
                                             build(self.model["controller"], "model.controller"))
        self._new()

    def _new(self) -> None:
        self.controller = ControllerComponent(self.params, self.value("generator_speed"), self.value("pitch"))

    def _initialize(self, start_time: float) -> None:
        self._new()

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        speed, pitch = self.value("generator_speed"), self.value("pitch")
        if not math.isfinite(speed + pitch):
            raise SolverError(f"non-finite input (generator_speed={speed!r}, pitch={pitch!r})", time)
        self.controller.step(step_size, speed, pitch)

    def _refresh(self, group: Hashable) -> None:
        self._values[self.vr["generator_torque"]] = self.controller.torque_nm
        self._values[self.vr["filtered_speed"]] = self.controller.filtered_speed_rad_s

    def _component_state(self) -> dict:
        return {"filtered": self.controller.filtered_speed_rad_s, "torque": self.controller.torque_nm}

    def _restore_component_state(self, state: dict) -> None:
        self._new()
        self.controller.filtered_speed_rad_s = float(state["filtered"])
        self.controller.torque_nm = float(state["torque"])
