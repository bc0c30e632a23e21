"""SSP 1.0 export and import of a scenario (``.ssp`` = zip of ``SystemStructure.ssd`` + FMUs).

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
  analysis window, algorithm, extrapolation, stepping order, recorded variables
  and the initial bindings (``[[initial]]``), and the ``[analysis]`` settings when
  they differ from the defaults. Load events (``[[events]]``) need no annotation:
  they are the generator FMU's event-slot parameters in the parameter set.

An initial binding (a parameter set from another FMU's output during
initialisation) cannot be an SSP/libcosim connection (targets must be inputs),
so the exporter also writes the value the binding produced at initialisation
into the parameter set: other hosts start from the same state; dtcosim, on
import, restores the binding instead of the fixed value.

Import
------
Reads ``.ssp`` archives (extracted once per process), SSP directories and
``.ssd`` files, and builds a :class:`~orchestrator.inputs.scenario.Scenario` with the
FMU paths relative to the SSD. Without the dtcosim annotation the sampling
interval is the step, the window the whole run, the master Gauss-Seidel with
hold, and every output is recorded.
"""

from __future__ import annotations

import atexit
import hashlib
import math
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any, Mapping

from ..cosim.system import ResolvedSystem
from ..errors import ScenarioError, SspError
from ..inputs.analysis_settings import AnalysisSettings
from ..inputs.limits import MAX_SSP_BYTES, MAX_SSP_MEMBERS, MAX_SSP_RATIO
from ..inputs.scenario import (
    Component,
    Connection,
    InitialBinding,
    Scenario,
    SimulationSettings,
    VariableRef,
)

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "https://opensimulationplatform.com/SSP/OSPAnnotations",
    "dtc": "https://dtcosim.org/SSP/Annotations",
}
OSP_ANNOTATION = "com.opensimulationplatform"
DTCOSIM_ANNOTATION = "org.dtcosim.scenario"
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


# ----------------------------------------------------------------------------- export
def _connector(parent: ET.Element, name: str, kind: str, fmi_type: str, unit: str = "") -> None:
    con = ET.SubElement(parent, _q("ssd:Connector"), name=name, kind=kind)
    el = ET.SubElement(con, _q(f"ssc:{'Integer' if fmi_type == 'Enumeration' else fmi_type}"))
    if unit and fmi_type == "Real":
        el.set("unit", unit)


def _parameter(parent: ET.Element, name: str, fmi_type: str, value: Any) -> None:
    p = ET.SubElement(parent, _q("ssv:Parameter"), name=name)
    if fmi_type == "Real":
        ET.SubElement(p, _q("ssv:Real"), value=_num(value))
    elif fmi_type in ("Integer", "Enumeration"):
        ET.SubElement(p, _q("ssv:Integer"), value=str(int(value)))
    elif fmi_type == "Boolean":
        ET.SubElement(p, _q("ssv:Boolean"), value="true" if value else "false")
    else:
        ET.SubElement(p, _q("ssv:String"), value=str(value))


def _resource_names(system: ResolvedSystem) -> dict[str, str]:
    """Archive path of each component's FMU (one copy per distinct file)."""
    by_sha: dict[str, str] = {}
    used: set[str] = set()
    out = {}
    for comp in system.scenario.components:
        iface = system.interfaces[comp.name]
        if iface.sha256 in by_sha:
            out[comp.name] = by_sha[iface.sha256]
            continue
        name = f"resources/{system.fmu_paths[comp.name].name}"
        if name in used:
            name = f"resources/{comp.name}_{system.fmu_paths[comp.name].name}"
        used.add(name)
        by_sha[iface.sha256] = name
        out[comp.name] = name
    return out


def system_structure(system: ResolvedSystem, initial_values: Mapping[str, float] | None = None) -> ET.ElementTree:
    """The ``SystemStructure.ssd`` document of a checked scenario.

    Parameters
    ----------
    system : ResolvedSystem
    initial_values : mapping of str -> float, optional
        Values the initial bindings produced (``"generator.initial_speed": 167.3``),
        written into the parameter sets for hosts without dtcosim's initialisation.
    """
    sc = system.scenario
    sim = sc.simulation
    initial_values = dict(initial_values or {})
    resources = _resource_names(system)
    root = ET.Element(_q("ssd:SystemStructureDescription"), name=sc.name, version="1.0")
    sysel = ET.SubElement(root, _q("ssd:System"), name=sc.name)
    if sc.description:
        sysel.set("description", sc.description)
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
        for b in sc.initial:
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
        values = dict(comp.parameters)
        for key, value in initial_values.items():
            ref = VariableRef.parse(key, "initial")
            if ref.component == comp.name:
                values[ref.variable] = value
        if values:
            bindings = ET.SubElement(el, _q("ssd:ParameterBindings"))
            binding = ET.SubElement(bindings, _q("ssd:ParameterBinding"))
            pvals = ET.SubElement(binding, _q("ssd:ParameterValues"))
            pset = ET.SubElement(pvals, _q("ssv:ParameterSet"), version="1.0", name=PARAMETER_SET)
            params = ET.SubElement(pset, _q("ssv:Parameters"))
            for pname, value in values.items():
                _parameter(params, pname, iface.variables[pname].type, value)
    if sc.connections:
        conns = ET.SubElement(sysel, _q("ssd:Connections"))
        for con in sc.connections:
            ET.SubElement(conns, _q("ssd:Connection"), startElement=con.source.component,
                          startConnector=con.source.variable, endElement=con.target.component,
                          endConnector=con.target.variable)
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
    if sim.order:
        settings.set("order", " ".join(sim.order))
    for b in sc.initial:
        ET.SubElement(dtc, _q("dtc:Initial"), source=str(b.source), target=str(b.target))
    for pattern in sc.record:
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


def export_ssp(system: ResolvedSystem, path: str | Path, initial_values: Mapping[str, float] | None = None) -> Path:
    """Write a ``.ssp`` archive: ``SystemStructure.ssd`` and the FMUs under ``resources/``.

    Parameters
    ----------
    system : ResolvedSystem
    path : path
        Output file (``.ssp``).
    initial_values : mapping, optional
        See :func:`system_structure`.
    """
    path = Path(path)
    if path.suffix != ".ssp":
        raise SspError(f"{path}: an SSP archive must have the extension .ssp")
    path.parent.mkdir(parents=True, exist_ok=True)
    tree = system_structure(system, initial_values)
    resources = _resource_names(system)
    tmp = path.with_name(path.name + ".tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(SSD_NAME, ET.tostring(tree.getroot(), encoding="UTF-8", xml_declaration=True))
        written: set[str] = set()
        for comp in system.scenario.components:
            arc = resources[comp.name]
            if arc not in written:
                zf.write(system.fmu_paths[comp.name], arc, compress_type=zipfile.ZIP_STORED)
                written.add(arc)
    tmp.replace(path)
    return path


# ----------------------------------------------------------------------------- import
_EXTRACTED: dict[str, Path] = {}


def _check_archive_size(path: Path, zf: zipfile.ZipFile) -> None:
    """Refuse an archive that would expand beyond the limits of :mod:`orchestrator.inputs.limits` (a zip bomb)."""
    infos = zf.infolist()
    if len(infos) > MAX_SSP_MEMBERS:
        raise SspError(f"{path}: {len(infos)} archive members, expected at most {MAX_SSP_MEMBERS}")
    total = sum(i.file_size for i in infos)
    if total > MAX_SSP_BYTES:
        raise SspError(f"{path}: expands to {total / 2**20:.0f} MiB, expected at most {MAX_SSP_BYTES / 2**20:.0f} MiB")
    for info in infos:
        if info.file_size > MAX_SSP_RATIO * max(info.compress_size, 1) and info.file_size > 1 << 20:
            raise SspError(f"{path}: archive member {info.filename!r} expands {info.file_size / max(info.compress_size, 1):.0f} "
                           f"times ({info.compress_size} -> {info.file_size} bytes), expected at most {MAX_SSP_RATIO} times")


def _extract_ssp(path: Path) -> Path:
    """Directory with the archive's content (extracted once per process and content)."""
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest not in _EXTRACTED:
        target = Path(tempfile.mkdtemp(prefix="dtcosim-ssp-"))
        atexit.register(shutil.rmtree, target, True)
        try:
            with zipfile.ZipFile(path) as zf:
                _check_archive_size(path, zf)
                for member in zf.namelist():
                    dest = (target / member).resolve()
                    if not str(dest).startswith(str(target.resolve())):
                        raise SspError(f"{path}: archive member {member!r} points outside the archive")
                zf.extractall(target)
        except zipfile.BadZipFile as exc:
            raise SspError(f"{path}: not a zip archive ({exc})") from None
        _EXTRACTED[digest] = target
    return _EXTRACTED[digest]


def _typed(el: ET.Element, where: str) -> Any:
    for tag, conv in (("ssv:Real", float), ("ssv:Integer", int), ("ssv:Boolean", None), ("ssv:String", str)):
        child = el.find(tag, NS)
        if child is not None:
            value = child.get("value")
            if value is None:
                raise SspError(f"{where}: {tag} without value")
            if conv is None:
                return value.strip().lower() in ("true", "1")
            try:
                return conv(value)
            except ValueError:
                raise SspError(f"{where}: {tag} value {value!r} is not valid") from None
    raise SspError(f"{where}: parameter without a Real, Integer, Boolean or String value")


def _float_attr(el: ET.Element, name: str, where: str, default: float | None = None) -> float | None:
    value = el.get(name)
    if value is None:
        return default
    try:
        out = float(value)
    except ValueError:
        raise SspError(f"{where}: attribute {name}={value!r} is not a number") from None
    if not math.isfinite(out):
        raise SspError(f"{where}: attribute {name}={value!r} is not finite")
    return out


def _analysis_settings(el: ET.Element, source: str) -> AnalysisSettings:
    """The ``[analysis]`` settings from a ``dtc:Analysis`` element (absent attributes: defaults)."""
    try:
        kwargs: dict[str, Any] = {}
        if el.get("woehlerExponents"):
            kwargs["woehler_exponents"] = tuple(float(x) for x in el.get("woehlerExponents").split())
        if el.get("referenceFrequencyHz"):
            kwargs["reference_frequency_hz"] = float(el.get("referenceFrequencyHz"))
        if el.get("lddBins"):
            parts = el.get("lddBins").split()
            kwargs["ldd_bins"] = int(parts[0]) if len(parts) == 1 else tuple(float(x) for x in parts)
        if el.get("contactLossThresholdN"):
            kwargs["contact_loss_threshold_n"] = float(el.get("contactLossThresholdN"))
    except ValueError as exc:
        raise SspError(f"{source}: dtc:Analysis has a malformed number ({exc})") from None
    for attr, key in (("rainflowResidue", "rainflow_residue"), ("spectrum", "spectrum")):
        if el.get(attr):
            kwargs[key] = el.get(attr)
    try:
        return AnalysisSettings(**kwargs)
    except ScenarioError as exc:
        raise ScenarioError(exc.key, exc.value, exc.expected, source) from None


def import_ssp(path: str | Path) -> Scenario:
    """Read a scenario from an ``.ssp`` archive, an SSP directory or a ``.ssd`` file.

    Raises
    ------
    SspError
        Unreadable file, missing elements.
    ScenarioError
        The content does not form a valid scenario (names the key, e.g. ``simulation.step``).
    """
    path = Path(path)
    if not path.exists():
        raise SspError(f"{path}: no such file or directory")
    if path.is_dir():
        ssd, base = path / SSD_NAME, path
    elif path.suffix == ".ssp":
        base = _extract_ssp(path)
        ssd = base / SSD_NAME
    else:
        ssd, base = path, path.parent
    if not ssd.is_file():
        raise SspError(f"{path}: no {SSD_NAME}")
    try:
        root = ET.parse(ssd).getroot()
    except ET.ParseError as exc:
        raise SspError(f"{ssd}: not valid XML ({exc})") from None
    if root.tag != _q("ssd:SystemStructureDescription"):
        raise SspError(f"{ssd}: root element is not ssd:SystemStructureDescription")
    source = str(path)
    system = root.find("ssd:System", NS)
    if system is None:
        raise SspError(f"{ssd}: no ssd:System")
    name = re.sub(r"[^A-Za-z0-9_\-]", "-", root.get("name") or system.get("name") or path.stem)

    dtc = None
    step = None
    exp = root.find("ssd:DefaultExperiment", NS)
    start = _float_attr(exp, "startTime", "ssd:DefaultExperiment", 0.0) if exp is not None else 0.0
    stop = _float_attr(exp, "stopTime", "ssd:DefaultExperiment") if exp is not None else None
    if exp is not None:
        for ann in exp.findall("ssd:Annotations/ssc:Annotation", NS):
            if ann.get("type") == OSP_ANNOTATION:
                fsa = ann.find("osp:Algorithm/osp:FixedStepAlgorithm", NS)
                if fsa is not None:
                    step = _float_attr(fsa, "baseStepSize", "osp:FixedStepAlgorithm")
            elif ann.get("type") == DTCOSIM_ANNOTATION:
                dtc = ann.find("dtc:Scenario", NS)
    if stop is None:
        raise ScenarioError("simulation.stop", None, "a stopTime in ssd:DefaultExperiment", source)
    sim_kwargs: dict[str, Any] = {"start_s": start, "stop_s": stop}
    initial: list[InitialBinding] = []
    record: list[str] = []
    analysis = AnalysisSettings()
    if dtc is not None:
        s = dtc.find("dtc:Simulation", NS)
        if s is not None:
            step = _float_attr(s, "step", "dtc:Simulation", step)
            sim_kwargs["output_interval_s"] = _float_attr(s, "outputInterval", "dtc:Simulation")
            w0 = _float_attr(s, "windowStart", "dtc:Simulation")
            w1 = _float_attr(s, "windowEnd", "dtc:Simulation")
            if w0 is not None and w1 is not None:
                sim_kwargs["window_s"] = (w0, w1)
            for attr, key in (("algorithm", "algorithm"), ("extrapolation", "extrapolation")):
                if s.get(attr):
                    sim_kwargs[key] = s.get(attr)
            if s.get("order"):
                sim_kwargs["order"] = tuple(s.get("order").split())
        for i, b in enumerate(dtc.findall("dtc:Initial", NS)):
            initial.append(InitialBinding(VariableRef.parse(b.get("source"), f"initial[{i}].from", source),
                                          VariableRef.parse(b.get("target"), f"initial[{i}].to", source)))
        record = [r.get("variable") for r in dtc.findall("dtc:Record", NS) if r.get("variable")]
        an = dtc.find("dtc:Analysis", NS)
        if an is not None:
            analysis = _analysis_settings(an, source)
    if step is None:
        raise ScenarioError("simulation.step", None, "osp:FixedStepAlgorithm baseStepSize or a dtcosim annotation", source)
    sim_kwargs["step_s"] = step
    try:
        settings = SimulationSettings(**{k: v for k, v in sim_kwargs.items() if v is not None})
    except ScenarioError as exc:
        raise ScenarioError(exc.key, exc.value, exc.expected, source) from None

    bound = {str(b.target) for b in initial}
    components = []
    for el in system.findall("ssd:Elements/ssd:Component", NS):
        cname = el.get("name")
        src = el.get("source")
        if not cname or not src:
            raise SspError(f"{ssd}: ssd:Component without name or source")
        params: dict[str, Any] = {}
        for pset in el.findall("ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet", NS):
            for p in pset.findall("ssv:Parameters/ssv:Parameter", NS):
                pname = p.get("name")
                if f"{cname}.{pname}" not in bound:  # the binding sets it at initialisation
                    params[pname] = _typed(p, f"{cname}.{pname}")
        components.append(Component(cname, Path(src), params))
    connections = []
    for i, c in enumerate(system.findall("ssd:Connections/ssd:Connection", NS)):
        ends = [c.get(a) for a in ("startElement", "startConnector", "endElement", "endConnector")]
        if not all(ends):
            raise SspError(f"{ssd}: ssd:Connection {i} lacks start/end element or connector")
        connections.append(Connection(VariableRef(ends[0], ends[1]), VariableRef(ends[2], ends[3])))
    return Scenario(
        name=name, description=system.get("description", ""), components=tuple(components),
        connections=tuple(connections), initial=tuple(initial), simulation=settings, record=tuple(record),
        analysis=analysis, base_dir=base, source=source,
    )
