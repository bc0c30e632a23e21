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
   (:mod:`components.model.parameter_map`), so coupled constraints
   (``f_max > f_min``, a kinematically consistent geometry) are found too.

:func:`value_problem` is used per value by :func:`orchestrator.cosim.system.resolve_system`
(scenarios, SSPs, ``--set``, study points), :func:`model_problem` once the system is resolved.
"""

from __future__ import annotations

import math
from typing import Any

from components.errors import ParameterError
from components.validation import INT32_MAX, INT32_MIN, Bounds

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


def model_problem(system) -> tuple[str, Any, str] | None:
    """``(scenario key, value, expectation)`` of the first dtcosim model that rejects the values, else None.

    Builds each dtcosim component's parameter set from its record and the
    effective parameter values (:mod:`orchestrator.cosim.physics_view`), exactly as
    the FMU does at initialisation. Foreign FMUs are skipped.
    """
    from .physics_view import (
        PhysicsUnavailable,
        gearbox_drivetrain,
        generator_parameters,
        wind_parameters,
    )
    from .roles import GEARBOX, GENERATOR, WIND_SOURCE

    builders = {GEARBOX: gearbox_drivetrain, WIND_SOURCE: wind_parameters, GENERATOR: generator_parameters}
    for name, role in system.roles.items():
        if role.record is None or role.role not in builders:
            continue
        try:
            builders[role.role](system, name)
        except PhysicsUnavailable as exc:
            cause = exc.__context__
            if not isinstance(cause, ParameterError):
                continue
            variables = system.interfaces[name].variables
            key = f"components.{name}.parameters"
            if cause.name in variables:
                key += f".{cause.name}"
            return key, cause.value, cause.expected
    return None
