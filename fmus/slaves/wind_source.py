"""WindSource FMU: the rotor-speed process of eq. 13-14 (:mod:`components.model.wind`).

Parameters (SI, paper defaults): ``omega0``, ``a``, ``sigma``, ``n_harmonics``,
``f_min``, ``f_max``, ``seed``, ``amplitude`` (0 = variance-preserving
``W_k = sqrt(2 S df)``, 1 = the paper's literal ``W_k = S df``).
Outputs: rotor speed ``omega`` [rad/s] and angle ``phi`` [rad] (``phi(0) = 0``)
at the current communication point. The signal is a closed-form function of
time; the FMU steps it by rotating the harmonics' phasors
(:class:`components.model.wind.PhasorStepper`, re-anchored on the closed form
periodically; one compiled loop where numba imports, else numpy, said once through
the FMI logger), whose state the FMU state carries.
"""

from __future__ import annotations

from typing import Any, Hashable, Iterable, Mapping

from pythonfmu.enums import Fmi2Status

from components.errors import ParameterError
from components.model.description import build
from components.model.parameter_map import WIND_FIELDS, wind_from_values
from components.model.wind import (
    AMPLITUDE_CONVENTIONS,
    MAX_HARMONICS,
    PhasorStepper,
    RotorSpeedProcess,
)

from .base import DtcosimSlave
from .interface import (
    Variable,
    enumeration_text,
    integer_parameter,
    real_output,
    real_parameter,
)


class WindSource(DtcosimSlave):
    """Stochastic rotor speed (eq. 13-14) as an FMU with outputs ``omega`` and ``phi``."""

    description = "dtcosim WindSource: stochastic rotor speed omega(t) and angle phi(t) of eq. 13-14 (SI units)"
    eager_output_groups = frozenset({"motion", "derivatives"})  # read every step by the Gearbox (rotor_derivatives)
    _kernel_reported = False

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        d = build(model["wind"], "model.wind")
        amplitude = enumeration_text(AMPLITUDE_CONVENTIONS)
        return (
            real_parameter("omega0", d.mean_speed_rad_s, "rad/s", "mean rotor speed omega0 (eq. 13; paper: 16 rpm)"),
            real_parameter("a", d.spectrum_level, "rad/s",
                           "spectral level a of S(f) = a exp(-a f / sigma^2) (eq. 14; paper: 0.02 in rpm units)"),
            real_parameter("sigma", d.sigma_rad_s, "rad/s", "fluctuation intensity sigma (eq. 14; paper: 0.12 rpm)"),
            integer_parameter("n_harmonics", d.n_harmonics, f"number of harmonics N (1 to {MAX_HARMONICS})"),
            real_parameter("f_min", d.f_min_rad_s, "rad/s", "lowest angular frequency of the harmonics"),
            real_parameter("f_max", d.f_max_rad_s, "rad/s", "highest angular frequency of the harmonics"),
            integer_parameter("seed", d.seed, "seed of the random phases (numpy default_rng, 0 to 2147483647)"),
            integer_parameter("amplitude", AMPLITUDE_CONVENTIONS.index(d.amplitude),
                              f"amplitude convention: {amplitude} (W_k = sqrt(2 S df) or the paper's S df)"),
            real_output("omega", "rad/s", "rotor speed omega(t) (eq. 13)", "rotor_speed"),
            real_output("phi", "rad", "rotor angle phi(t), the integral of omega from t = 0", "rotor_angle"),
            real_output("alpha", "rad/s2", "rotor acceleration d omega / dt (exact, from the same harmonics)",
                        "rotor_acceleration"),
            real_output("jerk", "rad/s3", "rotor jerk d^2 omega / dt^2 (exact; with alpha, the Gearbox's "
                        "rotor_derivatives extrapolation)", "rotor_jerk"),
        )

    def output_group(self, name: str) -> Hashable:
        return "derivatives" if name in ("alpha", "jerk") else "motion"

    def _configure(self) -> None:
        values = {name: self.value(name) for name in (*WIND_FIELDS, "amplitude")}
        self.process = RotorSpeedProcess(wind_from_values(values, build(self.model["wind"], "model.wind")))
        self.stepper = PhasorStepper(self.process)
        if self.stepper.kernel_note and not self._kernel_reported:  # once per instance: why it is slower
            self._report(f"WindSource: {self.stepper.kernel_note}", Fmi2Status.warning)
            self._kernel_reported = True
        self._vr_omega = self.vr["omega"]
        self._vr_phi = self.vr["phi"]
        self._vr_derivatives = (self.vr["alpha"], self.vr["jerk"])

    def _initialize(self, start_time: float) -> None:
        self.stepper.reset(start_time)

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        self.stepper.advance(time, step_size)

    def _refresh(self, group: Hashable) -> None:
        stepper = self.stepper
        if stepper.time_s != self._time:  # e.g. outputs read in initialisation mode at another start time
            stepper.reset(self._time)
        if group == "derivatives":
            i_alpha, i_jerk = self._vr_derivatives
            self._values[i_alpha], self._values[i_jerk] = stepper.acceleration_and_jerk()
        else:
            self._values[self._vr_omega], self._values[self._vr_phi] = stepper.speed_and_angle()

    def _component_state(self) -> dict:
        return self.stepper.get_state()

    def _restore_component_state(self, state: dict) -> None:
        if state:  # an empty dict: a state of the closed-form FMU (before the phasor stepper)
            self.stepper.set_state(state)
