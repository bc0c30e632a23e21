"""Parameter sets as plain JSON data and back: the description an FMU records of its physics.

:func:`describe` turns a frozen parameter dataclass of this package (a
:class:`~components.model.drivetrain.Drivetrain` with its stages, shafts,
meshes and generator, :class:`~components.model.wind.WindParameters`, ...) into
nested dicts, lists, strings and numbers; :func:`build` turns that back into the
same object, validated again by the dataclasses. Every init field is written, so
the description is complete (no defaults of the reading code fill gaps) and
``build(describe(x)) == x`` exactly: floats are written with ``repr`` precision
by :mod:`json`, and the non-finite ones (a permanent event's ``inf`` duration)
as ``{"float": "inf"}`` so that the file stays strict JSON.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Mapping

from ..errors import ParameterError
from .bearings import Bearing, Gravity, ParallelLateral, PlanetaryLateral, RingSupport
from .contact import MeshContact
from .drivetrain import Drivetrain
from .generator import GeneratorParameters, LoadEvent
from .stages import ParallelStage, PlanetaryStage, Shaft
from .rotor import RotorParameters
from .torque_controller import TorqueLawParameters
from .wind import WindParameters

#: the classes a description may contain, by the name written into it
TYPES: dict[str, type] = {cls.__name__: cls for cls in (
    Drivetrain, PlanetaryStage, ParallelStage, Shaft, MeshContact, GeneratorParameters, LoadEvent, WindParameters,
    RotorParameters, TorqueLawParameters, Bearing, RingSupport, PlanetaryLateral, ParallelLateral, Gravity,
)}
_TYPE_KEY = "type"


def describe(value: Any) -> Any:
    """Plain JSON data of a parameter object (recursively), with each object's class under ``"type"``."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        name = type(value).__name__
        if TYPES.get(name) is not type(value):
            raise ParameterError("description", name, "one of the parameter classes " + ", ".join(TYPES))
        out: dict[str, Any] = {_TYPE_KEY: name}
        for f in dataclasses.fields(value):
            if f.init:
                out[f.name] = describe(getattr(value, f.name))
        return out
    if isinstance(value, (list, tuple)):
        return [describe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return {"float": repr(value)}
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise ParameterError("description", repr(value), "numbers, strings, None, lists and parameter objects")


def build(data: Any, where: str = "description") -> Any:
    """The parameter object of :func:`describe`'s data (validated by its class).

    Parameters
    ----------
    data : JSON data
    where : str
        Path of ``data`` in the document, for error messages.

    Raises
    ------
    ParameterError
        An unknown class, unknown or missing fields, or a value its class rejects.
    """
    if isinstance(data, list):
        return tuple(build(v, f"{where}[{i}]") for i, v in enumerate(data))
    if not isinstance(data, Mapping):
        return data
    if set(data) == {"float"}:
        return float(data["float"])
    name = data.get(_TYPE_KEY)
    cls = TYPES.get(name)
    if cls is None:
        raise ParameterError(f"{where}.{_TYPE_KEY}", name, "one of " + ", ".join(TYPES))
    fields = {f.name for f in dataclasses.fields(cls) if f.init}
    given = set(data) - {_TYPE_KEY}
    if given != fields:
        problem = sorted(given - fields) or sorted(fields - given)
        raise ParameterError(f"{where}", problem, f"exactly the fields of {name}: {', '.join(sorted(fields))}")
    return cls(**{k: build(data[k], f"{where}.{k}") for k in sorted(given)})
