"""GeneratorRotor FMU: generator inertia with counter torque and load events (:mod:`components.model.generator`).

Input ``shaft_torque`` [N m] (shaft 3, from the Gearbox FMU), held over a step;
the rotor is integrated exactly. Parameters: ``inertia``, ``counter_torque``,
``initial_speed``, ``initial_angle`` and four load-event slots
``event{i}.kind/start/duration/factor`` (kind 0 = none). Outputs ``omega``,
``phi`` and the counter torque currently applied, ``generator_torque``.
"""

from __future__ import annotations

import math
from typing import Hashable, Iterable

from components.errors import ParameterError, SolverError
from components.model.generator import EVENT_KINDS, GeneratorParameters, LoadEvent
from components.model.generator import GeneratorRotor as RotorComponent
from components.model.presets import cosim_preset
from components.model.wind import WindParameters

from .base import DtcosimSlave, fmu_parameter_names
from .interface import (
    Variable,
    enumeration_text,
    integer_parameter,
    real_input,
    real_output,
    real_parameter,
)

#: number of load-event slots
N_EVENT_SLOTS = 4
EVENT_KIND_CODES = ("none",) + EVENT_KINDS

_NAMES = {
    "generator.inertia_kgm2": "inertia",
    "generator.counter_torque_nm": "counter_torque",
    "generator.initial_speed": "initial_speed",
    "generator.initial_angle": "initial_angle",
}


class GeneratorRotor(DtcosimSlave):
    """Generator rotor ``I omega_dot = T_shaft - T_gen(t)`` as an FMU."""

    description = ("dtcosim GeneratorRotor: generator inertia driven by the shaft-3 torque against a counter "
                   "torque with load events (SI units)")
    eager_output_groups = frozenset({"motion"})

    @classmethod
    def build_interface(cls) -> Iterable[Variable]:
        gen = cosim_preset(cls.preset).generator
        speed0 = cosim_preset(cls.preset).ratio * WindParameters().mean_speed_rad_s
        kinds = enumeration_text(EVENT_KIND_CODES)
        variables = [
            real_parameter("inertia", gen.inertia_kgm2, "kg.m2", "generator rotor inertia (Table 6: 1.51e8 kg mm^2)"),
            real_parameter("counter_torque", gen.counter_torque_nm, "N.m",
                           "base counter torque of the generator (Sec. 4.2: 2.54e7 N mm)"),
            real_parameter("initial_speed", speed0, "rad/s",
                           "generator speed at the start time (default: total ratio x 16 rpm)"),
            real_parameter("initial_angle", 0.0, "rad", "generator angle at the start time"),
        ]
        for i in range(1, N_EVENT_SLOTS + 1):
            variables += [
                integer_parameter(f"event{i}.kind", 0, f"load event {i}: {kinds}"),
                real_parameter(f"event{i}.start", 0.0, "s", f"load event {i}: start time"),
                real_parameter(f"event{i}.duration", 1.0, "s",
                               f"load event {i}: duration (> 0; +inf allowed for a permanent torque_step)"),
                real_parameter(f"event{i}.factor", 1.0, "1",
                               f"load event {i}: torque factor (torque_step: factor x base; emergency_stop: "
                               "-|factor| x base; unused by grid_fault)"),
            ]
        variables += [
            real_input("shaft_torque", 0.0, "N.m", "torque of shaft 3 driving the generator (Gearbox output)"),
            real_output("omega", "rad/s", "generator speed"),
            real_output("phi", "rad", "generator angle"),
            real_output("generator_torque", "N.m", "counter torque applied at the current time (base torque and events)"),
        ]
        return variables

    def output_group(self, name: str) -> Hashable:
        return "motion"

    def _events(self) -> tuple[LoadEvent, ...]:
        events = []
        for i in range(1, N_EVENT_SLOTS + 1):
            code = self.value(f"event{i}.kind")
            if not 0 <= code < len(EVENT_KIND_CODES):
                raise ParameterError(f"event{i}.kind", code, enumeration_text(EVENT_KIND_CODES))
            if code == 0:
                continue
            names = {f"event.{f}": f"event{i}.{g}" for f, g in
                     (("kind", "kind"), ("start_s", "start"), ("duration_s", "duration"), ("factor", "factor"))}
            with fmu_parameter_names(names):
                events.append(LoadEvent(
                    kind=EVENT_KIND_CODES[code],
                    start_s=self.value(f"event{i}.start"),
                    duration_s=self.value(f"event{i}.duration"),
                    factor=self.value(f"event{i}.factor"),
                ))
        return tuple(events)

    def _configure(self) -> None:
        events = self._events()
        with fmu_parameter_names(_NAMES):
            self.params = GeneratorParameters(
                inertia_kgm2=self.value("inertia"),
                counter_torque_nm=self.value("counter_torque"),
                events=events,
            )
            self._new_rotor()
        self._vr_torque = self.vr["shaft_torque"]
        self._vr_out = (self.vr["omega"], self.vr["phi"], self.vr["generator_torque"])

    def _new_rotor(self) -> None:
        with fmu_parameter_names(_NAMES):
            self.rotor = RotorComponent(self.params, self.value("initial_speed"), self.value("initial_angle"))

    def _initialize(self, start_time: float) -> None:
        self._new_rotor()

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        torque = self._values[self._vr_torque]
        if not math.isfinite(torque):
            raise SolverError(f"non-finite input shaft_torque = {torque!r}", time)
        self.rotor.step(time, step_size, torque)

    def _refresh(self, group: Hashable) -> None:
        values = self._values
        i_omega, i_phi, i_torque = self._vr_out
        values[i_omega] = self.rotor.speed_rad_s
        values[i_phi] = self.rotor.angle_rad
        values[i_torque] = self.rotor.counter_torque(self._time)

    def _component_state(self) -> dict:
        return {"speed_rad_s": self.rotor.speed_rad_s, "angle_rad": self.rotor.angle_rad}

    def _restore_component_state(self, state: dict) -> None:
        self._new_rotor()
        self.rotor.speed_rad_s = float(state["speed_rad_s"])
        self.rotor.angle_rad = float(state["angle_rad"])
