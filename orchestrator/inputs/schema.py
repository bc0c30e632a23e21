"""One schema layer for every input file: the shape of a TOML document, checked with pydantic.

Each file kind (scenario, study, ...) declares its tables as :class:`Table`
models: unknown keys are errors, values are taken as TOML typed them (strict: a
string is never read as a number, a boolean never as an integer), numbers must
be finite unless a field allows otherwise, and each field's ``description`` says
what it expects ("a number [s]"). :func:`read_document` validates a parsed
document and turns the first problem into the file kind's
:class:`~orchestrator.errors.EntryError`, naming the file, the key path
(``connections[2].to``), the value and the expectation, with a "did you mean"
for a misspelt key. The meaning of the values (a step that divides the run, a
window inside it, an input connected once) is checked by the frozen objects the
file kinds build from the validated tables, with the same kind of message.

Also here, shared by every file kind: names of components and files
(:data:`NAME_PATTERN`), parameter values and nested parameter tables
(:func:`flatten_parameters`).
"""

from __future__ import annotations

import math
import re
import types
import typing
from typing import Any, Mapping, TypeVar, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ..errors import EntryError, suggestion

#: names of components, scenarios and studies: letters, digits, ``_`` and ``-``, starting with a letter or ``_``
NAME_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*\Z")  # \Z, not $: "$" also matches before a final newline

#: parameter values an input file may give (FMI Real, Integer, Boolean, String)
ParameterValue = Union[float, int, bool, str]

M = TypeVar("M", bound="Table")


class Table(BaseModel):
    """A table of an input file (frozen; unknown keys, type mismatches and non-finite numbers are errors)."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False,
                              arbitrary_types_allowed=True, defer_build=True)


class PlausibilityTable(Table):
    """``[plausibility]``: values a deliberate study keeps although physics calls them implausible.

    ``allow`` names parameters: flat names in a drivetrain file (``"stage1.backlash"``),
    ``"component.parameter"`` in a scenario, study or load-case set (``"gearbox.stage1.backlash"``).
    """

    allow: list[str] = Field(default_factory=list, description='a list of parameter names such as '
                             '"gearbox.stage1.backlash" ("stage1.backlash" in a drivetrain file)')


def key_path(loc: tuple) -> str:
    """``("connections", 2, "to")`` -> ``"connections[2].to"``."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _strip(annotation: Any) -> Any:
    """``X | None`` and ``Annotated[X, ...]`` -> ``X`` (the first non-None member of a union)."""
    while True:
        origin = typing.get_origin(annotation)
        if origin is typing.Annotated:
            annotation = typing.get_args(annotation)[0]
        elif origin in (Union, types.UnionType):
            annotation = next(a for a in typing.get_args(annotation) if a is not type(None))
        else:
            return annotation


def _field_of(model: type[BaseModel], key: str):
    for name, info in model.model_fields.items():
        if key in (name, info.alias):
            return info
    return None


def _walk(root: type[BaseModel], loc: tuple) -> tuple[Any, type[BaseModel] | None]:
    """The field at ``loc`` (None outside the models) and the model the path ends in (None if not a table)."""
    model: type[BaseModel] | None = root
    info = None
    i = 0
    while i < len(loc):
        if model is None or not isinstance(loc[i], str):
            return info, None
        info = _field_of(model, loc[i])
        if info is None:
            return None, None
        annotation = _strip(info.annotation)
        if typing.get_origin(annotation) in (list, dict) and i + 1 < len(loc):
            annotation = _strip(typing.get_args(annotation)[-1])  # the entry type; skip its index or key
            i += 1
        model = annotation if isinstance(annotation, type) and issubclass(annotation, BaseModel) else None
        i += 1
    return info, model


_GENERIC = {
    "missing": "a value",
    "float_type": "a number",
    "int_type": "an integer",
    "bool_type": "true or false",
    "string_type": "a string",
    "list_type": "a list [...]",
    "dict_type": "a table",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "finite_number": "a finite number",
    "literal_error": "one of the listed values",
    "too_short": "more entries",
    "too_long": "fewer entries",
}


def _without_union_tag(root: type[BaseModel], loc: tuple) -> tuple:
    """``loc`` without the union member pydantic appends (``runs.length.constrained-float`` -> ``runs.length``)."""
    if len(loc) > 1 and isinstance(loc[-1], str):
        parent, table = _walk(root, loc[:-1])
        annotation = getattr(parent, "annotation", None)
        if table is None and typing.get_origin(annotation) in (Union, types.UnionType) \
                and typing.get_origin(_strip(annotation)) not in (list, dict):
            return loc[:-1]  # a leaf of union type: the last part names the member, not a key
    return loc


def entry_error(exc: ValidationError, root: type[BaseModel], error: type[EntryError],
                source: str | None) -> EntryError:
    """The first problem of a pydantic validation as one ``error`` naming key, value and expectation."""
    first = exc.errors(include_url=False)[0]
    loc = _without_union_tag(root, tuple(first["loc"]))
    kind = first["type"]
    key = key_path(loc) or "(document)"
    value = first.get("input")
    if kind == "extra_forbidden":
        parent = _walk(root, loc[:-1])[1] or root
        allowed = [info.alias or name for name, info in parent.model_fields.items()]
        hint = suggestion(str(loc[-1]), allowed, n=1)
        if len(loc) > 1 and _field_of(root, str(loc[-1])) is not None:
            hint += f" ({loc[-1]} is a top-level key: in TOML it must come before the first [table] header)"
        return error(key, value, "a known key here: " + ", ".join(sorted(allowed)) + hint, source)
    info = _walk(root, loc)[0]
    described = info.description if info is not None and info.description else None
    if kind == "missing":
        return error(key, None, f"{described or 'a value'} (missing)", source)
    if kind == "literal_error":
        expected = first.get("ctx", {}).get("expected", "")
        return error(key, value, f"one of {expected}" if expected else (described or _GENERIC[kind]), source)
    if kind == "quantity":  # a unit of the wrong dimension (orchestrator.inputs.quantities): say which
        expected = first["ctx"]["expected"]
        return error(key, value, f"{described}: {expected}" if described else expected, source)
    if described is not None and not isinstance(loc[-1], int):
        return error(key, value, described, source)
    if kind == "value_error":  # a validator's own message
        return error(key, value, str(first.get("ctx", {}).get("error", first["msg"])), source)
    generic = _GENERIC.get(kind, first["msg"][0].lower() + first["msg"][1:])
    if described is not None:  # an entry of a list or table: say what the whole is
        end = len(loc)
        while end and isinstance(loc[end - 1], int):
            end -= 1
        whole = key_path(loc[:end])
        generic += f" ({whole}: {described})"
    return error(key, value, generic, source)


def read_document(model: type[M], data: Any, error: type[EntryError], source: str | None = None) -> M:
    """Validate a parsed TOML document (or a table of one) against ``model``.

    Raises
    ------
    EntryError
        ``error`` naming the first offending key (see :func:`entry_error`).
    """
    if not isinstance(data, Mapping):
        raise error("(document)", data, "a table", source)
    try:
        return model.model_validate(dict(data))
    except ValidationError as exc:
        raise entry_error(exc, model, error, source) from None


def is_parameter_value(value: Any) -> bool:
    """A value a parameter may take: a finite number, a boolean or a string."""
    if isinstance(value, float):
        return math.isfinite(value)
    return isinstance(value, (int, bool, str))


def flatten_parameters(table: Mapping[str, Any], key: str, error: type[EntryError], source: str | None = None,
                       prefix: str = "") -> dict[str, ParameterValue]:
    """Nested parameter tables -> dotted names (``stage1 = {k0 = 1}`` -> ``stage1.k0``), values checked.

    Raises
    ------
    EntryError
        ``error`` naming ``<key>.<dotted name>`` for a value that is not a finite number, a boolean or a string.
    """
    out: dict[str, ParameterValue] = {}
    for name, value in table.items():
        dotted = f"{prefix}.{name}" if prefix else name
        if isinstance(value, Mapping):
            out.update(flatten_parameters(value, key, error, source, dotted))
        elif is_parameter_value(value):
            out[dotted] = value
        else:
            raise error(f"{key}.{dotted}", value, "a finite number, a boolean or a string", source)
    return out
