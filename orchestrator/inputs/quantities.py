"""Quantities with units in input files and on the command line: one unit registry, SI numbers inside.

Every dimensional input of dtcosim may be written as a number with its unit, as
a string: ``"0.56 mm"``, ``"25.4 kN m"``, ``"16 rpm"``, ``"1.51e8 kg mm^2"``,
``"5e5 N/mm^1.5"``. They are converted here, at the edge, with the
`pint <https://pint.readthedocs.io>`_ registry (:func:`registry`); everything
behind this module sees SI numbers (or the unit an FMU declares). A bare number
keeps its documented meaning (SI, or the unit a drivetrain file's ``[units]``
names for it).

Unit syntax
-----------
pint's (``kN m``, ``kg*mm**2``, ``N/mm^1.5``, ``1/mm``, ``rpm``, ``deg``, ``um``)
and the Modelica / FMI syntax of ``modelDescription.xml`` and of the drivetrain
files' ``[units]`` (``N.m``, ``kg.mm2``, ``N.s/mm2``, ``rad/s2``: a dot
multiplies, digits after a unit are its exponent). ``-`` and ``1`` are
dimensionless. In a contact stiffness ``^e`` stands for the force exponent of
the mesh (``N/mm^e``: k0 of F = k0 d^e is in N/mm^e, so its dimension depends
on e; ``N/mm^1.5`` is accepted where e = 1.5 only).

Dimensions
----------
Angles count: ``rad`` is a base unit here as in FMI 2 (``BaseUnit rad``), so a
torque (``N m``) is no shaft stiffness (``N m/rad``) and ``Hz`` is no ``rad/s``
(pint alone treats radians as dimensionless and would let both pass). A unit of
another dimension is a :class:`UnitError` whose :attr:`~UnitError.expected`
names the expected dimension and SI unit and what the given unit is.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Mapping

from components.validation import is_number

#: FMI 2 base units (``BaseUnit`` attributes) and pint's names of them
_BASE = {"kg": "kilogram", "m": "meter", "s": "second", "A": "ampere", "K": "kelvin", "mol": "mole",
         "cd": "candela", "rad": "radian"}
#: names of the dimensions in messages, by FMI base unit
_DIMENSION = {"kg": "mass", "m": "length", "s": "time", "A": "current", "K": "temperature", "mol": "substance",
              "cd": "luminosity", "rad": "angle"}
_PINT_TO_FMI = {v: k for k, v in _BASE.items()}
#: a leading number of a quantity text
_NUMBER = re.compile(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*\Z", re.S)
#: ``^e``: the force exponent of a contact stiffness
_EXPONENT_E = re.compile(r"\^\s*e(?![A-Za-z0-9_])")
_DIMENSIONLESS = ("", "-", "1")


class UnitError(ValueError):
    """A unit that is not one, or of the wrong dimension.

    Attributes
    ----------
    expected : str
        What would have been accepted and what was given, for an :class:`~orchestrator.errors.EntryError`.
    """

    def __init__(self, expected: str) -> None:
        super().__init__(expected)
        self.expected = expected


@lru_cache(maxsize=1)
def registry():
    """The one pint ``UnitRegistry`` of dtcosim (built on first use: pint is imported only when a unit is)."""
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


@dataclass(frozen=True)
class Given:
    """A value as the user wrote it: a magnitude and its unit (None: a bare number).

    Attributes
    ----------
    magnitude : float
    unit : str or None
        The unit text as written (``"mm"``, ``"kN m"``); None for a bare number.
    """

    magnitude: float
    unit: str | None = None

    @property
    def shown(self) -> float | str:
        """For messages: the bare number as it was read, or the text with its unit."""
        return self.magnitude if self.unit is None else self.text

    @property
    def text(self) -> str:
        """As written: ``"0.56 mm"``, or the bare number."""
        return f"{self.magnitude:g}" if self.unit is None else f"{self.magnitude:g} {self.unit}"

    def __str__(self) -> str:
        return self.text


def is_quantity_text(value: Any) -> bool:
    """True for a string of a number and a unit (``"0.56 mm"``, ``"16 rpm"``; not ``"0.3"`` nor ``"abc"``)."""
    if not isinstance(value, str):
        return False
    match = _NUMBER.match(value)
    return match is not None and bool(match.group(2))


def parse_given(value: Any) -> Given:
    """A number, or a string ``"<number> <unit>"``, as a :class:`Given`.

    Raises
    ------
    UnitError
        Not a finite number and not a quantity text, or a unit the registry does not know.
    """
    if is_number(value):
        if not math.isfinite(value):
            raise UnitError("a finite number, or a quantity with its unit such as \"0.56 mm\"")
        return Given(float(value))
    match = _NUMBER.match(value) if isinstance(value, str) else None
    if match is None:
        raise UnitError("a number, or a quantity with its unit such as \"0.56 mm\" or \"25.4 kN m\"")
    magnitude = float(match.group(1))
    if not math.isfinite(magnitude):
        raise UnitError("a finite number with its unit")
    unit = match.group(2)
    if not unit:
        raise UnitError("a number (not a string), or a quantity with its unit such as \"0.56 mm\"")
    _units(unit, 1.5)  # a known unit (the exponent of ^e does not matter here)
    return Given(magnitude, unit)


def _pint_text(unit: str, exponent: float | None) -> str:
    """Modelica / FMI syntax and ``^e`` turned into pint's."""
    text = unit.strip()
    if text in _DIMENSIONLESS:
        return "dimensionless"
    if _EXPONENT_E.search(text):
        if exponent is None:
            raise UnitError(f"a unit without ^e here ({unit!r}: ^e is the force exponent of a contact stiffness)")
        text = _EXPONENT_E.sub(f"^({exponent!r})", text)
    text = re.sub(r"(?<=[A-Za-z0-9)\u00b5])\.(?=[A-Za-z(\u00b5])", "*", text)  # N.m -> N*m
    text = re.sub(r"(?<=[A-Za-z\u00b5])(\d+)(?![\d.])", r"**\1", text)  # kg.m2 -> kg*m**2, rad/s2 -> rad/s**2
    return text


@lru_cache(maxsize=512)
def _units(unit: str, exponent: float | None):
    """(pint unit, factor to SI, FMI base exponents) of a unit text."""
    ureg = registry()
    import pint

    try:
        parsed = ureg.parse_units(_pint_text(unit, exponent))
    except (pint.errors.PintError, AttributeError, TypeError, ValueError, SyntaxError, AssertionError) as exc:
        raise UnitError(f"a unit dtcosim knows ({unit!r} is none: {exc})") from None
    base = ureg.Quantity(1.0, parsed).to_base_units()
    exponents: dict[str, float] = {}
    for name, power in base.unit_items():
        if name not in _PINT_TO_FMI:
            raise UnitError(f"a unit of SI base units ({unit!r} is made of {name})")
        exponents[_PINT_TO_FMI[name]] = float(power)
    return parsed, float(base.magnitude), exponents


def _same(a: Mapping[str, float], b: Mapping[str, float]) -> bool:
    return all(math.isclose(a.get(k, 0.0), b.get(k, 0.0), abs_tol=1e-9) for k in set(a) | set(b))


def dimension_text(exponents: Mapping[str, float]) -> str:
    """``{"kg": 1, "m": 2, "s": -2, "rad": -1}`` -> ``"[mass] [length]^2 [time]^-2 [angle]^-1"``."""
    parts = []
    for key in _BASE:
        p = exponents.get(key, 0.0)
        if abs(p) > 1e-12:
            power = "" if p == 1 else f"^{p:g}"
            parts.append(f"[{_DIMENSION[key]}]{power}")
    return " ".join(parts) or "dimensionless"


def base_exponents(unit: str, exponent: float | None = None) -> dict[str, float]:
    """The SI base-unit exponents of a unit text (FMI's, with ``rad``)."""
    return dict(_units(unit, exponent)[2])


def convert(magnitude: float, unit: str, target: str, exponent: float | None = None) -> float:
    """``magnitude`` in ``unit`` as a number in ``target`` (both unit texts; ``^e`` with ``exponent``).

    Raises
    ------
    UnitError
        Naming both dimensions when they differ.
    """
    parsed, _, dims = _units(unit, exponent)
    tparsed, _, tdims = _units(target, exponent)
    if not _same(dims, tdims):
        raise UnitError(mismatch_text(unit, dims, target, tdims))
    ureg = registry()
    return float(ureg.Quantity(magnitude, parsed).to(tparsed).magnitude)


def mismatch_text(unit: str, dims: Mapping[str, float], target: str, tdims: Mapping[str, float]) -> str:
    """The expectation of a unit of the wrong dimension."""
    return (f"a quantity of dimension {dimension_text(tdims)} (SI unit {target}); the unit {unit!r} is "
            f"{dimension_text(dims)}")


def to_unit(value: Any, target: str, exponent: float | None = None, bare_unit: str | None = None) -> float:
    """A number or quantity text as a number in ``target``.

    Parameters
    ----------
    value : float or str
        A bare number (in ``bare_unit``, default ``target``) or ``"<number> <unit>"``.
    target : str
        The unit of the result (``"m"``, ``"N.m/rad"``, ``"N/m^e"``).
    exponent : float, optional
        The force exponent ``e`` where ``target`` or the units contain ``^e``.
    bare_unit : str, optional
        The unit of a bare number (a drivetrain file's ``[units]`` entry).

    Raises
    ------
    UnitError
    """
    given = parse_given(value)
    unit = given.unit if given.unit is not None else bare_unit
    if unit is None:
        return given.magnitude
    return convert(given.magnitude, unit, target, exponent)


# --------------------------------------------------------------- FMI units
def fmi_target(unit: str, definition: Mapping[str, float] | None) -> tuple[dict[str, float], float, float] | None:
    """``(base exponents, factor, offset)`` of an FMU variable's declared unit, None if not known.

    From the FMU's ``UnitDefinitions`` (``BaseUnit`` exponents, ``factor``, ``offset``: value in SI =
    factor x value + offset) where it gives base units, else from the unit's name if the registry
    reads it (``"N.m"``); None for a unit neither says (``"N/m^e"`` of a contact stiffness, whose
    exponent the FMU's record gives: see :func:`to_declared`).
    """
    if definition:
        exponents = {k: float(definition[k]) for k in _BASE if k in definition}
        if exponents or any(k in definition for k in ("factor", "offset")):
            return exponents, float(definition.get("factor", 1.0)), float(definition.get("offset", 0.0))
    if not unit or unit in _DIMENSIONLESS:
        return {}, 1.0, 0.0
    try:
        _, factor, exponents = _units(unit, None)
    except UnitError:
        return None
    return dict(exponents), factor, 0.0


def to_declared(value: str, unit: str, definition: Mapping[str, float] | None = None,
                exponent: float | None = None) -> float:
    """A quantity text as a number in an FMU variable's declared unit.

    Parameters
    ----------
    value : str
        ``"<number> <unit>"``.
    unit : str
        The variable's declared unit name (``"m"``, ``"N.m/rad"``, ``"N/m^e"``).
    definition : mapping, optional
        The FMU's ``UnitDefinitions`` entry of ``unit``
        (:attr:`orchestrator.cosim.fmu_interface.FmuInterface.unit_definitions`).
    exponent : float, optional
        The value of ``e`` for a declared unit with ``^e`` (the FMU's record says which parameter holds it).

    Raises
    ------
    UnitError
    """
    given = parse_given(value)
    if given.unit is None:
        return given.magnitude
    g_dims = _units(given.unit, exponent)[2]
    if _EXPONENT_E.search(unit or ""):
        if exponent is None:
            raise UnitError(f"a bare number in {unit} (the FMU declares the exponent e of its unit nowhere dtcosim "
                            "can read it)")
        target = (dict(_units(unit, exponent)[2]), _units(unit, exponent)[1], 0.0)
    else:
        target = fmi_target(unit, definition)
    if target is None:
        raise UnitError(f"a bare number in the FMU's unit {unit!r} (it declares no SI base units for it)")
    exponents, factor, offset = target
    if not _same(g_dims, exponents):
        raise UnitError(mismatch_text(given.unit, g_dims, unit or "1", exponents))
    ureg = registry()
    parsed = _units(given.unit, exponent)[0]
    si = float(ureg.Quantity(given.magnitude, parsed).to_base_units().magnitude)
    return (si - offset) / factor


# --------------------------------------------------------------- schema fields
#: pydantic error type of a value whose unit is wrong (:func:`orchestrator.inputs.schema.entry_error` keeps its text)
QUANTITY_ERROR = "quantity"


def _quantity_error(expected: str):
    from pydantic_core import PydanticCustomError

    return PydanticCustomError(QUANTITY_ERROR, "{expected}", {"expected": expected})


def si_number(unit: str):
    """A field type: a bare number in ``unit``, or a quantity text converted to ``unit`` (then pydantic's checks).

    ``rated_torque: si_number("N.m") = Field(gt=0, ...)`` reads ``25.4e3`` and ``"25.4 kN m"`` alike.
    """
    from typing import Annotated

    from pydantic import BeforeValidator

    def convert(value: Any) -> Any:
        if not isinstance(value, str):
            return value
        try:
            return to_unit(value, unit)
        except UnitError as exc:
            raise _quantity_error(exc.expected) from None

    return Annotated[float, BeforeValidator(convert)]


def amount(*, gt: float | None = None, ge: float | None = None, le: float | None = None):
    """A field type: a bare number or a quantity text as a :class:`Given` (the unit of a bare one is the file's).

    ``gt``, ``ge``, ``le`` bound the magnitude (their sign does not depend on the unit); a value outside is
    pydantic's ``greater_than`` ... error, so the message is the field's description.
    """
    from typing import Annotated

    from pydantic import BeforeValidator
    from pydantic_core import PydanticCustomError

    def check(value: Any) -> Given:
        if isinstance(value, Given):
            given = value
        elif isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise PydanticCustomError("float_type", "a number")
        else:
            try:
                given = parse_given(value)
            except UnitError as exc:
                raise _quantity_error(exc.expected) from None
        x = given.magnitude
        if (gt is not None and not x > gt) or (ge is not None and not x >= ge) or (le is not None and not x <= le):
            raise PydanticCustomError("out_of_range", "out of range")
        return given

    return Annotated[Given, BeforeValidator(check)]
