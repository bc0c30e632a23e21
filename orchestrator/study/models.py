"""Built-in monolithic models a study can start from instead of a co-simulation scenario.

The three FMUs always form the Sec. 4.2 drivetrain (a generator rotor behind
shaft 3). The paper's sensitivity analysis (Sec. 4.1) has no generator: a
1 kN m counter torque acts directly on the output gear, the input turns at a
constant 5 rpm and the stage-1 ratio R1 is a real number that changes the
geometry of two stages. That system is a built-in model here, run with the
monolithic solver (:mod:`components.reference.solver`).

``sensitivity-variant``
    :func:`components.model.presets.sensitivity_variant`: the Table 6 gearbox with
    R1 in [6, 10], R2 = 100 / (1.25 R1), stage-2 masses and inertias x 10 / R1,
    no generator, counter torque on the output gear. Parameters:

    * ``gearbox.R1`` [-]: stage-1 ratio (default 10);
    * ``gearbox.<name>``: any flat drivetrain parameter of
      :mod:`components.model.parameter_map` (SI), applied after the variant is built,
      e.g. ``gearbox.stage1.lambda`` [1/m], ``gearbox.output_torque`` [N m]
      (default 1000), ``gearbox.shaft2.stiffness`` [N m/rad];
    * ``input.speed`` [rad/s]: constant input (stage-1 carrier) speed, default 5 rpm.

    Result variables for measures: ``gearbox.<series>`` with the series names of
    :func:`components.reference.solver.simulate_monolithic` (``gearbox.stage3.F_mesh``,
    ``gearbox.omega_out``, ``gearbox.alpha_out``, ...).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

from components import units

#: the component name result variables of a built-in model are given under
MODEL_COMPONENT = "gearbox"


@dataclass(frozen=True)
class BuiltinModel:
    """A named monolithic model with flat, named parameters.

    Attributes
    ----------
    name : str
    description : str
    defaults : callable() -> dict of str -> float
        Every parameter name (``component.parameter``) with its default value.
    build : callable(mapping) -> (Drivetrain, SpeedDriver)
        The model for given parameter values (defaults for the missing ones);
        raises :class:`~components.errors.ParameterError` for a bad value.
    start : {"operating_point", "rest"}
        Where its runs start (:func:`components.reference.solver.simulate_monolithic`).
    """

    name: str
    description: str
    defaults: Callable[[], dict[str, float]]
    build: Callable[[Mapping[str, Any]], tuple[Any, Any]]
    start: str = "operating_point"


_R1 = "gearbox.R1"
_SPEED = "input.speed"
_DEFAULT_R1 = 10.0
_DEFAULT_SPEED = units.rpm(5.0)
#: regularisation the variant is built with before the flat overrides (Table 6)
_BUILD_LAMBDA_PER_MM = 600.0


def _variant_defaults() -> dict[str, float]:
    from components.model.parameter_map import flatten
    from components.model.presets import sensitivity_variant

    out = {_R1: _DEFAULT_R1, _SPEED: _DEFAULT_SPEED}
    out.update({f"{MODEL_COMPONENT}.{k}": v for k, v in flatten(sensitivity_variant(_DEFAULT_R1, _BUILD_LAMBDA_PER_MM)).items()})
    return out


def _variant_build(values: Mapping[str, Any]):
    from components.model.parameter_map import unflatten
    from components.model.presets import sensitivity_variant
    from components.model.wind import ConstantSpeed

    r1 = values.get(_R1, _DEFAULT_R1)
    drivetrain = sensitivity_variant(r1, _BUILD_LAMBDA_PER_MM)
    prefix = MODEL_COMPONENT + "."
    flat = {k[len(prefix):]: v for k, v in values.items() if k.startswith(prefix) and k != _R1}
    if flat:
        drivetrain = unflatten(drivetrain, flat)
    driver = ConstantSpeed(values.get(_SPEED, _DEFAULT_SPEED))
    return drivetrain, driver


MODELS: dict[str, BuiltinModel] = {
    "sensitivity-variant": BuiltinModel(
        name="sensitivity-variant",
        description="Sec. 4.1 gearbox variant: R1 in [6, 10], R2 = 100 / (1.25 R1), stage-2 masses x 10 / R1, "
                    "counter torque on the output gear, constant input speed, no generator",
        defaults=_variant_defaults,
        build=_variant_build,
        start="rest",  # Sec. 4.1: the counter torque a step at t = 0 (eq. 11 measures the start-up impact)
    ),
}
