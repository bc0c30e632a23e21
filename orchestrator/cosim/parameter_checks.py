"""Parameter values checked against what the FMUs accept, before anything is instantiated.

Three layers, each with the message the FMU itself would give:

1. FMI types: an Integer is 32 bits (``fmi2Integer`` is a C int), so a larger
   value would silently wrap on its way into the FMU (a seed 4294967297 would
   become 1); it is refused instead (:data:`INT32_MIN`, :data:`INT32_MAX`).
2. Declared bounds: a dtcosim FMU's record carries the bounds of its parameters,
   probed from the slave's own validation at build time (``bounds``;
   :class:`components.validation.Bounds`), so the check gives the FMU's own
   expectation (``"> 0 (within [1e-30, 1e+30])"``); any other FMU's
   ``min``/``max`` attributes are checked the same way.
3. The model: for a dtcosim FMU the parameter set is built from its record and
   the values, with the same functions the slave uses at initialisation
   (:mod:`components.model.parameter_map`, ``rotor_from_values``,
   ``controller_from_values``), so coupled constraints (``f_max > f_min``, a
   kinematically consistent geometry, the torque law's region order) are found
   too; a TimeSeriesSource with ``out_of_record = 1`` (error) must cover the run
   with its effective ``time_offset`` (:func:`record_coverage`).

:func:`value_problem` is used per value by :func:`orchestrator.cosim.system.resolve_system`
(scenarios, SSPs, ``--set``, study points), :func:`model_problem` once the system is resolved.
"""

from __future__ import annotations

import math
from typing import Any

from components.errors import ParameterError
from components.validation import INT32_MAX, INT32_MIN, Bounds, is_number

from ..errors import EntryError, ScenarioError
from ..inputs.origins import responsible
from .fmu_interface import FmuInterface, FmuVariable

INTEGER_TYPES = ("Integer", "Enumeration")
INTEGER_RANGE = f"an FMI Integer within [{INT32_MIN}, {INT32_MAX}] (32 bits)"


def declared_bounds(iface: FmuInterface, var: FmuVariable) -> Bounds | None:
    """The bounds of ``var``: its FMU record's, else its ``min``/``max`` attributes (None if neither)."""
    record = iface.record or {}
    entry = (record.get("bounds") or {}).get(var.name)
    if isinstance(entry, dict):
        try:
            return Bounds.from_dict(entry)
        except (KeyError, TypeError, ValueError):
            pass
    if var.minimum is None and var.maximum is None:
        return None
    integer = var.type in INTEGER_TYPES
    low = var.minimum if var.minimum is not None else (INT32_MIN if integer else -math.inf)
    high = var.maximum if var.maximum is not None else (INT32_MAX if integer else math.inf)
    return Bounds(low, high, integer, f"within [{low:g}, {high:g}] (the FMU's declared min and max)")


def type_problem(var: FmuVariable, value: Any, name: str) -> str | None:
    """'an Integer value for NAME' if ``value`` is not of ``var``'s FMI type, else None."""
    if var.type == "Real":
        matches = is_number(value)
    elif var.type in ("Integer", "Enumeration"):
        matches = isinstance(value, int) and not isinstance(value, bool)
    elif var.type == "Boolean":
        matches = isinstance(value, bool)
    else:
        matches = isinstance(value, str)
    article = "an" if var.type[0] in "AEIOU" else "a"
    return None if matches else f"{article} {var.type} value for {name}"


def value_problem(iface: FmuInterface, var: FmuVariable, value: Any) -> str | None:
    """What ``value`` of ``var`` would have to be, or None if the FMU accepts it (as far as checkable here)."""
    if var.type in INTEGER_TYPES and isinstance(value, int) and not INT32_MIN <= value <= INT32_MAX:
        return INTEGER_RANGE
    bounds = declared_bounds(iface, var)
    if bounds is not None and not isinstance(value, (bool, str)):
        try:
            bounds.check(var.name, value)
        except ParameterError as exc:
            return exc.expected
    return None


def record_coverage(system, component: str) -> None:
    """A ParameterError for ``time_offset`` when a TimeSeriesSource that refuses to leave its record would leave it.

    The record's span is the FMU record's ``model["series"]`` (``start_s``, ``end_s``); the offset and
    the policy are the component's effective parameter values, as the FMU sees them at initialisation.
    """
    from components.model.time_series import OUT_OF_RECORD

    series = system.roles[component].record["model"]["series"]
    values = system.parameter_values(component)
    policy, offset = values.get("out_of_record"), values.get("time_offset")
    if not (isinstance(policy, int) and 0 <= policy < len(OUT_OF_RECORD)) or OUT_OF_RECORD[policy] != "error" \
            or not isinstance(offset, (int, float)) or not math.isfinite(offset):
        return  # hold, or a value the bounds check reports
    t0, t1 = float(series["start_s"]), float(series["end_s"])
    sim = system.scenario.simulation
    eps = 1e-9 * max(1.0, abs(t1))
    if not (t0 - eps <= sim.start_s + offset and sim.stop_s + offset <= t1 + eps):
        raise ParameterError("time_offset", offset, (
            f"an offset keeping the run [{sim.start_s:g}, {sim.stop_s:g}] s inside the record {series['source']} "
            f"[{t0:g}, {t1:g}] s (record time = simulation time + time_offset; or out_of_record = 0, hold)"))


def record_speed_ratio(system) -> ScenarioError | None:
    """The error for a load record whose generator/rotor speed ratio is not its drivetrain's, else None.

    A record that carries both speeds (OpenFAST's RotSpeed and GenSpeed or HSShftV) measured a drivetrain
    of that ratio; played through another (a record of another turbine), its speeds and loads run
    through the wrong gearbox without a word. The ratio is in the TimeSeriesSource's record
    (``model["series"]["speed_ratio"]``, unless the series says ``check_speed_ratio = false``); the
    drivetrain's is the scenario's dtcosim Gearbox's.
    """
    from components.model.assembly import Assembly

    from .physics_view import PhysicsUnavailable, dtcosim_component, gearbox_drivetrain
    from .roles import GEARBOX, TIME_SERIES

    sources = [(name, role.record["model"]["series"]["speed_ratio"]) for name, role in system.roles.items()
               if role.role == TIME_SERIES and role.record is not None
               and "speed_ratio" in role.record.get("model", {}).get("series", {})]
    if not sources:
        return None
    try:
        gear = dtcosim_component(system, GEARBOX).component
        drivetrain = gearbox_drivetrain(system, gear)
    except PhysicsUnavailable:
        return None
    ratio = abs(float(Assembly(drivetrain, cut_at_generator=True).port_ratio[0]))
    from ..inputs.series_spec import SPEED_RATIO_TOLERANCE

    for name, recorded in sources:
        for record, value in zip(recorded.get("records", []), recorded.get("ratios", [recorded["ratio"]])):
            if not abs(abs(value) / ratio - 1.0) <= SPEED_RATIO_TOLERANCE:
                return ScenarioError(
                    f"components.{name}.series", f"{record}: {recorded['generator']} / {recorded['rotor']} = "
                    f"{abs(value):.4g}",
                    f"the generator/rotor speed ratio of the drivetrain of {gear}, {ratio:.4g}, within "
                    f"{SPEED_RATIO_TOLERANCE:.0%} (a record of another drivetrain runs through the wrong gearbox; "
                    "check_speed_ratio = false in the series table runs it anyway)", system.scenario.source)
    return None


def model_problem(system) -> EntryError | None:
    """The error of the first dtcosim model that rejects the values (scenario key, value, expectation), else None.

    Builds each dtcosim component's parameter set from its record and the
    effective parameter values (:mod:`orchestrator.cosim.physics_view`), exactly as
    the FMU does at initialisation. Foreign FMUs are skipped. The error is named where the
    refused value was given, or for a value of the FMU's own where the last value of the
    component was (:func:`orchestrator.inputs.origins.responsible`).
    """
    from .physics_view import (
        PhysicsUnavailable,
        controller_parameters,
        gearbox_drivetrain,
        generator_parameters,
        rotor_parameters,
        wind_parameters,
    )
    from .roles import GEARBOX, GENERATOR, ROTOR, TIME_SERIES, TORQUE_CONTROLLER, WIND_SOURCE

    builders = {GEARBOX: gearbox_drivetrain, WIND_SOURCE: wind_parameters, GENERATOR: generator_parameters,
                ROTOR: rotor_parameters, TORQUE_CONTROLLER: controller_parameters, TIME_SERIES: record_coverage}
    for name, role in system.roles.items():
        if role.record is None or role.role not in builders:
            continue
        try:
            builders[role.role](system, name)
        except (PhysicsUnavailable, ParameterError) as exc:
            cause = exc if isinstance(exc, ParameterError) else exc.__context__
            if not isinstance(cause, ParameterError):
                continue
            variables = system.interfaces[name].variables
            if cause.name not in variables:  # no value of a parameter: the FMU with this scenario
                return ScenarioError(f"components.{name}.parameters", cause.value, cause.expected,
                                     system.scenario.source)
            origin, own = responsible(system.scenario, name, cause.name)
            return origin.refusal(f"components.{name}.parameters.{cause.name}", cause.value, cause.expected, own)
    return record_speed_ratio(system)
