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
over those of its elements. A name that reaches no variable (no connector or
element of that name, a system connector connected to nothing, a connector of an
empty subsystem) is ignored, as SSP 1.0, 5.2.3 prescribes ("If a parameter
matching this name is found in the system, the parameter value is applied.
Otherwise that parameter value is ignored."): :attr:`FlatSystem.ignored` lists it
with its file and line, and the import reports it (the run's summary lists it).
A component's binding naming a variable its FMU does not have is ignored the same
way by the import, which reads the FMU's model description.

Types
-----
SSP 1.0 gives ``Enumeration`` the underlying type ``Integer``: an Integer and an
Enumeration connector connect (either direction); other different types do not.
``startElement=""``/``endElement=""`` (as OMSimulator writes for a system's own
connectors) mean the attribute is absent: the system's own connector.
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
    ignored : list of str
        Parameter values whose name reaches no variable: ``"<name> (<file>, line <n>): <why>"``.
    """

    components: dict[str, str] = field(default_factory=dict)
    connections: list = field(default_factory=list)
    initial: list = field(default_factory=list)
    values: dict = field(default_factory=dict)
    ignored: list = field(default_factory=list)
    # internal: node -> Connector; directed edges node -> [(node, transformation, origin)]
    nodes: dict = field(default_factory=dict)
    edges: dict = field(default_factory=dict)
    elements: dict = field(default_factory=dict)  # system id -> its elements
    system_names: dict = field(default_factory=dict)  # system id -> its name


def _flat_name(path: tuple[str, ...]) -> str:
    return "-".join(re.sub(r"[^A-Za-z0-9_\-]", "_", p) for p in path)


def _connectors(el, path: Path) -> dict[str, Connector]:
    out = {}
    holder = child(el, "ssd:Connectors")
    for con in children(holder, "ssd:Connector") if holder is not None else []:
        name, kind = con.get("name"), con.get("kind")
        if not name or not kind:
            raise element_error(con, path, "needs a name and a kind (SSP 1.0 schema)",
                                "give the connector its name and kind (input, output, parameter, calculatedParameter)")
        if kind not in SOURCE_KINDS + TARGET_KINDS:
            raise element_error(con, path, f"kind {kind!r} is not supported (dtcosim reads input, output, "
                                           "parameter, calculatedParameter)",
                                "give the connector one of these kinds or remove it")
        typed = [c for c in con if isinstance(c.tag, str) and tag(c).split(":")[1] in CONNECTOR_TYPES]
        fmi_type = tag(typed[0]).split(":")[1] if typed else ""
        unit = typed[0].get("unit", "") if typed else ""
        if name in out:
            raise element_error(con, path, f"duplicates connector {name!r} (SSP 1.0: connector names are unique "
                                           "in their element)", "rename or remove one of them")
        out[name] = Connector(kind, fmi_type, unit, where(con, path))
    return out


def flatten(root, ssd_path: Path, units: dict[str, UnitDefinition], notes: list[str]) -> FlatSystem:
    """Flatten the ``ssd:System`` of a ``ssd:SystemStructureDescription`` (see the module docstring)."""
    systems = children(root, "ssd:System")
    if len(systems) != 1:
        raise element_error(root, ssd_path, "must hold exactly one ssd:System (SSP 1.0 schema)",
                            "put the system's elements into one ssd:System")
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
    flat.system_names[sys_id] = sys_el.get("name") or sys_id
    for name, con in _connectors(sys_el, ssd_path).items():
        flat.nodes[("S", sys_id, name)] = con
    elements: dict[str, tuple[str, str]] = {}  # element name -> ("C", flat name) | ("S", system id)
    holder = child(sys_el, "ssd:Elements")
    for el in (holder if holder is not None else []):
        if not isinstance(el.tag, str):
            continue
        name = el.get("name")
        if not name:
            raise element_error(el, ssd_path, "has no name (SSP 1.0 requires one)", "give the element a name")
        if name in elements:
            raise element_error(el, ssd_path, f"duplicates element name {name!r} (SSP 1.0: element names are "
                                              "unique in their system)", "rename one of them")
        if tag(el) == "ssd:System":
            sub_id = "/".join(prefix + (name,))
            elements[name] = ("S", sub_id)
            _read_system(el, prefix + (name,), flat, ssd_path, units, notes)
            continue
        kind = el.get("type") or FMU_TYPE
        if kind != FMU_TYPE:
            raise element_error(el, ssd_path, f"type {kind!r} is not supported (dtcosim runs FMUs, {FMU_TYPE}; "
                                              "no nested SSPs or SSDs)",
                                "export the element as an FMU, or copy its system into this SSD as an ssd:System")
        if (el.get("implementation") or "any") not in ("any", "CoSimulation"):
            raise element_error(el, ssd_path, f"implementation {el.get('implementation')!r} is not supported "
                                              "(dtcosim runs co-simulation FMUs)",
                                'export the model as an FMI 2.0 co-simulation FMU (implementation="CoSimulation")')
        source = el.get("source")
        if not source:
            raise element_error(el, ssd_path, "has no source (SSP 1.0: a component names its FMU)",
                                'name the FMU in source, e.g. source="resources/model.fmu"')
        flat_name = _flat_name(prefix + (name,))
        if flat_name in flat.components:
            raise element_error(el, ssd_path, f"flattens to the name {flat_name!r} of another component (dtcosim "
                                              "names a nested component by its path with '-')",
                                "rename the element or the system it is in")
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
            # an empty startElement/endElement (OMSimulator writes it for the system's own connectors) means absent
            element, connector = con.get(f"{side}Element") or None, con.get(f"{side}Connector")
            if not connector:
                raise element_error(con, ssd_path, f"has no {side}Connector (SSP 1.0 requires one)",
                                    f"name the connector in {side}Connector")
            if element is None:
                node, own = ("S", sys_id, connector), True
            elif element in elements:
                kind_, ident = elements[element]
                node, own = ((kind_, ident, connector) if kind_ == "C" else ("S", ident, connector)), False
            else:
                raise element_error(con, ssd_path, f"{side}Element {element!r} is not an element of system "
                                                   f"{sys_el.get('name')!r} ({', '.join(elements) or 'none'}; SSP "
                                                   "1.0: a connection joins elements of its own system)",
                                    f"name one of these elements, or leave {side}Element out for the system's own "
                                    "connector")
            if node not in flat.nodes:
                owner = element or f"system {sys_el.get('name')!r}"
                raise element_error(con, ssd_path, f"{side}Connector {connector!r} is not a connector of {owner} "
                                                   "(SSP 1.0: a connection joins declared connectors)",
                                    f"declare the connector in {owner}'s ssd:Connectors or correct the name")
            ends.append((node, _node_role(node, flat.nodes[node].kind, own)))
        roles = sorted(r for _, r in ends)
        if roles != ["source", "target"]:
            raise element_error(con, ssd_path, "joins two connectors that both " +
                                ("provide" if roles[0] == "source" else "receive") + " data (SSP 1.0: data flows "
                                "from an output or calculatedParameter to an input or parameter)",
                                "check the connectors' kinds and the connection's direction")
        (src, _), (dst, _) = sorted(ends, key=lambda e: e[1] != "source")
        a, b = flat.nodes[src], flat.nodes[dst]
        if a.type and b.type and a.type != b.type and {a.type, b.type} != {"Integer", "Enumeration"}:
            raise element_error(con, ssd_path, f"joins a {a.type} and a {b.type} connector (SSP 1.0: connected "
                                               "connectors have the same type; Enumeration's is Integer)",
                                "connect connectors of one type, or convert the value in an FMU between them")
        transform = transformation(con, ssd_path)
        if con.get("suppressUnitConversion") not in ("true", "1"):
            try:
                transform = compose(unit_conversion(a.unit, b.unit, units), transform)
            except ValueError as exc:
                raise element_error(con, ssd_path, f"{exc} (SSP 1.0: connected Real connectors of different "
                                                   "units are converted)",
                                    'define both units in ssd:Units, or set suppressUnitConversion="true"') from None
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
    """Give value ``v`` to what ``name`` means in a component or system (overriding earlier values).

    A name that reaches no variable is ignored (SSP 1.0, 5.2.3) and listed in ``flat.ignored``.
    """
    if owner[0] == "C":
        targets = [(("C", owner[1], name), None)]
    else:
        targets, why = _resolve_in_system(flat, owner[1], name, elements or {})
        if not targets:
            flat.ignored.append(f"{v.name} ({v.origin}): {why}")
            return
    for node, transform in targets:
        connector = flat.nodes.get(node)
        conversion = None
        if v.type == "Real" and v.unit and connector is not None and connector.unit and connector.unit != v.unit:
            try:
                conversion = unit_conversion(v.unit, connector.unit, {**units, **v.units})
            except ValueError as exc:
                raise SspError(f"{v.origin}: <ssv:Parameter> {v.name!r}: {exc} (SSP 1.0: a value is converted to its "
                               "connector's unit); define the unit in the parameter set's ssv:Units or the SSD's "
                               "ssd:Units, or give the value in the connector's unit") from None
        value = v.target_value(conversion)
        if transform is not None:
            if isinstance(transform, LinearTransformation) and v.type != "Real":
                raise SspError(f"{v.origin}: <ssv:Parameter> {v.name!r} is {v.type}; the connection to "
                               f"{node[1]}.{node[2]} has a linear transformation (SSP 1.0: for Real values only); "
                               "give a Real value or use a mapping transformation on the connection")
            value = transform.apply(value)
        flat.values[(node[1], node[2])] = (value, v.origin)


def _resolve_in_system(flat: FlatSystem, sys_id: str, name: str, elements: dict) -> tuple[list, str]:
    """(component nodes ``name`` reaches in system ``sys_id`` with the chained transformations, why none if empty)."""
    node = ("S", sys_id, name)
    system = flat.system_names.get(sys_id, sys_id)
    if node in flat.nodes:
        reached = _reach(flat, node)
        return reached, ("" if reached else f"connector {name!r} of system {system!r} is connected to no FMU variable")
    # element.rest: the longest element name that is a prefix
    for element in sorted(elements, key=len, reverse=True):
        if name.startswith(element + "."):
            rest = name[len(element) + 1:]
            kind, ident = elements[element]
            if kind == "C":
                return [(("C", ident, rest), None)], ""
            return _resolve_in_system(flat, ident, rest, flat.elements[ident])
    return [], f"neither a connector of system {system!r} nor element.name of one of its elements"


def _collect_links(flat: FlatSystem, ssd_path: Path) -> None:
    for node, con in flat.nodes.items():
        if node[0] != "C" or con.kind not in SOURCE_KINDS:
            continue
        for (kind, comp, var), transform in _reach(flat, node):
            target = flat.nodes[(kind, comp, var)]
            link = ((node[1], node[2]), (comp, var))
            if target.kind == "input":
                if con.kind != "output":
                    raise SspError(f"{target.origin}: <ssd:Connector> input {comp}.{var} is driven by calculatedParameter "
                                   f"{node[1]}.{node[2]}: not supported (dtcosim sets inputs from outputs at "
                                   "every step); connect an output, or the calculatedParameter to a parameter")
                flat.connections.append((*link, transform, target.origin))
            elif target.kind == "parameter":
                if transform is not None:
                    raise SspError(f"{target.origin}: <ssd:Connector> parameter {comp}.{var} is set at initialisation from "
                                   f"{node[1]}.{node[2]} through a transformation: not supported (dtcosim's "
                                   "initial bindings copy values); remove the transformation from the connections "
                                   "on the way, or compute the value in the FMU")
                flat.initial.append((*link, target.origin))
            else:
                raise SspError(f"{target.origin}: <ssd:Connector> {comp}.{var} (kind {target.kind}) cannot receive data (SSP 1.0: "
                               "only inputs and parameters do); connect it as the start of the connection or "
                               "correct its kind")

