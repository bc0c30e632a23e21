"""GeneratorRotor FMU: generator inertia with counter torque and load events (:mod:`components.model.generator`).

Input ``shaft_torque`` [N m] (shaft 3, from the Gearbox FMU), held over a step; with the
parameter ``torque_from_input`` the counter torque is the input ``counter_torque_input`` (a
controller's demand or a recorded torque) instead of the schedule; ``brake_torque`` is a
high-speed-shaft brake acting against the speed;
the rotor is integrated exactly. With ``follow_gearbox`` (for hosts that step with Jacobi, beside a Gearbox
with ``generator_interface = inertia_own``) the speed is set at every communication point to the input
``omega_gearbox`` (the Gearbox's ``omega_generator``) and the shaft torque over the step is the one
:class:`~components.model.generator.ShaftTorquePrediction` extrapolates from the step means received. Parameters: ``inertia``, ``counter_torque``,
``initial_speed``, ``initial_angle`` and four load-event slots
``event{i}.kind/start/duration/factor`` (kind 0 = none). Outputs ``omega``,
``phi`` and the counter torque currently applied, ``generator_torque``.
"""

from __future__ import annotations

import math
from typing import Any, Hashable, Iterable, Mapping

from components.errors import ParameterError, SolverError
from components.model.description import build
from components.model.generator import GeneratorRotor as RotorComponent
from components.model.generator import ShaftTorquePrediction
from components.model.parameter_map import (
    EVENT_KIND_CODES,
    GENERATOR_FIELDS,
    N_EVENT_SLOTS,
    generator_from_values,
    generator_values,
)

from .base import DtcosimSlave, fmu_parameter_names
from .interface import (
    Variable,
    enumeration_text,
    integer_parameter,
    real_input,
    real_output,
    real_parameter,
    boolean_parameter,
)

_NAMES = {
    "generator.initial_speed": "initial_speed",
    "generator.initial_angle": "initial_angle",
}


class GeneratorRotor(DtcosimSlave):
    """Generator rotor ``I omega_dot = T_shaft - T_gen(t)`` as an FMU."""

    description = ("dtcosim GeneratorRotor: generator inertia driven by the shaft-3 torque against a counter "
                   "torque with load events (SI units)")
    eager_output_groups = frozenset({"motion"})

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        gen = build(model["generator"], "model.generator")
        slots = generator_values(gen)
        speed0 = float(model["initial_speed_rad_s"])
        kinds = enumeration_text(EVENT_KIND_CODES)
        variables = [
            real_parameter("inertia", gen.inertia_kgm2, "kg.m2", "generator rotor inertia (Table 6: 1.51e8 kg mm^2)"),
            real_parameter("counter_torque", gen.counter_torque_nm, "N.m",
                           "base counter torque of the generator (Sec. 4.2: 2.54e7 N mm)"),
            real_parameter("initial_speed", speed0, "rad/s",
                           "generator speed at the start time (default: total ratio x the default rotor speed)"),
            real_parameter("initial_angle", 0.0, "rad", "generator angle at the start time"),
        ]
        for i in range(1, N_EVENT_SLOTS + 1):
            variables += [
                integer_parameter(f"event{i}.kind", slots[f"event{i}.kind"], f"load event {i}: {kinds}"),
                real_parameter(f"event{i}.start", slots[f"event{i}.start"], "s", f"load event {i}: start time"),
                real_parameter(f"event{i}.duration", slots[f"event{i}.duration"], "s",
                               f"load event {i}: duration (> 0; +inf allowed for a permanent torque_step)"),
                real_parameter(f"event{i}.factor", slots[f"event{i}.factor"], "1",
                               f"load event {i}: torque factor (torque_step: factor x base; emergency_stop: "
                               "-|factor| x base; unused by grid_fault)"),
            ]
        variables += [
            boolean_parameter("torque_from_input", False,
                              "counter torque from the input counter_torque_input (e.g. a TorqueController) "
                              "instead of counter_torque and the load events"),
            boolean_parameter("follow_gearbox", False,
                              "for hosts that step with Jacobi (libcosim, ecos): the speed is set to the input "
                              "omega_gearbox at every communication point and the shaft torque over a step is "
                              "extrapolated from the last three step means received (with a Gearbox whose "
                              "generator_interface is inertia_own, whose omega_generator feeds omega_gearbox)"),
            real_input("shaft_torque", 0.0, "N.m", "torque of shaft 3 driving the generator (Gearbox output)"),
            real_input("omega_gearbox", speed0, "rad/s",
                       "the Gearbox's generator speed (its output omega_generator), used with follow_gearbox only"),
            real_input("counter_torque_input", 0.0, "N.m",
                       "counter torque demand, used when torque_from_input is true (held over a step)"),
            real_input("brake_torque", 0.0, "N.m",
                       "high-speed-shaft brake torque magnitude, acting against the speed (dry friction)"),
            real_output("omega", "rad/s", "generator speed", "generator_speed"),
            real_output("phi", "rad", "generator angle", "generator_angle"),
            real_output("generator_torque", "N.m", "counter torque applied at the current time (base torque and events)",
                        "generator_torque"),
        ]
        return variables

    def output_group(self, name: str) -> Hashable:
        return "motion"

    def _configure(self) -> None:
        names = (*GENERATOR_FIELDS, *(f"event{i}.{f}" for i in range(1, N_EVENT_SLOTS + 1)
                                        for f in ("kind", "start", "duration", "factor")))
        self.params = generator_from_values({n: self.value(n) for n in names}, build(self.model["generator"]))
        self._new_rotor()
        self._vr_torque = self.vr["shaft_torque"]
        self._vr_demand = self.vr["counter_torque_input"]
        self._vr_brake = self.vr["brake_torque"]
        self._from_input = bool(self.value("torque_from_input"))
        self._vr_lead = self.vr["omega_gearbox"]
        self._follow = bool(self.value("follow_gearbox"))
        self._prediction = ShaftTorquePrediction()
        self._vr_out = (self.vr["omega"], self.vr["phi"], self.vr["generator_torque"])

    def _new_rotor(self) -> None:
        with fmu_parameter_names(_NAMES):
            self.rotor = RotorComponent(self.params, self.value("initial_speed"), self.value("initial_angle"))

    def _initialize(self, start_time: float) -> None:
        self._new_rotor()
        self._prediction = ShaftTorquePrediction()

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        torque = self._values[self._vr_torque]
        if not math.isfinite(torque):
            raise SolverError(f"non-finite input shaft_torque = {torque!r}", time)
        demand = self._values[self._vr_demand] if self._from_input else None
        brake = self._values[self._vr_brake]
        if not math.isfinite(brake) or (demand is not None and not math.isfinite(demand)):
            raise SolverError(f"non-finite input (counter_torque_input={demand!r}, brake_torque={brake!r})", time)
        if self._follow:
            lead = self._values[self._vr_lead]
            if not math.isfinite(lead):
                raise SolverError(f"non-finite input omega_gearbox = {lead!r}", time)
            self.rotor.speed_rad_s = lead
            torque = self._prediction.predict(time, step_size, torque)
        self.rotor.step(time, step_size, torque, demand, brake)

    def _refresh(self, group: Hashable) -> None:
        values = self._values
        i_omega, i_phi, i_torque = self._vr_out
        values[i_omega] = self.rotor.speed_rad_s
        values[i_phi] = self.rotor.angle_rad
        values[i_torque] = (values[self._vr_demand] if self._from_input else self.rotor.counter_torque(self._time))

    def _component_state(self) -> dict:
        return {"speed_rad_s": self.rotor.speed_rad_s, "angle_rad": self.rotor.angle_rad,
                "prediction": self._prediction.get_state()}

    def _restore_component_state(self, state: dict) -> None:
        self._new_rotor()
        self.rotor.speed_rad_s = float(state["speed_rad_s"])
        self.rotor.angle_rad = float(state["angle_rad"])
        self._prediction.set_state(state["prediction"])
