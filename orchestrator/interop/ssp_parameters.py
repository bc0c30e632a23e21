"""SSP 1.0 parameter bindings: inline and external ``.ssv`` parameter sets with ``.ssm`` parameter mappings.

One ``ssd:ParameterBinding`` yields named values (:func:`binding_values`):

1. the parameter set, inline (``ssd:ParameterValues``) or from the file its
   ``source`` names (relative to the SSD; ``sourceBase="component"`` is not
   supported and refused);
2. its names with the binding's ``prefix`` prepended;
3. the parameter mapping, inline or from a ``.ssm`` file. SSP 1.0, 5.2.3
   (ParameterBindings): without a mapping every value of the set is applied
   under its own name; *with* a mapping only the mapped values are applied,
   under their mapped-to names ("Non-mapped parameter values are not applied in
   this case"). Every ``ssm:MappingEntry`` maps one ``source`` to one ``target``
   with its own transformation (linear, Boolean/Integer/Enumeration mapping), so
   one source may feed many targets, each through its entry's transformation.
   An entry with an empty ``source`` or ``target`` (schema-valid) maps nothing:
   it is reported as a note and skipped; so are the values the mapping leaves out.

Which variable a name means, the names that reach none (ignored, SSP 1.0: "Otherwise
that parameter value is ignored"), and the precedence between bindings (later
bindings at one level over earlier ones, a system's over its elements'), are
the system reader's part (:mod:`orchestrator.interop.ssp_system`).
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
        raise element_error(el, path, f"source {source!r}: only relative paths inside the SSP are supported "
                            "(dtcosim reads no URLs or files outside the package)",
                            "put the file into the SSP and name it relative to the SSD")
    target = (base / source).resolve()
    if not target.is_file():
        raise element_error(el, path, f"source {source!r}: no such file {target}",
                            "add the file to the SSP or correct the source")
    return target


def _parameter_set(binding, ssd_path: Path, notes: list[str]):
    """(ssv:ParameterSet element, file it is in)."""
    if (binding.get("type") or PARAMETER_SET_TYPE) != PARAMETER_SET_TYPE:
        raise element_error(binding, ssd_path, f"type {binding.get('type')!r} is not supported (dtcosim reads "
                            f"{PARAMETER_SET_TYPE}, .ssv)", "convert the values to an .ssv parameter set")
    if (binding.get("sourceBase") or "SSD") != "SSD":
        raise element_error(binding, ssd_path, 'sourceBase="component" is not supported (files relative to the '
                            'SSD only)', 'place the .ssv file in the SSP and name it relative to the SSD '
                            '(sourceBase="SSD")')
    source = binding.get("source")
    inline = child(binding, "ssd:ParameterValues")
    if source:
        if inline is not None:
            raise element_error(binding, ssd_path, "has both a source and inline ssd:ParameterValues (SSP 1.0: "
                                "one or the other)", "keep either the source or the inline values")
        file = _resolve(ssd_path.parent, source, binding, ssd_path)
        root = parse(file)
        if tag(root) != "ssv:ParameterSet":
            raise element_error(root, file, "is not an ssv:ParameterSet (the root of a .ssv file, SSP 1.0)",
                                "name a .ssv file in the binding's source")
        check_supported(root, file, notes)
        return root, file
    if inline is None:
        raise element_error(binding, ssd_path, "has neither a source nor inline ssd:ParameterValues (SSP 1.0: "
                            "a binding needs its values)", "name a .ssv file in source or give the values inline")
    sets = children(inline, "ssv:ParameterSet")
    if len(sets) != 1:
        raise element_error(inline, ssd_path, "must hold exactly one ssv:ParameterSet (SSP 1.0 schema)",
                            "put the values into one ssv:ParameterSet")
    return sets[0], ssd_path


@dataclass(frozen=True)
class MappingEntry:
    """One ``ssm:MappingEntry``: parameter ``source`` is applied as ``target`` through ``transformation``."""

    source: str
    target: str
    transformation: Any
    origin: str


def _mapping(binding, ssd_path: Path, notes: list[str]) -> list[MappingEntry] | None:
    """The entries of the binding's parameter mapping in file order; None without an ``ssd:ParameterMapping``."""
    mapping_el = child(binding, "ssd:ParameterMapping")
    if mapping_el is None:
        return None
    if (mapping_el.get("type") or PARAMETER_MAPPING_TYPE) != PARAMETER_MAPPING_TYPE:
        raise element_error(mapping_el, ssd_path, f"type {mapping_el.get('type')!r} is not supported",
                            f"dtcosim reads mappings of type {PARAMETER_MAPPING_TYPE} (.ssm): convert the mapping "
                            "to an .ssm file or give its entries inline")
    if (mapping_el.get("sourceBase") or "SSD") != "SSD":
        raise element_error(mapping_el, ssd_path, 'sourceBase="component" is not supported',
                            'place the .ssm file in the SSP and name it relative to the SSD (sourceBase="SSD")')
    source = mapping_el.get("source")
    if source:
        file = _resolve(ssd_path.parent, source, mapping_el, ssd_path)
        root = parse(file)
        if tag(root) != "ssm:ParameterMapping":
            raise element_error(root, file, "is not an ssm:ParameterMapping (the root of a .ssm file, SSP 1.0)",
                                "name a .ssm file in the ssd:ParameterMapping's source")
        check_supported(root, file, notes)
    else:
        roots = children(mapping_el, "ssm:ParameterMapping")
        if len(roots) != 1:
            raise element_error(mapping_el, ssd_path, "must hold exactly one ssm:ParameterMapping or name a source "
                                "(SSP 1.0 schema)", "give the entries inline or the .ssm file in source")
        root, file = roots[0], ssd_path
    out = []
    for entry in children(root, "ssm:MappingEntry"):
        src, dst = entry.get("source") or "", entry.get("target") or ""
        if not src or not dst:
            empty = "source" if not src else "target"
            notes.append(f"{where(entry, file)}: <ssm:MappingEntry> has an empty {empty}: it maps no parameter "
                         "and is skipped")
            continue
        out.append(MappingEntry(src, dst, transformation(entry, file), where(entry, file)))
    return out


def binding_values(binding, ssd_path: Path, notes: list[str]) -> list[BoundValue]:
    """The values one ``ssd:ParameterBinding`` gives, in file order (see the module docstring)."""
    pset, file = _parameter_set(binding, ssd_path, notes)
    units: dict[str, UnitDefinition] = unit_definitions(child(pset, "ssv:Units"), file)
    prefix = binding.get("prefix") or ""
    mapping = _mapping(binding, ssd_path, notes)
    out = []
    unmapped = []
    params = child(pset, "ssv:Parameters")
    for p in children(params, "ssv:Parameter") if params is not None else []:
        name = p.get("name")
        if not name:
            raise element_error(p, file, "has no name (SSP 1.0 requires one)", "give the parameter a name")
        kind, value, unit = parameter_value(p, file)
        name = prefix + name
        if mapping is None:
            out.append(BoundValue(name, kind, value, unit, where(p, file), units))
            continue
        entries = [e for e in mapping if e.source == name]
        if not entries:
            unmapped.append(f"{name} ({where(p, file)})")
        for e in entries:
            _check_transform(e.transformation, kind, p, file)
            out.append(BoundValue(e.target, kind, value, unit, where(p, file), units, e.transformation))
    if unmapped:
        notes.append(f"{where(binding, ssd_path)}: the binding has a parameter mapping, so its parameter values "
                     f"without a mapping entry are not applied (SSP 1.0, 5.2.3): {', '.join(unmapped)}")
    return out


def _check_transform(transform, kind: str, el, file: Path) -> None:
    if transform is None:
        return
    if isinstance(transform, LinearTransformation):
        if kind != "Real":
            raise element_error(el, file, f"is {kind}: a LinearTransformation applies to Real parameters only "
                                "(SSP 1.0)", "use an Integer/Boolean/Enumeration mapping transformation in the "
                                "mapping entry, or give a Real value")
    elif transform.kind != kind:
        raise element_error(el, file, f"is {kind}: a {transform.kind} mapping does not apply to it (SSP 1.0: "
                            "the mapping's type must be the parameter's)",
                            f"use a {kind} mapping in the mapping entry or give a {transform.kind} value")


def bindings_of(el, ssd_path: Path, notes: list[str]) -> list[list[BoundValue]]:
    """The values of every ``ssd:ParameterBinding`` of a component or system, in order."""
    holder = child(el, "ssd:ParameterBindings")
    if holder is None:
        return []
    return [binding_values(b, ssd_path, notes) for b in children(holder, "ssd:ParameterBinding")]

