"""Rotor FMU: torque-driven rotor inertia, optionally with a main shaft (:mod:`components.model.rotor`).

Inputs ``aero_torque`` [N m] (aerodynamic torque on the rotor) and ``gearbox_torque`` [N m] (the
Gearbox's ``torque_rotor``, the torque the rotor applies to the gearbox), held over a step.
Outputs ``omega``, ``phi`` (the motion that drives the Gearbox's stage-1 carrier: the rotor's,
or with a main shaft its gearbox end's), ``rotor_speed`` and ``shaft_torque``.
"""

from __future__ import annotations

import math
from typing import Any, Hashable, Iterable, Mapping

from components.errors import ParameterError, SolverError
from components.model.description import build
from components.model.rotor import ROTOR_FIELDS
from components.model.rotor import Rotor as RotorComponent
from components.model.rotor import rotor_from_values

from .base import DtcosimSlave
from .interface import Variable, real_input, real_output, real_parameter

class Rotor(DtcosimSlave):
    """``J_r omega' = T_aero - T_gearbox`` (rigid) or the rotor and main shaft, as an FMU."""

    description = "dtcosim Rotor: torque-driven rotor inertia (optionally with a main shaft) driving the gearbox (SI)"
    eager_output_groups = frozenset({"motion"})

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        p = build(model["rotor"], "model.rotor")
        return (
            real_parameter("inertia", p.inertia_kgm2, "kg.m2", "rotor inertia about the shaft axis"),
            real_parameter("shaft_stiffness", p.shaft_stiffness_nm_rad, "N.m/rad", "main-shaft stiffness (0: rigid)"),
            real_parameter("shaft_damping", p.shaft_damping_nms_rad, "N.m.s/rad", "main-shaft damping"),
            real_parameter("carrier_inertia", p.carrier_inertia_kgm2, "kg.m2",
                           "inertia lumped at the gearbox end of the main shaft (with a shaft only)"),
            real_parameter("initial_speed", float(model["initial_speed_rad_s"]), "rad/s", "rotor speed at the start"),
            real_parameter("initial_angle", 0.0, "rad", "rotor angle at the start"),
            real_input("aero_torque", 0.0, "N.m", "aerodynamic torque on the rotor"),
            real_input("gearbox_torque", 0.0, "N.m", "torque the rotor applies to the gearbox (Gearbox torque_rotor)"),
            real_output("omega", "rad/s", "speed driving the stage-1 carrier", "rotor_speed"),
            real_output("phi", "rad", "angle driving the stage-1 carrier", "rotor_angle"),
            real_output("rotor_speed", "rad/s", "speed of the rotor inertia itself"),
            real_output("shaft_torque", "N.m", "main-shaft torque (0 when rigid)", "main_shaft_torque"),
        )

    def output_group(self, name: str) -> Hashable:
        return "motion"

    def _configure(self) -> None:
        self.params = rotor_from_values({k: self.value(k) for k in ROTOR_FIELDS}, build(self.model["rotor"], "model.rotor"))
        self._new_rotor()

    def _new_rotor(self) -> None:
        self.rotor = RotorComponent(self.params, self.value("initial_speed"), self.value("initial_angle"),
                                    self.value("aero_torque"))

    def _initialize(self, start_time: float) -> None:
        self._new_rotor()

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        aero, gear = self.value("aero_torque"), self.value("gearbox_torque")
        if not math.isfinite(aero + gear):
            raise SolverError(f"non-finite input (aero_torque={aero!r}, gearbox_torque={gear!r})", time)
        self.rotor.step(step_size, aero, gear)

    def _refresh(self, group: Hashable) -> None:
        r = self.rotor
        for name, value in (("omega", r.speed_rad_s), ("phi", r.angle_rad), ("rotor_speed", r.rotor_speed_rad_s),
                            ("shaft_torque", r.shaft_torque_nm)):
            self._values[self.vr[name]] = value

    def _component_state(self) -> dict:
        return {"state": [float(x) for x in self.rotor.state]}

    def _restore_component_state(self, state: dict) -> None:
        self._new_rotor()
        self.rotor.state[:] = state["state"]
