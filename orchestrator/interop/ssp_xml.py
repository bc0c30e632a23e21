"""SSP 1.0 files as dtcosim reads them: parsing with line numbers, the elements dtcosim supports, values, units.

Every SSP file (``.ssd``, ``.ssv``, ``.ssm``) is parsed with lxml, which keeps
each element's line. :func:`check_supported` walks a document before anything
is interpreted and refuses the first element dtcosim does not support (a signal
dictionary, a Binary connector, ...) with an :class:`~orchestrator.errors.SspError`
naming the element, the file and the line: nothing in an SSP is silently
dropped. Layout-only elements (geometry, graphical notes) carry no simulation
meaning and are passed over; annotations are read where dtcosim knows them (the
OSP and dtcosim ones in ``ssd:DefaultExperiment``) and reported as notes
otherwise (SSP 1.0: tools ignore annotations they do not know).
"""

from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from lxml import etree

from ..archive_members import shown_path
from ..errors import SspError
from ..inputs.limits import MAX_SSP_XML_BYTES
from ..inputs.transformations import LinearTransformation, MappingTransformation, Transformation

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "ssm": "http://ssp-standard.org/SSP1/SystemStructureParameterMapping",
    "osp": "https://opensimulationplatform.com/SSP/OSPAnnotations",
    "dtc": "https://dtcosim.org/SSP/Annotations",
}
PREFIX = {uri: prefix for prefix, uri in NS.items()}
#: the OSP annotation namespace as libcosim accepts it (the same name under http and https)
OSP_NAMESPACES = ("https://opensimulationplatform.com/SSP/OSPAnnotations",
                  "http://opensimulationplatform.com/SSP/OSPAnnotations")
OSP_ANNOTATION = "com.opensimulationplatform"
DTCOSIM_ANNOTATION = "org.dtcosim.scenario"
#: a parameter value dtcosim's initialisation computed (an exported [[initial]] binding)
COMPUTED_ANNOTATION = "org.dtcosim.computed"

_TRANSFORMATIONS = {"ssc:LinearTransformation", "ssc:BooleanMappingTransformation",
                    "ssc:IntegerMappingTransformation", "ssc:EnumerationMappingTransformation"}
_ANNOTATIONS = {"ssd:Annotations", "ssc:Annotations", "ssv:Annotations", "ssm:Annotations"}
#: layout only: no meaning for a simulation
LAYOUT = {"ssd:ElementGeometry", "ssd:ConnectorGeometry", "ssd:ConnectionGeometry", "ssd:SystemGeometry",
          "ssd:GraphicalElements"}
_VALUES = {"ssv:Real", "ssv:Integer", "ssv:Boolean", "ssv:String", "ssv:Enumeration"}
#: element -> the child elements dtcosim supports (SSP 1.0)
SUPPORTED_CHILDREN: dict[str, set[str]] = {
    "ssd:SystemStructureDescription": {"ssd:System", "ssd:Enumerations", "ssd:Units", "ssd:DefaultExperiment"},
    "ssd:System": {"ssd:Connectors", "ssd:ParameterBindings", "ssd:Elements", "ssd:Connections"},
    "ssd:Elements": {"ssd:Component", "ssd:System"},
    "ssd:Component": {"ssd:Connectors", "ssd:ParameterBindings"},
    "ssd:Connectors": {"ssd:Connector"},
    "ssd:Connector": {"ssc:Real", "ssc:Integer", "ssc:Boolean", "ssc:String", "ssc:Enumeration"},
    "ssc:Real": set(), "ssc:Integer": set(), "ssc:Boolean": set(), "ssc:String": set(), "ssc:Enumeration": set(),
    "ssd:ParameterBindings": {"ssd:ParameterBinding"},
    "ssd:ParameterBinding": {"ssd:ParameterValues", "ssd:ParameterMapping"},
    "ssd:ParameterValues": {"ssv:ParameterSet"},
    "ssd:ParameterMapping": {"ssm:ParameterMapping"},
    "ssv:ParameterSet": {"ssv:Parameters", "ssv:Units", "ssv:Enumerations"},
    "ssv:Parameters": {"ssv:Parameter"},
    "ssv:Parameter": set(_VALUES),
    **{v: set() for v in _VALUES},
    "ssv:Units": {"ssc:Unit"}, "ssd:Units": {"ssc:Unit"}, "ssc:Unit": {"ssc:BaseUnit"}, "ssc:BaseUnit": set(),
    "ssv:Enumerations": {"ssc:Enumeration"}, "ssd:Enumerations": {"ssc:Enumeration"},
    "ssc:Item": set(),
    "ssm:ParameterMapping": {"ssm:MappingEntry"},
    "ssm:MappingEntry": set(_TRANSFORMATIONS),
    "ssd:Connections": {"ssd:Connection"},
    "ssd:Connection": set(_TRANSFORMATIONS),
    "ssc:LinearTransformation": set(),
    "ssc:BooleanMappingTransformation": {"ssc:MapEntry"}, "ssc:IntegerMappingTransformation": {"ssc:MapEntry"},
    "ssc:EnumerationMappingTransformation": {"ssc:MapEntry"}, "ssc:MapEntry": set(),
    "ssd:DefaultExperiment": set(),
}


def tag(el) -> str:
    """``prefix:local`` of an element (the namespace URI in braces when it is not an SSP one)."""
    qname = etree.QName(el)
    prefix = PREFIX.get(qname.namespace)
    return f"{prefix}:{qname.localname}" if prefix else el.tag


def where(el, path: Path | str) -> str:
    """``<file>, line <n>`` of an element (a file of an ``.ssp`` as ``<archive>!<member>``)."""
    return f"{shown_path(path)}, line {el.sourceline}"


def element_error(el, path: Path | str, problem: str, remedy: str) -> SspError:
    """An SspError naming the element, its file and line, what is wrong (the rule or the feature) and the remedy.

    ``problem`` says which rule of SSP 1.0 the element breaks or which feature
    dtcosim does not support; ``remedy`` what the user can do about it.
    """
    return SspError(f"{where(el, path)}: <{tag(el)}> {problem}; {remedy}")


def parse(path: Path) -> Any:
    """The root element of an SSP XML file (lxml, with line numbers); only a regular file of at most
    :data:`~orchestrator.inputs.limits.MAX_SSP_XML_BYTES` is read."""
    shown = shown_path(path)  # a file of an .ssp as <archive>!<member>
    try:
        info = os.stat(path)
    except OSError as exc:
        raise SspError(f"{shown}: cannot be read ({exc.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise SspError(f"{shown}: not a regular file (a device, pipe or folder); name the SSP file itself") from None
    if info.st_size > MAX_SSP_XML_BYTES:
        raise SspError(f"{shown}: {info.st_size / 2**20:.0f} MiB, expected at most {MAX_SSP_XML_BYTES >> 20} MiB for "
                       "one SSP XML file") from None
    try:
        return etree.parse(str(path), etree.XMLParser(remove_blank_text=False, resolve_entities=False)).getroot()
    except OSError as exc:
        raise SspError(f"{shown}: cannot be read ({exc})") from None
    except etree.XMLSyntaxError as exc:
        raise SspError(f"{shown}: not valid XML ({exc})") from None


def check_supported(root, path: Path, notes: list[str]) -> None:
    """Refuse the first element dtcosim does not support; note the annotations it will not read.

    Raises
    ------
    SspError
        Naming the element, the file and the line, and what its parent may hold.
    """
    def visit(el) -> None:
        name = tag(el)
        for child in el:
            if not isinstance(child.tag, str):  # comments, processing instructions
                continue
            child_name = tag(child)
            if child_name in LAYOUT:
                continue
            if child_name in _ANNOTATIONS:
                for annotation in child:
                    if isinstance(annotation.tag, str) and not _known_annotation(child_name, annotation):
                        notes.append(f"{where(annotation, path)}: annotation of type "
                                     f"{annotation.get('type')!r} ignored (SSP: tool-specific)")
                continue
            if child_name == "ssd:Note" and name == "ssd:GraphicalElements":
                continue
            if name == "ssc:Enumeration" and child_name == "ssc:Item":
                continue
            allowed = SUPPORTED_CHILDREN.get(name)
            if allowed is None or child_name not in allowed:
                raise element_error(child, path, f"is not supported by dtcosim (inside <{name}>"
                                    + (f" it reads {', '.join(sorted(allowed))}" if allowed else "") + ")",
                                    "remove the element or express it with what dtcosim reads (docs/orchestrator.md, "
                                    "'SSP export and import')")
            visit(child)

    visit(root)


def _known_annotation(parent: str, annotation) -> bool:
    holder = annotation.getparent().getparent()
    if parent == "ssv:Annotations" and holder is not None and tag(holder) == "ssv:Parameter":
        return annotation.get("type") == COMPUTED_ANNOTATION  # the import restores the [[initial]] binding
    return parent == "ssd:Annotations" and holder is not None and tag(holder) == "ssd:DefaultExperiment" \
        and annotation.get("type") in (OSP_ANNOTATION, DTCOSIM_ANNOTATION)


def children(el, name: str) -> list:
    """Child elements called ``prefix:local``."""
    return [c for c in el if isinstance(c.tag, str) and tag(c) == name]


def child(el, name: str):
    """The first child element called ``prefix:local`` (None if absent)."""
    found = children(el, name)
    return found[0] if found else None


def float_attr(el, name: str, path: Path | str, default: float | None = None) -> float | None:
    """A finite number attribute (xs:double spellings INF/-INF are refused)."""
    value = el.get(name)
    if value is None:
        return default
    try:
        out = float(value)
    except ValueError:
        raise element_error(el, path, f"attribute {name}={value!r} is not a number (an xs:double)",
                            "write a decimal number such as 0.02 or 2e-2") from None
    if not math.isfinite(out):
        raise element_error(el, path, f"attribute {name}={value!r} is not finite (dtcosim needs a finite "
                            "number here)", "write a finite decimal number")
    return out


def int_attr(el, name: str, path: Path | str, default: int | None = None) -> int | None:
    """A whole-number attribute (xs:int spelling)."""
    value = el.get(name)
    if value is None:
        return default
    try:
        return int(value.strip())
    except ValueError:
        raise element_error(el, path, f"attribute {name}={value!r} is not a whole number (an xs:int)",
                            "write an integer such as 40") from None


def bool_text(value: str, el, path: Path | str) -> bool:
    text = value.strip()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise element_error(el, path, f"value {value!r} is not an xs:boolean (SSP 1.0 schema)",
                        "write true, false, 1 or 0")


def parameter_value(param, path: Path | str) -> tuple[str, Any, str]:
    """(type, value, unit) of an ``ssv:Parameter``: Real float, Integer int, Boolean bool, String/Enumeration str."""
    for value_el in param:
        if not isinstance(value_el.tag, str) or tag(value_el) not in _VALUES:
            continue
        kind = tag(value_el).split(":")[1]
        text = value_el.get("value")
        if text is None:
            raise element_error(value_el, path, "has no value attribute (SSP 1.0 requires one)",
                                "give the parameter's value in a value attribute")
        try:
            if kind == "Real":
                value = float(text)
            elif kind == "Integer":
                value = int(text)
            elif kind == "Boolean":
                value = bool_text(text, value_el, path)
            else:
                value = text
        except ValueError:
            raise element_error(value_el, path, f"value {text!r} is not a valid {kind} (SSP 1.0 schema)",
                                f"write a {kind} value or change the element's type") from None
        return kind, value, value_el.get("unit") or ""
    raise element_error(param, path, "has no ssv:Real, ssv:Integer, ssv:Boolean, ssv:String or ssv:Enumeration "
                        "value (dtcosim reads these; ssv:Binary is not supported)",
                        "give the value as one of these elements or remove the parameter")


def transformation(el, path: Path | str) -> Transformation | None:
    """The transformation child of a connection or mapping entry (None if it has none)."""
    for t in el:
        if not isinstance(t.tag, str) or tag(t) not in _TRANSFORMATIONS:
            continue
        name = tag(t)
        if name == "ssc:LinearTransformation":
            return LinearTransformation(float_attr(t, "factor", path, 1.0), float_attr(t, "offset", path, 0.0))
        kind = name.split(":")[1].replace("MappingTransformation", "")
        entries = []
        for entry in children(t, "ssc:MapEntry"):
            pair = []
            for side in ("source", "target"):
                text = entry.get(side)
                if text is None:
                    raise element_error(entry, path, f"has no {side} attribute (SSP 1.0 requires source and "
                                        "target)", f"add the {side} value of the map entry")
                if kind == "Boolean":
                    pair.append(bool_text(text, entry, path))
                elif kind == "Integer":
                    try:
                        pair.append(int(text))
                    except ValueError:
                        raise element_error(entry, path, f"{side}={text!r} is not an integer (an "
                                            "IntegerMappingTransformation maps xs:int values)",
                                            f"write an integer {side}") from None
                else:
                    pair.append(text)
            entries.append(tuple(pair))
        if not entries:
            raise element_error(t, path, "has no ssc:MapEntry (SSP 1.0: a mapping needs at least one)",
                                "add the map entries or remove the transformation")
        return MappingTransformation(kind, tuple(entries))
    return None


@dataclass(frozen=True)
class UnitDefinition:
    """An ``ssc:Unit``: SI base-unit exponents and ``SI value = factor * value + offset``."""

    exponents: tuple[tuple[str, int], ...]
    factor: float = 1.0
    offset: float = 0.0


_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def unit_definitions(units_el, path: Path | str) -> dict[str, UnitDefinition]:
    """The ``ssc:Unit`` entries of an ``ssd:Units`` or ``ssv:Units`` element by name."""
    out: dict[str, UnitDefinition] = {}
    if units_el is None:
        return out
    for unit in children(units_el, "ssc:Unit"):
        base = child(unit, "ssc:BaseUnit")
        if unit.get("name") is None or base is None:
            raise element_error(unit, path, "needs a name and an ssc:BaseUnit (SSP 1.0 schema)",
                                "give the unit a name and its SI base-unit exponents in ssc:BaseUnit")
        exps = []
        for k in _BASE:
            if base.get(k) not in (None, "0"):
                try:
                    exps.append((k, int(base.get(k))))
                except ValueError:
                    raise element_error(base, path, f"exponent {k}={base.get(k)!r} is not an integer (SSP 1.0 "
                                        "schema: xs:int)", "write the exponent as an integer") from None
        out[unit.get("name")] = UnitDefinition(tuple(exps), float_attr(base, "factor", path, 1.0),
                                               float_attr(base, "offset", path, 0.0))
    return out


def unit_conversion(source_unit: str, target_unit: str, units: Mapping[str, UnitDefinition]):
    """The LinearTransformation from ``source_unit`` to ``target_unit``, None if equal; raises ValueError if unknown."""
    if not source_unit or not target_unit or source_unit == target_unit:
        return None
    a, b = units.get(source_unit), units.get(target_unit)
    if a is None or b is None:
        missing = source_unit if a is None else target_unit
        raise ValueError(f"unit {missing!r} has no ssc:Unit definition to convert {source_unit} to {target_unit}")
    if a.exponents != b.exponents:
        raise ValueError(f"units {source_unit} and {target_unit} have different SI dimensions")
    # SI = fa * x + oa = fb * y + ob  ->  y = (fa / fb) x + (oa - ob) / fb
    return LinearTransformation(a.factor / b.factor, (a.offset - b.offset) / b.factor)
