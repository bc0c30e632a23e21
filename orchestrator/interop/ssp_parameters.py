"""SSP 1.0 parameter bindings: inline and external ``.ssv`` parameter sets with ``.ssm`` parameter mappings.

One ``ssd:ParameterBinding`` yields named values (:func:`binding_values`):

1. the parameter set, inline (``ssd:ParameterValues``) or from the file its
   ``source`` names (relative to the SSD; ``sourceBase="component"`` is not
   supported and refused);
2. its names with the binding's ``prefix`` prepended;
3. the parameter mapping, inline or from a ``.ssm`` file: an entry renames a
   parameter (``source`` -> ``target``) and may transform its value (linear,
   Boolean/Integer/Enumeration mapping); parameters without an entry keep their
   names (SSP 1.0).

Which variable a name means, and the precedence between bindings (later
bindings at one level over earlier ones, a system's over its elements'), are
the system reader's part (:mod:`orchestrator.interop.ssp_import`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..inputs.transformations import LinearTransformation
from .ssp_xml import (
    check_supported,
    child,
    children,
    element_error,
    parameter_value,
    parse,
    tag,
    transformation,
    unit_definitions,
    UnitDefinition,
    where,
)

PARAMETER_SET_TYPE = "application/x-ssp-parameter-set"
PARAMETER_MAPPING_TYPE = "application/x-ssp-parameter-mapping"


@dataclass(frozen=True)
class BoundValue:
    """One value a parameter binding gives.

    Attributes
    ----------
    name : str
        Name after prefix and mapping (a connector, or ``element.name`` in a system).
    type : str
        ``Real``, ``Integer``, ``Boolean``, ``String`` or ``Enumeration`` (item name).
    value : Any
    unit : str
        Unit of a Real value ("" when none is given).
    origin : str
        ``file, line n`` of the ``ssv:Parameter``.
    units : dict of str -> UnitDefinition
        Unit definitions of the parameter set (``ssv:Units``).
    transformation : Transformation or None
        The mapping entry's transformation, applied after the conversion to the
        target's unit (SSP 1.0: "the value of source is already converted to the
        target unit").
    """

    name: str
    type: str
    value: Any
    unit: str
    origin: str
    units: dict
    transformation: Any = None

    def target_value(self, conversion=None) -> Any:
        """The value for the target: unit conversion (a LinearTransformation or None), then the mapping's transformation."""
        value = self.value if conversion is None else conversion.apply(self.value)
        return value if self.transformation is None else self.transformation.apply(value)


def _resolve(base: Path, source: str, el, path: Path) -> Path:
    if "://" in source or source.startswith("/") or ".." in Path(source).parts:
        raise element_error(el, path, f"source {source!r}: only relative paths inside the SSP are supported")
    target = (base / source).resolve()
    if not target.is_file():
        raise element_error(el, path, f"source {source!r}: no such file {target}")
    return target


def _parameter_set(binding, ssd_path: Path, notes: list[str]):
    """(ssv:ParameterSet element, file it is in)."""
    if (binding.get("type") or PARAMETER_SET_TYPE) != PARAMETER_SET_TYPE:
        raise element_error(binding, ssd_path, f"type {binding.get('type')!r} is not supported (only {PARAMETER_SET_TYPE})")
    if (binding.get("sourceBase") or "SSD") != "SSD":
        raise element_error(binding, ssd_path, 'sourceBase="component" is not supported (files relative to the SSD only)')
    source = binding.get("source")
    inline = child(binding, "ssd:ParameterValues")
    if source:
        if inline is not None:
            raise element_error(binding, ssd_path, "has both a source and inline ssd:ParameterValues")
        file = _resolve(ssd_path.parent, source, binding, ssd_path)
        root = parse(file)
        if tag(root) != "ssv:ParameterSet":
            raise element_error(root, file, "is not an ssv:ParameterSet (the root of a .ssv file)")
        check_supported(root, file, notes)
        return root, file
    if inline is None:
        raise element_error(binding, ssd_path, "has neither a source nor inline ssd:ParameterValues")
    sets = children(inline, "ssv:ParameterSet")
    if len(sets) != 1:
        raise element_error(inline, ssd_path, "must hold exactly one ssv:ParameterSet")
    return sets[0], ssd_path


def _mapping(binding, ssd_path: Path, notes: list[str]):
    """``{source name: (target name, transformation)}`` of the binding's parameter mapping (empty if none)."""
    mapping_el = child(binding, "ssd:ParameterMapping")
    if mapping_el is None:
        return {}
    if (mapping_el.get("type") or PARAMETER_MAPPING_TYPE) != PARAMETER_MAPPING_TYPE:
        raise element_error(mapping_el, ssd_path, f"type {mapping_el.get('type')!r} is not supported")
    if (mapping_el.get("sourceBase") or "SSD") != "SSD":
        raise element_error(mapping_el, ssd_path, 'sourceBase="component" is not supported')
    source = mapping_el.get("source")
    if source:
        file = _resolve(ssd_path.parent, source, mapping_el, ssd_path)
        root = parse(file)
        if tag(root) != "ssm:ParameterMapping":
            raise element_error(root, file, "is not an ssm:ParameterMapping (the root of a .ssm file)")
        check_supported(root, file, notes)
    else:
        roots = children(mapping_el, "ssm:ParameterMapping")
        if len(roots) != 1:
            raise element_error(mapping_el, ssd_path, "must hold exactly one ssm:ParameterMapping or name a source")
        root, file = roots[0], ssd_path
    out = {}
    for entry in children(root, "ssm:MappingEntry"):
        src, dst = entry.get("source"), entry.get("target")
        if not src or not dst:
            raise element_error(entry, file, "needs source and target")
        out[src] = (dst, transformation(entry, file), where(entry, file))
    return out


def binding_values(binding, ssd_path: Path, notes: list[str]) -> list[BoundValue]:
    """The values one ``ssd:ParameterBinding`` gives, in file order (see the module docstring)."""
    pset, file = _parameter_set(binding, ssd_path, notes)
    units: dict[str, UnitDefinition] = unit_definitions(child(pset, "ssv:Units"), file)
    prefix = binding.get("prefix") or ""
    mapping = _mapping(binding, ssd_path, notes)
    out = []
    params = child(pset, "ssv:Parameters")
    for p in children(params, "ssv:Parameter") if params is not None else []:
        name = p.get("name")
        if not name:
            raise element_error(p, file, "has no name")
        kind, value, unit = parameter_value(p, file)
        name = prefix + name
        transform = None
        if name in mapping:
            name, transform, _ = mapping[name]
            _check_transform(transform, kind, p, file)
        out.append(BoundValue(name, kind, value, unit, where(p, file), units, transform))
    return out


def _check_transform(transform, kind: str, el, file: Path) -> None:
    if transform is None:
        return
    if isinstance(transform, LinearTransformation):
        if kind != "Real":
            raise element_error(el, file, f"is {kind}: a LinearTransformation applies to Real parameters only")
    elif transform.kind != kind:
        raise element_error(el, file, f"is {kind}: a {transform.kind} mapping does not apply to it")


def bindings_of(el, ssd_path: Path, notes: list[str]) -> list[list[BoundValue]]:
    """The values of every ``ssd:ParameterBinding`` of a component or system, in order."""
    holder = child(el, "ssd:ParameterBindings")
    if holder is None:
        return []
    return [binding_values(b, ssd_path, notes) for b in children(holder, "ssd:ParameterBinding")]

