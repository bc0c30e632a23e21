"""SSP 1.0 export of a scenario (``.ssp`` = zip of ``SystemStructure.ssd`` + FMUs).

Export
------
``SystemStructure.ssd`` holds one ``ssd:Component`` per FMU (``source =
"resources/<file>.fmu"``) with an ``ssd:Connector`` (kind and ``ssc:Real`` /
``ssc:Integer`` / ``ssc:Boolean`` / ``ssc:String`` type, unit) for every variable
the scenario connects, binds, sets or records (the units are defined in
``ssd:Units`` from the FMUs' UnitDefinitions), its parameter values as an inline
``ssv:ParameterSet`` named :data:`PARAMETER_SET` in every component (hosts that
apply parameter sets by name, such as ecos's ``--parameterSet``, then apply all
of them at once), the ``ssd:Connections``, and an ``ssd:DefaultExperiment``
(start, stop) whose annotations carry

* ``com.opensimulationplatform``: ``osp:FixedStepAlgorithm baseStepSize = H``,
  which libcosim's SSP loader needs;
* ``org.dtcosim.scenario``: what SSP 1.0 has no element for - sampling interval,
  analysis window, algorithm (with ``target`` and ``stepTunedFor`` when the export
  names its host: the algorithm the step was chosen for, the criteria it meets, the scenario's coupling for
  that algorithm that was applied), extrapolation, stepping order, recorded variables
  and the initial bindings (``[[initial]]``), and the ``[analysis]`` settings when
  they differ from the defaults. Load events (``[[events]]``) need no annotation:
  they are the generator FMU's event-slot parameters in the parameter set.

A parameter binding (``[[bindings]]``: a parameter taking another FMU's parameter
value) is SSP 1.0's own: the system's ``ssd:ParameterBinding`` holds the source's
one value and its ``ssd:ParameterMapping`` applies it to the source and to every
target (``generator.inertia`` -> ``generator.inertia``, ``gearbox.generator_inertia``),
so a host that applies system-level bindings changes both with the one value
(``dtc:Binding`` restores the link on dtcosim's import). libcosim and ecos read
component-level values only: the components' parameter sets (and the archived
dtcosim FMUs) carry the bound value too, equal at export, and ``dtcosim export-ssp``
warns that those hosts must change both.

An initial binding (a parameter set from another FMU's output during
initialisation) cannot be an SSP/libcosim connection (targets must be inputs),
so the exporter also writes the value the binding produced at initialisation
into the parameter set: other hosts start from the same state; dtcosim, on
import, restores the binding instead of the fixed value.

A host that applies no parameter set (ecos 0.7 without ``--parameterSet``) would run
the FMUs with their build defaults. So a dtcosim FMU (one with a record) whose
component has parameter values goes into the archive as a copy in which those values
are the start values (:mod:`fmus.start_values`: ``modelDescription.xml`` and the
record, which the slave applies before the host sets anything): every host runs the
exported system, whether it applies the parameter set or not. Another tool's FMU is
archived as it is; its values are in the parameter set only
(:func:`unbaked_components` names them, and ``dtcosim export-ssp`` warns).

Import is :mod:`orchestrator.interop.ssp_import`.
"""


from __future__ import annotations

import json
import math
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from fmus.start_values import StartValueError, write_with_start_values

from ..atomic_files import atomic_path
from ..cosim.resolved import ResolvedSystem
from ..errors import SspError
from ..inputs.analysis_settings import AnalysisSettings
from ..inputs.scenario import VariableRef
from .ssp_xml import COMPUTED_ANNOTATION, DTCOSIM_ANNOTATION, NS, OSP_ANNOTATION

SSD_NAME = "SystemStructure.ssd"
#: Name of every component's parameter set in an exported SSP.
PARAMETER_SET = "dtcosim"
for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)


def _q(tag: str) -> str:
    prefix, _, local = tag.partition(":")
    return f"{{{NS[prefix]}}}{local}"


def _num(x: float) -> str:
    x = float(x)
    if math.isinf(x):  # xs:double spelling (e.g. a permanent torque step's duration)
        return "INF" if x > 0 else "-INF"
    return repr(x)


def _connector(parent: ET.Element, name: str, kind: str, fmi_type: str, unit: str = "") -> None:
    con = ET.SubElement(parent, _q("ssd:Connector"), name=name, kind=kind)
    el = ET.SubElement(con, _q(f"ssc:{'Integer' if fmi_type == 'Enumeration' else fmi_type}"))
    if unit and fmi_type == "Real":
        el.set("unit", unit)


def computed_values(system: ResolvedSystem) -> dict[str, tuple[str, tuple[str, ...]]]:
    """For each ``[[initial]]`` target: (its source, the components whose parameters decide the value).

    The value an initial binding produces depends on the parameters of the source
    component and of every component that feeds it, directly or through others, by
    connections or initial bindings (the initialisation sweeps).
    """
    sc = system.scenario
    feeders: dict[str, set[str]] = {name: set() for name in sc.component_names}
    for link in list(sc.connections) + list(sc.initial):
        feeders[link.target.component].add(link.source.component)
    out = {}
    for b in sc.initial:
        seen, todo = set(), [b.source.component]
        while todo:
            comp = todo.pop()
            if comp not in seen:
                seen.add(comp)
                todo += sorted(feeders[comp] - seen)
        out[str(b.target)] = (str(b.source), tuple(n for n in sc.component_names if n in seen))
    return out


def stale_warnings(system: ResolvedSystem, initial_values: Mapping[str, Any]) -> list[str]:
    """What ``dtcosim export-ssp`` warns: which exported values are computed or bound, and what makes them stale in
    another host."""
    out = [f"{b.target} is bound to {b.source} ([[bindings]]): the SSP's system-level parameter binding applies one "
           f"value to both, but hosts that read component values only (libcosim, ecos) take the copy in "
           f"{b.target.component}'s parameter set: change both there" for b in system.scenario.bindings]
    for target, (source, depends) in computed_values(system).items():
        if target in initial_values:
            out.append(f"{target} = {initial_values[target]:.10g} is computed by dtcosim's initialisation from "
                       f"{source}; another host applies it as a fixed value, which goes stale when a parameter of "
                       f"{', '.join(depends)} is changed there: export again (dtcosim export-ssp --set ...) instead")
    return out


def _parameter(parent: ET.Element, name: str, fmi_type: str, value: Any,
               computed: tuple[str, tuple[str, ...]] | None = None) -> None:
    p = ET.SubElement(parent, _q("ssv:Parameter"), name=name)
    if computed is not None:
        source, depends = computed
        p.set("description", f"computed by dtcosim's initialisation from {source}; stale once a parameter of "
                             f"{', '.join(depends)} changes (export again)")
    if fmi_type == "Real":
        ET.SubElement(p, _q("ssv:Real"), value=_num(value))
    elif fmi_type in ("Integer", "Enumeration"):
        ET.SubElement(p, _q("ssv:Integer"), value=str(int(value)))
    elif fmi_type == "Boolean":
        ET.SubElement(p, _q("ssv:Boolean"), value="true" if value else "false")
    else:
        ET.SubElement(p, _q("ssv:String"), value=str(value))
    if computed is not None:
        annotations = ET.SubElement(p, _q("ssv:Annotations"))
        annotation = ET.SubElement(annotations, _q("ssc:Annotation"), type=COMPUTED_ANNOTATION)
        ET.SubElement(annotation, _q("dtc:Computed"), source=computed[0], dependsOn=" ".join(computed[1]))


def _system_bindings(parent: ET.Element, system: ResolvedSystem) -> None:
    """The system's binding of each ``[[bindings]]`` source: its value, mapped to itself and to its targets."""
    sc = system.scenario
    targets: dict[str, list[str]] = {}
    for b in sc.bindings:
        targets.setdefault(sc.bound_source(b.target), []).append(str(b.target))
    binding = ET.SubElement(parent, _q("ssd:ParameterBinding"))
    pvals = ET.SubElement(binding, _q("ssd:ParameterValues"))
    pset = ET.SubElement(pvals, _q("ssv:ParameterSet"), version="1.0", name=PARAMETER_SET)
    params = ET.SubElement(pset, _q("ssv:Parameters"))
    mapping = ET.SubElement(ET.SubElement(binding, _q("ssd:ParameterMapping")), _q("ssm:ParameterMapping"),
                            version="1.0")
    for source, bound in targets.items():
        ref = VariableRef.parse(source, "bindings")
        _parameter(params, source, system.variable(ref).type, system.parameter_values(ref.component)[ref.variable])
        for target in [source, *bound]:
            ET.SubElement(mapping, _q("ssm:MappingEntry"), source=source, target=target)


def _transformation(parent: ET.Element, transformation) -> None:
    """The ``ssc:`` element of a connection's transformation (nothing for None)."""
    from ..inputs.transformations import MAPPING_KINDS, LinearTransformation

    if transformation is None:
        return
    if isinstance(transformation, LinearTransformation):
        ET.SubElement(parent, _q("ssc:LinearTransformation"), factor=_num(transformation.factor),
                      offset=_num(transformation.offset))
        return
    el = ET.SubElement(parent, _q(MAPPING_KINDS[transformation.kind]))
    for source, target in transformation.entries:
        text = (lambda v: ("true" if v else "false") if isinstance(v, bool) else str(v))
        ET.SubElement(el, _q("ssc:MapEntry"), source=text(source), target=text(target))


def component_values(system: ResolvedSystem, initial_values: Mapping[str, Any] | None = None) -> dict[str, dict]:
    """Each component's exported parameter values: the scenario's, and the values its initial bindings produced."""
    initial_values = dict(initial_values or {})
    out = {}
    for comp in system.scenario.components:
        values = dict(comp.parameters)
        for key, value in initial_values.items():
            ref = VariableRef.parse(key, "initial")
            if ref.component == comp.name:
                values[ref.variable] = value
        out[comp.name] = values
    return out


def baked_values(system: ResolvedSystem, initial_values: Mapping[str, Any] | None = None) -> dict[str, dict]:
    """Component -> the start values its archived FMU copy carries (dtcosim FMUs with parameter values only)."""
    return {name: values for name, values in component_values(system, initial_values).items()
            if values and system.interfaces[name].record is not None}


def unbaked_components(system: ResolvedSystem, initial_values: Mapping[str, Any] | None = None) -> list[str]:
    """Components with parameter values whose FMU is archived unchanged (not a dtcosim FMU)."""
    return [name for name, values in component_values(system, initial_values).items()
            if values and system.interfaces[name].record is None]


def _resource_names(system: ResolvedSystem, baked: Mapping[str, Mapping[str, Any]]) -> dict[str, str]:
    """Archive path of each component's FMU (one file per distinct FMU and start values)."""
    by_key: dict[tuple[str, str], str] = {}
    used: set[str] = set()
    out = {}
    for comp in system.scenario.components:
        iface = system.interfaces[comp.name]
        key = (iface.sha256, json.dumps(baked.get(comp.name, {}), sort_keys=True, default=repr))
        if key in by_key:
            out[comp.name] = by_key[key]
            continue
        name = f"resources/{system.fmu_paths[comp.name].name}"
        if name in used:
            name = f"resources/{comp.name}_{system.fmu_paths[comp.name].name}"
        used.add(name)
        by_key[key] = name
        out[comp.name] = name
    return out


#: the master algorithm each export target steps with (libcosim's and ecos's fixed-step algorithm is Jacobi)
HOST_ALGORITHMS = {"dtcosim": None, "libcosim": "jacobi", "ecos": "jacobi"}


def host_notes(target: str, step_s: float, stop_s: float) -> list[str]:
    """What to tell the user of ``target`` to run the exported system over its whole time (measured on ecos 0.7.2)."""
    if target != "ecos":
        return []
    return [f"ecos 0.7.2 writes its CSV up to one step before --stopTime (with --stopTime {stop_s:g} its last row is "
            f"{stop_s - step_s:g} s): run it with --stepSize {step_s:g} --stopTime {stop_s + step_s:g} to have the "
            f"sample at {stop_s:g} s"]


@dataclass(frozen=True)
class ExportTuning:
    """What an export was tuned for: the ``target`` host, the algorithm its step was chosen for, the criteria met,
    and the scenario's coupling for the target's algorithm that was applied (``[jacobi]``, as text)."""

    target: str
    step_tuned_for: str
    criteria: str = ""
    coupling: str = ""


def system_structure(system: ResolvedSystem, initial_values: Mapping[str, float] | None = None,
                     tuning: ExportTuning | None = None) -> ET.ElementTree:
    """The ``SystemStructure.ssd`` document of a checked scenario.

    Parameters
    ----------
    system : ResolvedSystem
    initial_values : mapping of str -> float, optional
        Values the initial bindings produced (``"generator.initial_speed": 167.3``),
        written into the parameter sets for hosts without dtcosim's initialisation.
    tuning : ExportTuning, optional
        The host the export is for and the algorithm its step was chosen for, written
        as ``target`` and ``stepTunedFor`` of ``dtc:Simulation``.
    """
    sc = system.scenario
    sim = sc.simulation
    initial_values = dict(initial_values or {})
    resources = _resource_names(system, baked_values(system, initial_values))
    exported = component_values(system, initial_values)
    computed = computed_values(system)
    root = ET.Element(_q("ssd:SystemStructureDescription"), name=sc.name, version="1.0")
    sysel = ET.SubElement(root, _q("ssd:System"), name=sc.name)
    if sc.description:
        sysel.set("description", sc.description)
    if sc.bindings:  # before ssd:Elements (SSP 1.0 schema order)
        _system_bindings(ET.SubElement(sysel, _q("ssd:ParameterBindings")), system)
    elements = ET.SubElement(sysel, _q("ssd:Elements"))
    units: dict[str, Mapping[str, float]] = {}  # unit definitions of the connectors (SSP 1.0 ssd:Units)
    for comp in sc.components:
        iface = system.interfaces[comp.name]
        el = ET.SubElement(elements, _q("ssd:Component"), name=comp.name, source=resources[comp.name],
                           type="application/x-fmu-sharedlibrary")
        connectors = ET.SubElement(el, _q("ssd:Connectors"))
        names: list[str] = []

        def add(var_name: str) -> None:
            if var_name not in names:
                names.append(var_name)

        for con in sc.connections:
            if con.source.component == comp.name:
                add(con.source.variable)
            if con.target.component == comp.name:
                add(con.target.variable)
        for b in (*sc.initial, *sc.bindings):
            if b.source.component == comp.name:
                add(b.source.variable)
            if b.target.component == comp.name:
                add(b.target.variable)
        for pname in comp.parameters:
            add(pname)
        for rv in system.recorded:
            if rv.component == comp.name:
                add(rv.variable)
        for var_name in names:
            var = iface.variables[var_name]
            kind = var.causality if var.causality in ("input", "output", "parameter", "calculatedParameter") else "unspecified"
            unit = var.unit if var.unit in iface.unit_definitions else ""
            if unit:
                units.setdefault(unit, iface.unit_definitions[unit])
            _connector(connectors, var_name, kind, var.type, unit)
        values = exported[comp.name]
        if values:
            bindings = ET.SubElement(el, _q("ssd:ParameterBindings"))
            binding = ET.SubElement(bindings, _q("ssd:ParameterBinding"))
            pvals = ET.SubElement(binding, _q("ssd:ParameterValues"))
            pset = ET.SubElement(pvals, _q("ssv:ParameterSet"), version="1.0", name=PARAMETER_SET)
            params = ET.SubElement(pset, _q("ssv:Parameters"))
            for pname, value in values.items():
                _parameter(params, pname, iface.variables[pname].type, value,
                           computed.get(f"{comp.name}.{pname}") if f"{comp.name}.{pname}" in initial_values else None)
    if sc.connections:
        conns = ET.SubElement(sysel, _q("ssd:Connections"))
        for con in sc.connections:
            el = ET.SubElement(conns, _q("ssd:Connection"), startElement=con.source.component,
                               startConnector=con.source.variable, endElement=con.target.component,
                               endConnector=con.target.variable)
            _transformation(el, con.transformation)
    if units:
        units_el = ET.SubElement(root, _q("ssd:Units"))
        for name, base in sorted(units.items()):
            unit_el = ET.SubElement(units_el, _q("ssc:Unit"), name=name)
            ET.SubElement(unit_el, _q("ssc:BaseUnit"), {k: (str(int(v)) if k not in ("factor", "offset") else _num(v))
                                                           for k, v in base.items()})
    exp = ET.SubElement(root, _q("ssd:DefaultExperiment"), startTime=_num(sim.start_s), stopTime=_num(sim.stop_s))
    annotations = ET.SubElement(exp, _q("ssd:Annotations"))
    osp = ET.SubElement(annotations, _q("ssc:Annotation"), type=OSP_ANNOTATION)
    alg = ET.SubElement(osp, _q("osp:Algorithm"))
    ET.SubElement(alg, _q("osp:FixedStepAlgorithm"), baseStepSize=_num(sim.step_s))
    dtc_annotation = ET.SubElement(annotations, _q("ssc:Annotation"), type=DTCOSIM_ANNOTATION)
    dtc = ET.SubElement(dtc_annotation, _q("dtc:Scenario"))  # an ssc:Annotation holds exactly one element
    settings = ET.SubElement(
        dtc, _q("dtc:Simulation"), step=_num(sim.step_s), outputInterval=_num(sim.output_interval_s),
        windowStart=_num(sim.window_s[0]), windowEnd=_num(sim.window_s[1]), algorithm=sim.algorithm,
        extrapolation=sim.extrapolation,
    )
    if tuning is not None:
        settings.set("target", tuning.target)
        settings.set("stepTunedFor", tuning.step_tuned_for)
        if tuning.criteria:
            settings.set("stepCriteria", tuning.criteria)
        if tuning.coupling:
            settings.set("coupling", tuning.coupling)
    if sim.order:
        settings.set("order", " ".join(sim.order))
    if sim.algebraic_loops != "refuse":
        settings.set("algebraicLoops", sim.algebraic_loops)
        settings.set("loopTolerance", _num(sim.loop_tolerance))
        settings.set("loopMaxIterations", str(sim.loop_max_iterations))
    for b in sc.initial:
        ET.SubElement(dtc, _q("dtc:Initial"), source=str(b.source), target=str(b.target))
    for b in sc.bindings:
        ET.SubElement(dtc, _q("dtc:Binding"), source=str(b.source), target=str(b.target))
    for pattern in sc.recorded:
        ET.SubElement(dtc, _q("dtc:Record"), variable=pattern)
    if sc.analysis != AnalysisSettings():
        a = sc.analysis
        bins = a.ldd_bins
        ET.SubElement(dtc, _q("dtc:Analysis"), woehlerExponents=" ".join(_num(m) for m in a.woehler_exponents),
                      referenceFrequencyHz=_num(a.reference_frequency_hz),
                      lddBins=str(bins) if isinstance(bins, int) else " ".join(_num(x) for x in bins),
                      rainflowResidue=a.rainflow_residue, contactLossThresholdN=_num(a.contact_loss_threshold_n),
                      spectrum=a.spectrum)
    ET.indent(root, space="  ")
    return ET.ElementTree(root)


def export_ssp(system: ResolvedSystem, path: str | Path, initial_values: Mapping[str, float] | None = None,
               tuning: ExportTuning | None = None) -> Path:
    """Write a ``.ssp`` archive: ``SystemStructure.ssd`` and the FMUs under ``resources/``.

    Parameters
    ----------
    system : ResolvedSystem
    path : path
        Output file (``.ssp``).
    initial_values : mapping, optional
        See :func:`system_structure`.
    tuning : ExportTuning, optional
        See :func:`system_structure`.
    """
    path = Path(path)
    if path.suffix != ".ssp":
        raise SspError(f"{path}: an SSP archive must have the extension .ssp")
    path.parent.mkdir(parents=True, exist_ok=True)
    tree = system_structure(system, initial_values, tuning)
    baked = baked_values(system, initial_values)
    resources = _resource_names(system, baked)
    # whole or not there, and a write error (a full disk) names the .ssp
    with atomic_path(path) as tmp, tempfile.TemporaryDirectory(prefix="dtcosim-ssp-") as staging, \
            zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(SSD_NAME, ET.tostring(tree.getroot(), encoding="UTF-8", xml_declaration=True))
        written: set[str] = set()
        for comp in system.scenario.components:
            arc = resources[comp.name]
            if arc in written:
                continue
            source = system.fmu_paths[comp.name]
            if comp.name in baked:
                try:
                    source = write_with_start_values(source, Path(staging) / arc, baked[comp.name])
                except StartValueError as exc:
                    raise SspError(f"components.{comp.name}: {exc}") from None
            zf.write(source, arc, compress_type=zipfile.ZIP_STORED)
            written.add(arc)
    return path
