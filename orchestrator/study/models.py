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
    units : callable() -> dict of str -> str
        Every parameter's SI unit (``"1/m"``, ``"N/m^e"``, ``"1"``): a value with another unit is converted to it.
    """

    name: str
    description: str
    defaults: Callable[[], dict[str, float]]
    build: Callable[[Mapping[str, Any]], tuple[Any, Any]]
    start: str = "operating_point"
    units: Callable[[], dict[str, str]] = dict

    def exponent(self, name: str) -> float | None:
        """The default exponent ``e`` of a parameter whose unit has it (``gearbox.stage1.k0`` in N/m^e), else None."""
        from components.model.parameter_map import unit_exponent_parameter

        comp, _, flat = name.partition(".")
        other = unit_exponent_parameter(flat)
        return self.defaults().get(f"{comp}.{other}") if other else None

    def plausibility(self, base: Mapping[str, Any], allow: tuple[str, ...]):
        """``problem(point values) -> (parameter, value, expectation) or None``: the model's values judged by physics.

        The drivetrain with the point's values against the model as the study's base defines it
        (:func:`components.analysis.plausibility.implausible`: a failure the point introduces), and the
        input speed and output torque against that base's rating. A point the model refuses is not judged
        here (it fails when it runs).
        """
        from components.analysis.plausibility import Rating, implausible, judge, judge_operation
        from components.errors import ParameterError

        prefix = MODEL_COMPONENT + "."
        drivetrain, driver = self.build(dict(base))
        rating = Rating.of(drivetrain, driver.speed(0.0))
        built = judge(drivetrain, rating)
        own = [k[len(prefix):] for k in allow if k.startswith(prefix)]

        def problem(values: Mapping[str, Any]):
            try:
                dt, drv = self.build({**base, **values})
            except ParameterError:
                return None
            given = [k[len(prefix):] for k, v in values.items() if k.startswith(prefix) and base.get(k) != v]
            bad = [(prefix + j.key, j) for j in implausible(judge(dt, rating), own, built, given)]
            bad += [(j.key, j) for j in implausible(judge_operation(rating, {_SPEED: drv.speed(0.0)},
                                                                    {f"{prefix}output_torque": dt.output_torque_nm}),
                                                    allow)]
            if not bad:
                return None
            name, j = bad[0]
            return (name, values.get(name, f"{j.value:.6g} (as the model builds it)"),
                    f'{j.expected}; it is {j.in_si} in SI; a deliberate value is kept by [plausibility] '
                    f'allow = ["{name}"] in the study or --allow-implausible {name}')

        return problem


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


def _variant_units() -> dict[str, str]:
    from components.model.parameter_map import unit_of_parameter

    prefix = MODEL_COMPONENT + "."
    return {name: ("1" if name == _R1 else "rad/s" if name == _SPEED else unit_of_parameter(name[len(prefix):]))
            for name in _variant_defaults()}


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
        units=_variant_units,
    ),
}
