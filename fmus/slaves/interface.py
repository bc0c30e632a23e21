"""Declarative description of an FMU interface: variables and their units.

A slave declares its variables as a tuple of :class:`Variable`; the base slave
registers them with pythonfmu (value reference = position in the tuple) and the
build writes their units into ``modelDescription.xml`` from :data:`UNITS`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Union

Value = Union[float, int, bool]

#: Variable types (FMI 2 scalar types used here).
REAL, INTEGER, BOOLEAN = "Real", "Integer", "Boolean"
#: Causalities used here.
PARAMETER, INPUT, OUTPUT = "parameter", "input", "output"


@dataclass(frozen=True)
class UnitDefinition:
    """An FMI 2 ``Unit``: its SI base-unit exponents and display units.

    Parameters
    ----------
    name : str
        Unit name as written in ``modelDescription.xml`` (Modelica unit syntax where possible).
    base_exponents : mapping of str to int, or None
        Exponents of the SI base units (``kg``, ``m``, ``s``, ``A``, ``K``, ``mol``, ``cd``,
        ``rad``); ``None`` when the unit has no integer-exponent expression (e.g. N/m^1.5).
    display_units : mapping of str to float
        Display units and their factors: ``value_display = factor * value``.
    """

    name: str
    base_exponents: Mapping[str, int] | None
    display_units: Mapping[str, float]


def _unit(name: str, base: Mapping[str, int] | None, **display: float) -> UnitDefinition:
    return UnitDefinition(name, base, dict(display))


#: Every unit an FMU variable may declare, by name.
UNITS: dict[str, UnitDefinition] = {
    u.name: u
    for u in (
        _unit("1", {}),
        _unit("s", {"s": 1}),
        _unit("m", {"m": 1}, mm=1.0e3),
        _unit("kg", {"kg": 1}),
        _unit("kg.m2", {"kg": 1, "m": 2}),
        _unit("rad", {"rad": 1}, deg=180.0 / math.pi),
        _unit("rad/s", {"rad": 1, "s": -1}, rpm=60.0 / (2.0 * math.pi)),
        _unit("rad/s2", {"rad": 1, "s": -2}),
        _unit("rad/s3", {"rad": 1, "s": -3}),
        _unit("N", {"kg": 1, "m": 1, "s": -2}, kN=1.0e-3),
        _unit("N.m", {"kg": 1, "m": 2, "s": -2}, **{"kN.m": 1.0e-3}),
        _unit("N.m/rad", {"kg": 1, "m": 2, "s": -2, "rad": -1}),
        _unit("N.m.s/rad", {"kg": 1, "m": 2, "s": -1, "rad": -1}),
        _unit("N/m^e", None),  # contact stiffness k0 for a force exponent e (N/m^1.5 by default)
        _unit("N.s/m2", {"kg": 1, "m": -1, "s": -1}),
        _unit("N.s/m", {"kg": 1, "s": -1}),
        _unit("1/m", {"m": -1}),
        _unit("m/s", {"m": 1, "s": -1}),
        _unit("W", {"kg": 1, "m": 2, "s": -3}, kW=1.0e-3),
        _unit("N.m.s2/rad2", {"kg": 1, "m": 2, "rad": -2}),  # the torque law's k of k w^2
        _unit("N.m/s", {"kg": 1, "m": 2, "s": -3}),  # torque rate
        _unit("N/m", {"kg": 1, "s": -2}),  # bearing stiffness
        _unit("m/s2", {"m": 1, "s": -2}),  # gravity
    )
}


@dataclass(frozen=True)
class Variable:
    """One FMU variable.

    Parameters
    ----------
    name : str
        FMI name (structured convention, may contain dots and brackets).
    type : {"Real", "Integer", "Boolean"}
    causality : {"parameter", "input", "output"}
    description : str
        Human-readable description; the build appends the unit.
    unit : str
        Unit name (a key of :data:`UNITS`); Real variables only, ``""`` otherwise.
    start : float, int, bool or None
        Start value of parameters and inputs; ``None`` for outputs (they are calculated).
    signal : str
        What an output is in the drivetrain (a kind of :data:`fmus.slaves.record.SIGNALS`,
        e.g. ``"contact_force"``), declared in the FMU's record; ``""``: nothing the
        analyses use.
    info : tuple of (str, str)
        Details of the signal (``("stage", "stage1"), ("mesh", "sun_planet"), ("planet", "1")``).
    unit_exponent : str
        For a unit with the exponent ``e`` (``"N/m^e"`` of a contact stiffness): the parameter whose value
        is ``e``, declared in the FMU's record (``unit_exponents``) so a host can convert a quantity
        such as ``"5e5 N/mm^1.5"`` to it; ``""`` otherwise.
    """

    name: str
    type: str
    causality: str
    description: str
    unit: str = ""
    start: Value | None = None
    signal: str = ""
    info: tuple[tuple[str, str], ...] = ()
    unit_exponent: str = ""

    def __post_init__(self) -> None:
        if self.type not in (REAL, INTEGER, BOOLEAN):
            raise ValueError(f"variable {self.name}: type {self.type!r} not supported")
        if self.causality not in (PARAMETER, INPUT, OUTPUT):
            raise ValueError(f"variable {self.name}: causality {self.causality!r} not supported")
        if self.type == REAL and self.unit not in UNITS:
            raise ValueError(f"variable {self.name}: unit {self.unit!r} is not in UNITS")
        if self.type != REAL and self.unit:
            raise ValueError(f"variable {self.name}: only Real variables carry a unit in FMI 2")
        if (self.causality == OUTPUT) != (self.start is None):
            raise ValueError(f"variable {self.name}: outputs have no start value, parameters and inputs need one")

    @property
    def variability(self) -> str:
        """FMI variability: parameters are ``fixed``, Real inputs/outputs ``continuous``."""
        if self.causality == PARAMETER:
            return "fixed"
        return "continuous" if self.type == REAL else "discrete"

    @property
    def full_description(self) -> str:
        """Description with the unit appended, as written into ``modelDescription.xml``."""
        unit = self.unit if self.type == REAL else "-"
        return f"{self.description} [{unit}]"


def real_parameter(name: str, start: float, unit: str, description: str, unit_exponent: str = "") -> Variable:
    """A fixed Real parameter (``unit_exponent``: the parameter holding the ``e`` of a unit such as ``N/m^e``)."""
    return Variable(name, REAL, PARAMETER, description, unit, float(start), unit_exponent=unit_exponent)


def integer_parameter(name: str, start: int, description: str) -> Variable:
    """A fixed Integer parameter."""
    return Variable(name, INTEGER, PARAMETER, description, "", int(start))


def boolean_parameter(name: str, start: bool, description: str) -> Variable:
    """A fixed Boolean parameter."""
    return Variable(name, BOOLEAN, PARAMETER, description, "", bool(start))


def real_input(name: str, start: float, unit: str, description: str) -> Variable:
    """A continuous Real input."""
    return Variable(name, REAL, INPUT, description, unit, float(start))


def real_output(name: str, unit: str, description: str, signal: str = "", **info: str) -> Variable:
    """A continuous Real output (initial = calculated), optionally declared as a drivetrain ``signal``."""
    return Variable(name, REAL, OUTPUT, description, unit, None, signal, tuple((k, str(v)) for k, v in info.items()))


def enumeration_text(choices: tuple[str, ...]) -> str:
    """``"0 = a, 1 = b"`` for an Integer parameter that encodes a choice."""
    return ", ".join(f"{i} = {c}" for i, c in enumerate(choices))
