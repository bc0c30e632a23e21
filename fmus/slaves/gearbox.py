"""Gearbox FMU: the gearbox side of the co-simulation cut (:class:`components.model.gearbox_model.GearboxModel`).

Inputs ``omega_rotor``, ``phi_rotor`` (kinematic driver of the stage-1 carrier)
and ``omega_gen``, ``phi_gen`` (far end of shaft 3). Outputs: ``shaft_torque``
(shaft 3 on the generator; step average or end value per the parameter
``shaft_torque_mode``), ``shaft_torque_end``, ``shaft_torque_avg``,
``omega_out``, ``torque_rotor``, every contact force (``stage1.F_sp[1]``,
``stage1.F_rp[1]``, ..., ``stage3.F_mesh``), every shaft torque
(``shaft1.torque``, ...), every body speed (``stage1.sun.omega``, ...), with
lateral-torsional stages every displacement and bearing output (``stage1.sun.x``,
``stage1.planet_bearing[1].F``, ...; :func:`components.model.signals.gearbox_signals`), the
output member's acceleration ``alpha_out`` (averaged over the last step) and
its running peak magnitude ``alpha_out_max`` (eq. 11, over every internal
solver step).

The structure (stages, planets, shafts) is the drivetrain of the FMU's record
(``resources/dtcosim.json``, fixed at build time); every number is a parameter (see :mod:`fmus.slaves.gearbox_parameters`).
Before the first step (initialisation mode) the outputs describe the
kinematically consistent initial state at the current inputs, e.g.
``omega_out = ratio * omega_rotor``: the static deflection of the ``counter_torque``
input (unless ``start_at_rest``), so constant inputs give constant outputs from the start.
"""

from __future__ import annotations

from dataclasses import replace
from operator import itemgetter
from typing import Any, Hashable, Iterable, Mapping

from pythonfmu.enums import Fmi2Status

from components.errors import ParameterError
from components.model.assembly import Assembly
from components.model.description import build
from components.model.drivetrain import Drivetrain
from components.model.gearbox_model import GENERATOR_INTERFACES, SHAFT_TORQUE_MODES, STEP_INPUTS, GearboxModel
from components.model.integrators import StepControl
from components.model.signals import gearbox_signals
from components.validation import choice_bounds, positive

from .base import DtcosimSlave
from .gearbox_parameters import (
    control_from_values,
    drivetrain_from_values,
    drivetrain_variables,
    solver_variables,
)
from .interface import (
    Variable,
    boolean_parameter,
    enumeration_text,
    integer_parameter,
    real_input,
    real_output,
    real_parameter,
)

# all outputs form one group: computed in one vectorised pass (GearboxModel.output_vector)
# at most once per step, when the first output is read
_OUTPUTS = "outputs"


def template_of(model: Mapping[str, Any]) -> Drivetrain:
    """The drivetrain of a Gearbox record's model (structure and default values)."""
    return build(model["drivetrain"], "model.drivetrain")


class Gearbox(DtcosimSlave):
    """Multi-stage gearbox with CFS gear contact and shaft 3, cut at the generator, as an FMU."""

    description = ("dtcosim Gearbox: multi-stage planetary/parallel gearbox with CFS (or impact) gear contact "
                   "and shaft 3, driven by the rotor motion and cut at the generator (SI units)")
    eager_output_groups = frozenset({_OUTPUTS})  # shaft_torque is read every step

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        template = template_of(model)
        assembly = Assembly(template, cut_at_generator=True)
        omega0 = float(model["rotor_speed_rad_s"])
        ratio = float(assembly.port_ratio[0])
        variables = drivetrain_variables(template)
        variables += solver_variables(StepControl())
        variables += [
            integer_parameter("shaft_torque_mode", 0,
                              f"value reported as shaft_torque: {enumeration_text(SHAFT_TORQUE_MODES)} "
                              "(average over the last step conserves the exchanged impulse)"),
            boolean_parameter("extrapolate_inputs", True,
                              "extrapolate the input speeds over a step with the slope of the last two inputs "
                              "(false: hold them)"),
            integer_parameter("generator_interface", 0,
                              f"how the generator end of shaft 3 moves within a step: "
                              f"{enumeration_text(GENERATOR_INTERFACES)} (motion: along the generator-motion "
                              "inputs; inertia: an interface model, the generator inertia generator_inertia "
                              "integrated in the step against the input counter_torque, its speed set to "
                              "omega_gen at every communication point; inertia_own: the same, its speed set to "
                              "its own impulse balance instead (omega_gen unused), for hosts that step with "
                              "Jacobi, with a generator that follows omega_generator)"),
            real_parameter("generator_inertia", template.generator.inertia_kgm2, "kg.m2",
                           "generator rotor inertia of the inertia interface (the generator component's)"),
            boolean_parameter("rotor_derivatives", False,
                              "extrapolate the rotor motion over a step from the inputs alpha_rotor and jerk_rotor "
                              "(third-order Taylor) instead of the slope of the last two speed inputs"),
            boolean_parameter("start_at_rest", False,
                              "start undeflected at full load, the load a step at the start time (false: at the "
                              "static deflection of the counter_torque input at the initial speeds, so constant "
                              "inputs give constant outputs from the start)"),
            real_input("omega_rotor", omega0, "rad/s", "rotor speed driving the stage-1 carrier"),
            real_input("phi_rotor", 0.0, "rad", "rotor angle"),
            real_input("omega_gen", ratio * omega0, "rad/s", "generator speed (far end of shaft 3)"),
            real_input("phi_gen", 0.0, "rad", "generator angle (far end of shaft 3; not used by the inertia interface)"),
            real_input("counter_torque", template.generator.counter_torque_nm, "N.m",
                       "counter torque on the generator rotor: the load of the static deflection at the start, and "
                       "held over a step with the inertia interface"),
            real_input("alpha_rotor", 0.0, "rad/s2", "rotor acceleration (with rotor_derivatives only)"),
            real_input("jerk_rotor", 0.0, "rad/s3", "rotor jerk (with rotor_derivatives only)"),
            real_output("shaft_torque", "N.m",
                        "torque of shaft 3 on the generator, per shaft_torque_mode (default: step average)",
                        "generator_shaft_torque"),
            # the outputs in GearboxModel.output_names's order: one slice assignment per refresh, no reordering
            real_output("shaft_torque_avg", "N.m", "torque of shaft 3 on the generator averaged over the last step",
                        "generator_shaft_torque"),
            real_output("shaft_torque_end", "N.m", "torque of shaft 3 on the generator at the end of the last step",
                        "generator_shaft_torque"),
            real_output("omega_out", "rad/s", f"speed of the output member {assembly.stage_members[template.stages[-1].name]['output']}",
                        "output_speed"),
            real_output("torque_rotor", "N.m", "torque the rotor applies to the gearbox (for the power balance)",
                        "rotor_torque"),
        ]
        # every contact force, shaft torque, body speed and bearing output, as the monolithic reference declares
        variables += [real_output(name, s.unit, s.description, s.kind, **dict(s.info))
                      for name, s in gearbox_signals(assembly).items()]
        out_member = assembly.stage_members[template.stages[-1].name]["output"]
        variables += [  # after the body speeds: the same order as GearboxModel.output_names
            real_output("alpha_out", "rad/s2",
                        f"angular acceleration of the output member {out_member}, averaged over the last step"),
            real_output("alpha_out_max", "rad/s2",
                        "largest |d omega_out/dt| since initialisation over every internal solver step "
                        "(paper eq. 11; resolves tooth impacts shorter than the communication step)",
                        "output_acceleration_peak"),
            real_output("omega_generator", "rad/s",
                        "generator speed of the interface model: the speed the next step starts from "
                        "(inertia_own), the generator's impulse balance over the last step (inertia), the "
                        "extrapolated omega_gen (motion)"),
        ]
        return variables

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        self._template = template_of(self.model)
        vr = self.vr
        self._vr_inputs = tuple(vr[n] for n in STEP_INPUTS)  # in GearboxModel.step's order
        self._inputs = itemgetter(*self._vr_inputs)  # values list -> the inputs, in one C call
        names = GearboxModel(self._template).output_names
        self._vr_outputs = [vr[n] for n in names]
        # the outputs occupy one range of value references in the model's order (build_interface): one slice
        # assignment per refresh; an interface in another order is reordered (itemgetter: one C call)
        first, n = min(self._vr_outputs), len(names)
        contiguous = sorted(self._vr_outputs) == list(range(first, first + n))
        self._output_slice = slice(first, first + n) if contiguous else None
        order = [self._vr_outputs.index(first + j) for j in range(n)] if contiguous else []
        self._output_order = itemgetter(*order) if n > 1 and order != list(range(n)) else None
        self.model: GearboxModel | None = None
        self._kernel_reported = False
        self._start_inputs = None

    def output_group(self, name: str) -> Hashable:
        return _OUTPUTS

    # ------------------------------------------------------------------ hooks
    def _configure(self) -> None:
        mode = self.value("shaft_torque_mode")
        if not 0 <= mode < len(SHAFT_TORQUE_MODES):
            text = enumeration_text(SHAFT_TORQUE_MODES)
            raise ParameterError("shaft_torque_mode", mode, text, choice_bounds(SHAFT_TORQUE_MODES, text))
        interface = self.value("generator_interface")
        if not 0 <= interface < len(GENERATOR_INTERFACES):
            text = enumeration_text(GENERATOR_INTERFACES)
            raise ParameterError("generator_interface", interface, text, choice_bounds(GENERATOR_INTERFACES, text))
        drivetrain = drivetrain_from_values(self._template, self.value)
        inertia = positive("generator_inertia", self.value("generator_inertia"))
        drivetrain = replace(drivetrain, generator=replace(drivetrain.generator, inertia_kgm2=inertia))
        control = control_from_values(self.value)
        self.model = GearboxModel(drivetrain, control, SHAFT_TORQUE_MODES[mode], bool(self.value("extrapolate_inputs")),
                                  generator_interface=GENERATOR_INTERFACES[interface],
                                  rotor_derivatives=bool(self.value("rotor_derivatives")),
                                  start="rest" if self.value("start_at_rest") else "operating_point")
        if self.model.kernel_note and not self._kernel_reported:  # once per instance: the host sees why it is slower
            self._report(f"Gearbox: {self.model.kernel_note}", Fmi2Status.warning)
            self._kernel_reported = True

    def _initialize(self, start_time: float) -> None:
        values = self._values
        inputs = [values[i] for i in self._vr_inputs[:5]]
        self.model.initialize(start_time, *inputs)
        self._start_inputs: tuple[float, list[float]] | None = (start_time, inputs)

    def _step(self, time: float, step_size: float) -> None:
        if self._start_inputs is not None:
            self._check_input_timing(time, step_size)
        self.model.step(time, step_size, *self._inputs(self._values))

    def _check_input_timing(self, time: float, step_size: float) -> None:
        """Warn once if the first step's angles are not the initial ones: a source stepped before the Gearbox.

        The Gearbox takes its inputs as the values at the communication point ``t_n`` (FMI 2.0) and
        extrapolates them over the step. A source stepped first (Gauss-Seidel) hands over its values at
        ``t_n + h``: its angle leads by one step, ``omega h`` at the carrier, times the gear ratio at the
        generator - a shaft twist that rings through the drivetrain at the start.
        """
        t0, initial = self._start_inputs
        self._start_inputs = None
        if time != t0:
            return
        values = self._values
        checked = [("phi_rotor", 1, 0)]
        if self.model.generator_interface == "motion":
            checked.append(("phi_gen", 3, 2))
        for name, k, speed_k in checked:
            moved = values[self._vr_inputs[k]] - initial[k]
            per_step = abs(initial[speed_k]) * step_size
            if per_step > 0.0 and abs(moved) > 0.5 * per_step:
                self._report(
                    f"Gearbox: {name} moved by {moved:.4g} rad between initialisation and the first step at "
                    f"t = {time:g} s ({moved / per_step:.2g} steps of its speed): its source was stepped before the "
                    f"Gearbox. The Gearbox takes inputs as values at the communication point (FMI 2.0), so the "
                    f"motion it is given leads by one step ({per_step:.3g} rad; x the gear ratio at the generator): "
                    f"the extra twist rings through the drivetrain. Step the Gearbox before the components that "
                    f"drive it (simulation.order with the gearbox first)", Fmi2Status.warning)

    def _refresh(self, group: Hashable) -> None:
        out = self.model.output_list()  # the compiled model: its kernel wrote them during the step
        if self._output_slice is not None:
            self._values[self._output_slice] = out if self._output_order is None else self._output_order(out)
        else:
            values = self._values
            for vr, value in zip(self._vr_outputs, out):
                values[vr] = value

    def _component_state(self) -> dict:
        return self.model.get_state()

    def _restore_component_state(self, state: dict) -> None:
        self.model.set_state(state)
