"""A study's values in the units their parameters declare, and every point judged by physics, before any run.

Units
-----
An axis's ``unit`` is the unit its numbers are written in (``values = [2.8648, 5.7296]`` with
``unit = "kN m/rad"``); a value may also carry its own (``"5.7 kN m/rad"``, in an axis without a
``unit``, a ``[[points]]`` table or a built-in model's ``base.parameters``). Each is converted to
the unit the parameter declares - a dtcosim or foreign FMU's ``modelDescription.xml`` unit
(:mod:`orchestrator.cosim.declared_units`), a built-in model's SI unit - by the one unit registry
(:mod:`orchestrator.inputs.quantities`), before points, keys or checks exist; an incompatible unit
is an error naming the key; a converted number keeps 15 significant digits (the float's last one is
conversion noise: 2.8648 kN m/rad is 2864.8 N m/rad). Plots and the table show an axis as written. A drivetrain file entry
(``gearbox.drivetrain.stages[0].face_width``) gets its value with its unit, for the file to convert.

Plausibility
------------
Every point's values are judged by :mod:`components.analysis.plausibility` as a run would
judge them (:func:`orchestrator.cosim.plausibility_checks.plausibility_problem`; a built-in model's
drivetrain against the model as defined), with the study's ``[plausibility] allow``; the first
implausible point is an error naming where the value was given (the study's axis value or point, a
load-case set's entry: :meth:`orchestrator.inputs.study.Study.origins`), the point and the bound.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable, Mapping

from components.validation import is_number

from ..errors import EntryError
from ..inputs.origins import Origin, last_given
from ..inputs.quantities import UnitError, is_quantity_text, to_unit
from ..inputs.study import Point, Study, StudyError, split_parameter

#: ``convert(name, text) -> value``: a quantity text as the value parameter ``name`` takes
Converter = Callable[[str, str], Any]


def _text(value: Any, unit: str, key: str, source: str | None) -> str | None:
    """The quantity text of a value in ``unit`` (or with its own), None for a value without a unit."""
    if unit:
        if not is_number(value):
            raise StudyError(key, value, f"a number in the axis's unit {unit!r} (the axis names the unit; a value "
                             "with its own unit belongs in an axis without one)", source)
        return f"{value!r} {unit}"
    if isinstance(value, str) and is_quantity_text(value):
        return value
    return None


def _value(convert: Converter, name: str, value: Any, unit: str, key: str, source: str | None) -> Any:
    text = _text(value, unit, key, source)
    if text is None:
        return value
    try:
        out = convert(name, text)
    except UnitError as exc:
        raise StudyError(key, value if not unit else text, f"{exc.expected} (for {name})", source) from None
    # 15 significant digits: 2.8648 kN m/rad is 2864.8 N m/rad, not the conversion's 2864.7999999999997
    return float(f"{out:.15g}") if isinstance(out, float) else out


def in_declared_units(study: Study, convert: Converter, base_too: bool = False) -> Study:
    """The study with every axis and point value (and the base's, ``base_too``) in its parameter's unit."""
    src = study.source
    axes = []
    for i, axis in enumerate(study.axes):
        per = [tuple(_value(convert, p, v, axis.unit, f"axes[{i}].values[{j}]", src) for j, v in enumerate(axis.values))
               for p in axis.parameters]
        if any(values != per[0] for values in per[1:]):
            raise StudyError(f"axes[{i}].unit", axis.unit, "parameters that take the axis's values in one unit "
                             f"(linked: {', '.join(axis.parameters)})", src)
        axes.append(axis.converted(per[0]) if per[0] != axis.values else axis)
    points = tuple({p: _value(convert, p, v, "", f"points[{i}].{p}", src) for p, v in pt.items()}
                   for i, pt in enumerate(study.points))
    base = study.base
    if base_too:
        base = replace(base, parameters={p: _value(convert, p, v, "", f"base.parameters.{p}", src)
                                         for p, v in base.parameters.items()})
    return replace(study, axes=tuple(axes), points=points, base=base)


def scenario_converter(system, is_file_entry: Callable[[str], bool]) -> Converter:
    """Quantity text -> the number in the unit the base scenario's FMU declares for the parameter.

    A parameter of no component, or not a Real, keeps its text (the checks of the study name it);
    a drivetrain file entry keeps it too (the file converts it).
    """
    from ..cosim.declared_units import declared_value

    def convert(name: str, text: str) -> Any:
        comp, param = split_parameter(name)
        iface = system.interfaces.get(comp)
        if is_file_entry(name) or iface is None or param not in iface.variables:
            return text
        return declared_value(iface, iface.variables[param], text, system.parameter_values(comp))

    return convert


def model_converter(units: Mapping[str, str], exponents: Callable[[str], float | None]) -> Converter:
    """Quantity text -> the SI number of a built-in model's parameter (``units``: name -> SI unit)."""
    def convert(name: str, text: str) -> Any:
        if name not in units:
            return text  # the study's checks name an unknown parameter
        return to_unit(text, units[name], exponents(name))

    return convert


#: ``problem(point values, their origins) -> the error refusing the first implausible value, or None``
Problem = Callable[[Mapping[str, Any], Mapping[str, Origin]], "EntryError | None"]


def check_points(study: Study, points: list[Point], problem: Problem,
                 skip: Callable[[str], bool] = lambda name: False) -> None:
    """Each point's ``problem(values, origins)``, the first error raised (named where its value was given).

    Points that differ only in parameters ``skip`` leaves out (a seed) are judged once.
    """
    seen: set = set()
    for point in points:
        values = {k: v for k, v in point.parameters.items() if not skip(k)}
        marker = tuple(sorted((k, repr(v)) for k, v in values.items()))
        if marker in seen:
            continue
        seen.add(marker)
        origins = study.origins(point)
        found = problem(values, {k: origins[k] for k in values})
        if found is not None:
            raise found


def model_problem(study: Study, judge: Callable[[Mapping[str, Any]], tuple | None]) -> Problem:
    """``problem`` of :func:`check_points` for a built-in model: ``judge(values) -> (parameter, value, expectation)``.

    A value the model builds itself, implausible with the point's values, is named with the last of those.
    """
    def problem(values: Mapping[str, Any], origins: Mapping[str, Origin]) -> EntryError | None:
        found = judge(values)
        if found is None:
            return None
        name, value, expected = found
        if name in origins:
            return origins[name].refusal(name, value, expected)
        return last_given(origins, origins, Origin(study.source, error=StudyError)).refusal(name, value, expected,
                                                                                            own=False)

    return problem


def scenario_problem(system) -> Problem:
    """``problem`` of :func:`check_points` for a scenario base: the run's own plausibility check, values at their origins."""
    from ..cosim.plausibility_checks import plausibility_problem
    from ..inputs.overrides import apply_parameters

    def problem(values: Mapping[str, Any], origins: Mapping[str, Origin]) -> EntryError | None:
        return plausibility_problem(replace(system, scenario=apply_parameters(system.scenario, values, origins)))

    return problem
