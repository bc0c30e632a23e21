"""An SSP 1.0 ``ssd:System`` tree flattened into components, connections and parameter values.

Nested systems
--------------
Every FMU component of every nested ``ssd:System`` becomes one component of the
flat system, named by its path with ``-`` between the levels (``drive-motor`` for
component ``motor`` in system ``drive``; characters other than letters, digits,
``_`` and ``-`` become ``_``). Connections through system connectors are followed
to their ends: an output of one FMU reaching inputs of others through any number
of system levels is one connection per input, with the transformations on the way
chained in the direction of the data (and unit conversions between connectors of
different units, ``ssd:Units``, before each connection's own transformation,
unless ``suppressUnitConversion``). A ``calculatedParameter`` reaching a
``parameter`` is an initialisation binding (``[[initial]]``).

Direction
---------
SSP 1.0 (``ssd:Connection``): data flows from an output/calculatedParameter to an
input/parameter; for a connection between a system's own connector and an element
inside it the kinds match, so an ``input`` connector of the system is where data
enters and an ``output`` connector where it leaves.

Parameter values
----------------
Bindings of a component name its variables; bindings of a system name the
system's connectors (the value reaches the variables those connectors lead to)
or ``element.name`` of its elements (hierarchically: ``B.C.P2``). Precedence
(SSP 1.0): at one level a later binding over an earlier one; a system's bindings
over those of its elements. A name that reaches no variable is an error naming
the parameter's file and line (SSP 1.0 lets tools ignore it; dtcosim does not
drop anything silently).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SspError
from ..inputs.transformations import LinearTransformation, Transformation, compose
from .ssp_parameters import BoundValue, bindings_of
from .ssp_xml import (
    UnitDefinition,
    child,
    children,
    element_error,
    tag,
    transformation,
    unit_conversion,
    where,
)

FMU_TYPE = "application/x-fmu-sharedlibrary"
CONNECTOR_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")
SOURCE_KINDS = ("output", "calculatedParameter")
TARGET_KINDS = ("input", "parameter")


@dataclass(frozen=True)
class Connector:
    """An ``ssd:Connector``: kind, type, unit and where it is."""

    kind: str
    type: str
    unit: str
    origin: str


@dataclass
class FlatSystem:
    """What :func:`flatten` found.

    Attributes
    ----------
    components : dict of str -> str
        Flat component name -> the FMU source (relative to the SSD).
    connections : list of (source (comp, var), target (comp, var), transformation or None, origin)
    initial : list of (source (comp, var), target (comp, var), origin)
    values : dict of (comp, var) -> (value, origin)
        Parameter values after the SSP precedence rules.
    """

    components: dict[str, str] = field(default_factory=dict)
    connections: list = field(default_factory=list)
    initial: list = field(default_factory=list)
    values: dict = field(default_factory=dict)
    # internal: node -> Connector; directed edges node -> [(node, transformation, origin)]
    nodes: dict = field(default_factory=dict)
    edges: dict = field(default_factory=dict)
    elements: dict = field(default_factory=dict)  # system id -> its elements


def _flat_name(path: tuple[str, ...]) -> str:
    return "-".join(re.sub(r"[^A-Za-z0-9_\-]", "_", p) for p in path)


def _connectors(el, path: Path) -> dict[str, Connector]:
    out = {}
    holder = child(el, "ssd:Connectors")
    for con in children(holder, "ssd:Connector") if holder is not None else []:
        name, kind = con.get("name"), con.get("kind")
        if not name or not kind:
            raise element_error(con, path, "needs a name and a kind")
        if kind not in SOURCE_KINDS + TARGET_KINDS:
            raise element_error(con, path, f"kind {kind!r} is not supported (input, output, parameter, "
                                           f"calculatedParameter)")
        typed = [c for c in con if isinstance(c.tag, str) and tag(c).split(":")[1] in CONNECTOR_TYPES]
        fmi_type = tag(typed[0]).split(":")[1] if typed else ""
        unit = typed[0].get("unit", "") if typed else ""
        if name in out:
            raise element_error(con, path, f"duplicates connector {name!r}")
        out[name] = Connector(kind, fmi_type, unit, where(con, path))
    return out


def flatten(root, ssd_path: Path, units: dict[str, UnitDefinition], notes: list[str]) -> FlatSystem:
    """Flatten the ``ssd:System`` of a ``ssd:SystemStructureDescription`` (see the module docstring)."""
    systems = children(root, "ssd:System")
    if len(systems) != 1:
        raise element_error(root, ssd_path, "must hold exactly one ssd:System")
    flat = FlatSystem()
    _read_system(systems[0], (), flat, ssd_path, units, notes)
    _collect_links(flat, ssd_path)
    return flat


def _node_role(node, kind: str, own: bool) -> str | None:
    if own:  # the system's own connector, seen from inside
        return "source" if kind in TARGET_KINDS else "target"
    return "source" if kind in SOURCE_KINDS else "target"


def _read_system(sys_el, prefix: tuple[str, ...], flat: FlatSystem, ssd_path: Path,
                 units: dict[str, UnitDefinition], notes: list[str]) -> None:
    sys_id = "/".join(prefix)
    for name, con in _connectors(sys_el, ssd_path).items():
        flat.nodes[("S", sys_id, name)] = con
    elements: dict[str, tuple[str, str]] = {}  # element name -> ("C", flat name) | ("S", system id)
    holder = child(sys_el, "ssd:Elements")
    for el in (holder if holder is not None else []):
        if not isinstance(el.tag, str):
            continue
        name = el.get("name")
        if not name:
            raise element_error(el, ssd_path, "has no name")
        if name in elements:
            raise element_error(el, ssd_path, f"duplicates element name {name!r}")
        if tag(el) == "ssd:System":
            sub_id = "/".join(prefix + (name,))
            elements[name] = ("S", sub_id)
            _read_system(el, prefix + (name,), flat, ssd_path, units, notes)
            continue
        kind = el.get("type") or FMU_TYPE
        if kind != FMU_TYPE:
            raise element_error(el, ssd_path, f"type {kind!r} is not supported (only FMUs, {FMU_TYPE})")
        if (el.get("implementation") or "any") not in ("any", "CoSimulation"):
            raise element_error(el, ssd_path, f"implementation {el.get('implementation')!r} is not supported "
                                              "(dtcosim runs co-simulation FMUs)")
        source = el.get("source")
        if not source:
            raise element_error(el, ssd_path, "has no source")
        flat_name = _flat_name(prefix + (name,))
        if flat_name in flat.components:
            raise element_error(el, ssd_path, f"flattens to the name {flat_name!r} of another component")
        flat.components[flat_name] = source
        elements[name] = ("C", flat_name)
        for var, con in _connectors(el, ssd_path).items():
            flat.nodes[("C", flat_name, var)] = con
        for values in bindings_of(el, ssd_path, notes):
            for v in values:
                _assign(flat, ("C", flat_name), v.name, v, el, ssd_path, units)
    flat.elements[sys_id] = elements
    conns = child(sys_el, "ssd:Connections")
    for con in children(conns, "ssd:Connection") if conns is not None else []:
        ends = []
        for side in ("start", "end"):
            element, connector = con.get(f"{side}Element"), con.get(f"{side}Connector")
            if not connector:
                raise element_error(con, ssd_path, f"has no {side}Connector")
            if element is None:
                node, own = ("S", sys_id, connector), True
            elif element in elements:
                kind_, ident = elements[element]
                node, own = ((kind_, ident, connector) if kind_ == "C" else ("S", ident, connector)), False
            else:
                raise element_error(con, ssd_path, f"{side}Element {element!r} is not an element of system "
                                                   f"{sys_el.get('name')!r} ({', '.join(elements) or 'none'})")
            if node not in flat.nodes:
                owner = element or f"system {sys_el.get('name')!r}"
                raise element_error(con, ssd_path, f"{side}Connector {connector!r} is not a connector of {owner}")
            ends.append((node, _node_role(node, flat.nodes[node].kind, own)))
        roles = sorted(r for _, r in ends)
        if roles != ["source", "target"]:
            raise element_error(con, ssd_path, "joins two connectors that both " +
                                ("provide" if roles[0] == "source" else "receive") + " data (see the kinds)")
        (src, _), (dst, _) = sorted(ends, key=lambda e: e[1] != "source")
        a, b = flat.nodes[src], flat.nodes[dst]
        if a.type and b.type and a.type != b.type:
            raise element_error(con, ssd_path, f"joins a {a.type} and a {b.type} connector")
        transform = transformation(con, ssd_path)
        if con.get("suppressUnitConversion") not in ("true", "1"):
            try:
                transform = compose(unit_conversion(a.unit, b.unit, units), transform)
            except ValueError as exc:
                raise element_error(con, ssd_path, str(exc)) from None
        flat.edges.setdefault(src, []).append((dst, transform, where(con, ssd_path)))
    for values in bindings_of(sys_el, ssd_path, notes):
        for v in values:
            _assign(flat, ("S", sys_id), v.name, v, sys_el, ssd_path, units, elements)


def _reach(flat: FlatSystem, node, transform: Transformation | None = None, seen=None):
    """Component nodes the data of ``node`` reaches, with the chained transformation."""
    seen = set() if seen is None else seen
    out = []
    for dst, t, _ in flat.edges.get(node, ()):
        if dst in seen:
            continue
        seen.add(dst)
        chained = compose(transform, t)
        if dst[0] == "C":
            out.append((dst, chained))
        else:
            out += _reach(flat, dst, chained, seen)
    return out


def _assign(flat: FlatSystem, owner, name: str, v: BoundValue, el, ssd_path: Path,
            units: dict[str, UnitDefinition], elements: dict | None = None) -> None:
    """Give value ``v`` to what ``name`` means in a component or system (overriding earlier values)."""
    if owner[0] == "C":
        targets = [(("C", owner[1], name), None)]
    else:
        targets = _resolve_in_system(flat, owner[1], name, elements or {})
        if not targets:
            raise SspError(f"{v.origin}: parameter {v.name!r} reaches no variable of system "
                           f"{owner[1] or el.get('name')!r}: it is neither a connector of the system nor "
                           f"element.name of one of its elements")
    for node, transform in targets:
        connector = flat.nodes.get(node)
        conversion = None
        if v.type == "Real" and v.unit and connector is not None and connector.unit and connector.unit != v.unit:
            try:
                conversion = unit_conversion(v.unit, connector.unit, {**units, **v.units})
            except ValueError as exc:
                raise SspError(f"{v.origin}: parameter {v.name!r}: {exc}") from None
        value = v.target_value(conversion)
        if transform is not None:
            if isinstance(transform, LinearTransformation) and v.type != "Real":
                raise SspError(f"{v.origin}: parameter {v.name!r} is {v.type}; the connection to "
                               f"{node[1]}.{node[2]} has a linear transformation")
            value = transform.apply(value)
        flat.values[(node[1], node[2])] = (value, v.origin)


def _resolve_in_system(flat: FlatSystem, sys_id: str, name: str, elements: dict) -> list:
    node = ("S", sys_id, name)
    if node in flat.nodes:
        return _reach(flat, node)
    # element.rest: the longest element name that is a prefix
    for element in sorted(elements, key=len, reverse=True):
        if name.startswith(element + "."):
            rest = name[len(element) + 1:]
            kind, ident = elements[element]
            if kind == "C":
                return [(("C", ident, rest), None)]
            return _resolve_in_system(flat, ident, rest, flat.elements[ident])
    return []


def _collect_links(flat: FlatSystem, ssd_path: Path) -> None:
    for node, con in flat.nodes.items():
        if node[0] != "C" or con.kind not in SOURCE_KINDS:
            continue
        for (kind, comp, var), transform in _reach(flat, node):
            target = flat.nodes[(kind, comp, var)]
            link = ((node[1], node[2]), (comp, var))
            if target.kind == "input":
                if con.kind != "output":
                    raise SspError(f"{target.origin}: input {comp}.{var} is driven by calculatedParameter "
                                   f"{node[1]}.{node[2]}: not supported (connect an output)")
                flat.connections.append((*link, transform, target.origin))
            elif target.kind == "parameter":
                if transform is not None:
                    raise SspError(f"{target.origin}: parameter {comp}.{var} is set at initialisation from "
                                   f"{node[1]}.{node[2]} through a transformation: not supported")
                flat.initial.append((*link, target.origin))
            else:
                raise SspError(f"{target.origin}: {comp}.{var} (kind {target.kind}) cannot receive data")

