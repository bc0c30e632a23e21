"""Transformations of a value on its way from a source to a target (SSP 1.0 ``ssc:GTransformationChoice``).

A connection (and an SSP parameter mapping entry) may change the value it
conveys:

* :class:`LinearTransformation` ``target = factor * source + offset`` (Real);
* :class:`MappingTransformation` a table of source -> target values for Boolean,
  Integer (also Enumeration values) and Enumeration item names; a value the
  table does not list passes unchanged.

Unit conversions between connectors with different units are linear
transformations applied before the connection's own (SSP 1.0: "the value of
source is already converted to the target unit"); :func:`compose` chains them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Union

from ..errors import ScenarioError

#: MappingTransformation kinds and the SSP element of each
MAPPING_KINDS = {"Boolean": "ssc:BooleanMappingTransformation", "Integer": "ssc:IntegerMappingTransformation",
                 "Enumeration": "ssc:EnumerationMappingTransformation"}


@dataclass(frozen=True)
class LinearTransformation:
    """``target = factor * source + offset`` (Real values)."""

    factor: float = 1.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        for name in ("factor", "offset"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ScenarioError(f"transformation.{name}", value, "a finite number")
            object.__setattr__(self, name, float(value))

    def apply(self, value: float) -> float:
        return self.factor * value + self.offset

    def describe(self) -> str:
        return f"{self.factor:g} * x + {self.offset:g}"


@dataclass(frozen=True)
class MappingTransformation:
    """A table of source -> target values.

    Parameters
    ----------
    kind : {"Boolean", "Integer", "Enumeration"}
        Value type: bool, int, or an Enumeration's item names (str).
    entries : tuple of (source, target)
    """

    kind: str
    entries: tuple[tuple[Any, Any], ...]

    def __post_init__(self) -> None:
        if self.kind not in MAPPING_KINDS:
            raise ScenarioError("transformation.kind", self.kind, "one of " + ", ".join(MAPPING_KINDS))
        object.__setattr__(self, "entries", tuple((a, b) for a, b in self.entries))
        expected = {"Boolean": bool, "Integer": int, "Enumeration": str}[self.kind]
        for a, b in self.entries:
            if not (type(a) is expected and type(b) is expected):
                raise ScenarioError("transformation.entries", (a, b), f"{expected.__name__} values for a {self.kind} mapping")

    @property
    def table(self) -> dict:
        return dict(self.entries)

    def apply(self, value: Any) -> Any:
        return self.table.get(value, value)

    def describe(self) -> str:
        return ", ".join(f"{a!r} -> {b!r}" for a, b in self.entries)


Transformation = Union[LinearTransformation, MappingTransformation]


def compose(first: Transformation | None, second: Transformation | None) -> Transformation | None:
    """The transformation applying ``first`` and then ``second`` (either may be None)."""
    if first is None:
        return second
    if second is None:
        return first
    if isinstance(first, LinearTransformation) and isinstance(second, LinearTransformation):
        return LinearTransformation(second.factor * first.factor, second.factor * first.offset + second.offset)
    if isinstance(first, MappingTransformation) and isinstance(second, MappingTransformation) \
            and first.kind == second.kind:
        keys = list(dict.fromkeys([a for a, _ in first.entries] + [a for a, _ in second.entries]))
        return MappingTransformation(first.kind, tuple((k, second.apply(first.apply(k))) for k in keys))
    raise ScenarioError("transformation", f"{first} then {second}", "transformations of one kind to chain")
