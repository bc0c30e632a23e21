"""Parameter values given with their unit, converted to the unit each FMU declares for the variable.

A scenario's ``[components.X.parameters]``, ``--set``, an SSP's values and a study's points may
give a Real parameter as a quantity text (``"0.56 mm"``, ``"25.4 kN m"``, ``"16 rpm"``). What it
must be converted to is the variable's declaration in ``modelDescription.xml``: its ``unit`` and
that unit's ``BaseUnit`` (SI exponents, factor, offset), never the parameter's name. A unit with
the exponent ``e`` (a contact stiffness in ``N/m^e``) takes ``e`` from the parameter the FMU's
record names for it (``unit_exponents``: ``"stage1.k0": "stage1.exponent"``), at its value in
this scenario (given, or the FMU's start value). The conversion itself is
:func:`orchestrator.inputs.quantities.to_declared` (the one unit registry).
"""

from __future__ import annotations

from typing import Any, Mapping

from ..inputs.origins import origin_of
from ..inputs.quantities import UnitError, is_quantity_text, to_declared
from .fmu_interface import FmuInterface, FmuVariable


def exponent_of(iface: FmuInterface, var: FmuVariable, values: Mapping[str, Any]) -> float | None:
    """The ``e`` of ``var``'s unit: the value of the parameter the record names for it (None if none)."""
    name = ((iface.record or {}).get("unit_exponents") or {}).get(var.name)
    if not name or name not in iface.variables:
        return None
    value = values.get(name, iface.variables[name].start)
    if isinstance(value, str) and is_quantity_text(value):
        value = to_declared(value, iface.variables[name].unit, iface.unit_definitions.get(iface.variables[name].unit))
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def declared_value(iface: FmuInterface, var: FmuVariable, value: Any, values: Mapping[str, Any]) -> Any:
    """``value`` in ``var``'s declared unit if it is a quantity text for a Real, else ``value`` unchanged.

    Raises
    ------
    UnitError
        A unit of another dimension than the declared one (its message names both).
    """
    if var.type != "Real" or not is_quantity_text(value):
        return value
    return to_declared(value, var.unit, iface.unit_definitions.get(var.unit), exponent_of(iface, var, values))


def quantities_as_values(scenario, interfaces: Mapping[str, FmuInterface]):
    """The scenario with every quantity text of a Real parameter as a number in the FMU's declared unit.

    Raises
    ------
    EntryError
        Naming where the value was given (:mod:`orchestrator.inputs.origins`),
        ``components.<name>.parameters.<parameter>``, the value, the declared unit and dimension.
    """
    for comp in scenario.components:
        iface = interfaces[comp.name]
        changed = {}
        for pname, value in comp.parameters.items():
            var = iface.variables.get(pname)
            if var is None:
                continue  # an unknown name: the caller's check names it
            try:
                new = declared_value(iface, var, value, comp.parameters)
            except UnitError as exc:
                raise origin_of(scenario, comp.name, pname).refusal(
                    f"components.{comp.name}.parameters.{pname}", value,
                    f"{exc.expected} ({pname} is declared in {var.unit or '1'} by {iface.path.name})") from None
            if new is not value:
                changed[pname] = new
        if changed:
            scenario = scenario.with_parameters(comp.name, **changed)
    return scenario
