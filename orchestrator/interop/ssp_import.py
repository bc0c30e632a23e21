"""SSP 1.0 import: a :class:`~orchestrator.inputs.scenario.Scenario` from an ``.ssp`` archive, an SSP folder or an ``.ssd``.

What is read
------------
* the ``ssd:System`` tree, flattened (:mod:`orchestrator.interop.ssp_system`):
  FMU components of nested systems, connections through system connectors with
  their transformations (linear, Boolean/Integer/Enumeration mappings) and unit
  conversions, parameter bindings inline and from ``.ssv`` files with ``.ssm``
  mappings (:mod:`orchestrator.interop.ssp_parameters`), with SSP's precedence;
* ``ssd:DefaultExperiment``: start and stop time, and its annotations:

  - ``com.opensimulationplatform``: ``Algorithm/FixedStepAlgorithm baseStepSize``
    (the communication step), its elements matched by meaning under both the
    ``https://`` and ``http://opensimulationplatform.com/SSP/OSPAnnotations``
    namespaces, as libcosim does;
  - ``org.dtcosim.scenario``: what dtcosim's own export adds (sampling interval,
    window, algorithm, extrapolation, order, records, initial and parameter bindings, analysis).

* without either annotation the step is ``--step`` (``step_s``), else the
  smallest DefaultExperiment ``stepSize`` of the FMUs, else a ScenarioError that
  says to give ``--step``; the stop time is the SSD's ``stopTime``, else
  ``--stop``, else the FMUs' DefaultExperiment ``stopTime``, else an error naming
  ``--stop``.

An SSP whose system holds no FMU component is refused first, saying so. Parameter
values follow SSP 1.0, 5.2.3 (:mod:`orchestrator.interop.ssp_parameters`): a name
that reaches no variable is ignored and reported. Everything else in the file that
dtcosim does not support is refused naming the element, the file, the line, the
rule or feature and what to do (:func:`orchestrator.interop.ssp_xml.check_supported`);
annotations of other tools are reported as notes.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import re
import shutil
import stat
import tempfile
import zipfile
import zlib
from pathlib import Path
from typing import Any, Callable

from lxml import etree

from ..archive_members import record_extraction
from ..errors import ScenarioError, SspError
from ..inputs.analysis_settings import AnalysisSettings
from ..inputs.limits import MAX_SSP_BYTES, MAX_SSP_MEMBERS, MAX_SSP_RATIO
from ..inputs.origins import Origin
from ..inputs.scenario import (
    Component,
    Connection,
    InitialBinding,
    ParameterBinding,
    Scenario,
    SimulationSettings,
    VariableRef,
)
from .ssp_system import FMU_TYPE, flatten
from .ssp_xml import (
    DTCOSIM_ANNOTATION,
    NS,
    OSP_ANNOTATION,
    OSP_NAMESPACES,
    check_supported,
    child,
    children,
    element_error,
    float_attr,
    int_attr,
    parse,
    tag,
    unit_definitions,
    where,
)

SSD_NAME = "SystemStructure.ssd"
_EXTRACTED: dict[str, Path] = {}


def _check_archive_size(path: Path, zf: zipfile.ZipFile) -> None:
    """Refuse an archive that would expand beyond the limits of :mod:`orchestrator.inputs.limits` (a zip bomb)."""
    infos = zf.infolist()
    if len(infos) > MAX_SSP_MEMBERS:
        raise SspError(f"{path}: {len(infos)} archive members, expected at most {MAX_SSP_MEMBERS} (a limit against "
                       "zip bombs); split the system or unpack it and run the folder")
    total = sum(i.file_size for i in infos)
    if total > MAX_SSP_BYTES:
        raise SspError(f"{path}: expands to {total / 2**20:.0f} MiB, expected at most {MAX_SSP_BYTES / 2**20:.0f} MiB "
                       "(a limit against zip bombs); unpack it yourself and run the folder")
    for info in infos:
        if info.file_size > MAX_SSP_RATIO * max(info.compress_size, 1) and info.file_size > 1 << 20:
            raise SspError(f"{path}: archive member {info.filename!r} expands {info.file_size / max(info.compress_size, 1):.0f} "
                           f"times ({info.compress_size} -> {info.file_size} bytes), expected at most {MAX_SSP_RATIO} times "
                           "(a limit against zip bombs); unpack it yourself and run the folder")


def _extract_ssp(path: Path) -> Path:
    """Directory with the archive's content (extracted once per process and content)."""
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise SspError(f"{path}: not a regular file (a device, pipe or folder); name the .ssp archive itself")
    if info.st_size > MAX_SSP_BYTES:
        raise SspError(f"{path}: {info.st_size / 2**20:.0f} MiB, expected at most {MAX_SSP_BYTES / 2**20:.0f} MiB "
                       "(a limit against zip bombs); unpack it yourself and run the folder")
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
                        raise SspError(f"{path}: archive member {member!r} points outside the archive (refused: "
                                       "it would write elsewhere); repack the SSP with relative member names")
                zf.extractall(target)
        except (zlib.error, EOFError) as exc:  # a damaged member (zipfile reports a CRC mismatch as BadZipFile)
            raise SspError(f"{path}: a damaged archive member ({exc or type(exc).__name__}); pack the SSP again") from None
        except OSError as exc:  # a full disk, a file-size limit
            reason = exc.strerror or str(exc)
            raise SspError(f"{path}: cannot be extracted into {target} ({reason})") from None
        except zipfile.BadZipFile as exc:
            raise SspError(f"{path}: not a zip archive ({exc}; SSP 1.0: an .ssp file is a zip archive); pack the SSD "
                           "and its resources with zip, or name the SSP folder or its .ssd") from None
        _EXTRACTED[digest] = target
    return _EXTRACTED[digest]


def is_ssp(path: str | Path) -> bool:
    """True for what :func:`import_ssp` reads: an ``.ssp`` archive, an ``.ssd`` file or a folder holding an SSD."""
    p = Path(path)
    return p.suffix in (".ssp", ".ssd") or (p.is_dir() and (p / SSD_NAME).is_file())


def locate_ssd(path: Path) -> tuple[Path, Path]:
    """(the SSD file, the folder component sources are relative to) of an archive, folder or ``.ssd``."""
    if not path.exists():
        raise SspError(f"{path}: no such file or directory; name an .ssp archive, an SSP folder or an .ssd file")
    if path.is_dir():
        ssd, base = path / SSD_NAME, path
    elif path.suffix == ".ssp":
        base = _extract_ssp(path)
        record_extraction(base, path)  # messages name its files <archive>!<member>
        ssd = base / SSD_NAME
    else:
        ssd, base = path, path.parent
    if not ssd.is_file():
        raise SspError(f"{path}: no {SSD_NAME} (SSP 1.0: the system structure of a package is in that file); "
                       f"name the .ssd file itself, or add {SSD_NAME} at the top of the package")
    return ssd, base


def _osp_step(annotation, ssd: Path) -> float | None:
    """baseStepSize of an OSP annotation (any content other than the fixed-step algorithm is refused)."""
    step = None
    for el in annotation:
        if not isinstance(el.tag, str):
            continue
        qname = etree.QName(el)
        if qname.namespace not in OSP_NAMESPACES or qname.localname != "Algorithm":
            raise element_error(el, ssd, "is not supported in the OSP annotation (dtcosim reads osp:Algorithm)",
                                "remove it, or give the step on the command line (--step H) and drop the annotation")
        for alg in el:
            if not isinstance(alg.tag, str):
                continue
            q = etree.QName(alg)
            if q.namespace not in OSP_NAMESPACES or q.localname != "FixedStepAlgorithm":
                raise element_error(alg, ssd, "is not supported (dtcosim runs osp:FixedStepAlgorithm)",
                                    "use osp:FixedStepAlgorithm baseStepSize=\"H\" or give --step H")
            step = float_attr(alg, "baseStepSize", ssd)
            if step is None:
                raise element_error(alg, ssd, "has no baseStepSize (the OSP annotation requires it)",
                                    "add baseStepSize=\"H\" (seconds)")
    return step


def _dtcosim_settings(annotation, ssd: Path, source: str) -> tuple[dict, list, list, AnalysisSettings, float | None,
                                                                   list]:
    """(simulation keyword arguments, initial bindings, record patterns, analysis settings, step, parameter bindings)
    of dtcosim's annotation."""
    sim: dict[str, Any] = {}
    initial: list[InitialBinding] = []
    bindings: list[ParameterBinding] = []
    record: list[str] = []
    analysis = AnalysisSettings()
    step = None
    scenario_el = child(annotation, "dtc:Scenario")
    if scenario_el is None:
        raise element_error(annotation, ssd, "of type org.dtcosim.scenario has no dtc:Scenario (dtcosim's "
                            "annotation holds one)", "remove the annotation or export the scenario again")
    for el in scenario_el:
        if not isinstance(el.tag, str):
            continue
        name = tag(el)
        if name == "dtc:Simulation":
            step = float_attr(el, "step", ssd)
            sim["output_interval_s"] = float_attr(el, "outputInterval", ssd)
            w0, w1 = float_attr(el, "windowStart", ssd), float_attr(el, "windowEnd", ssd)
            if w0 is not None and w1 is not None:
                sim["window_s"] = (w0, w1)
            for attr in ("algorithm", "extrapolation"):
                if el.get(attr):
                    sim[attr] = el.get(attr)
            if el.get("order"):
                sim["order"] = tuple(el.get("order").split())
            if el.get("algebraicLoops"):
                sim["algebraic_loops"] = el.get("algebraicLoops")
            tolerance = float_attr(el, "loopTolerance", ssd)
            if tolerance is not None:
                sim["loop_tolerance"] = tolerance
            if el.get("loopMaxIterations") is not None:
                sim["loop_max_iterations"] = int_attr(el, "loopMaxIterations", ssd)
        elif name == "dtc:Initial":
            i = len(initial)
            initial.append(InitialBinding(VariableRef.parse(el.get("source"), f"initial[{i}].from", source),
                                          VariableRef.parse(el.get("target"), f"initial[{i}].to", source)))
        elif name == "dtc:Binding":
            i = len(bindings)
            bindings.append(ParameterBinding(VariableRef.parse(el.get("source"), f"bindings[{i}].from", source),
                                             VariableRef.parse(el.get("target"), f"bindings[{i}].to", source)))
        elif name == "dtc:Record":
            if el.get("variable"):
                record.append(el.get("variable"))
        elif name == "dtc:Analysis":
            analysis = _analysis_settings(el, ssd, source)
        else:
            raise element_error(el, ssd, "is not an element of dtcosim's annotation (dtc:Simulation, dtc:Initial, "
                                "dtc:Binding, dtc:Record, dtc:Analysis)", "remove it or export the scenario again")
    return sim, initial, record, analysis, step, bindings


def _analysis_settings(el, ssd: Path, source: str) -> AnalysisSettings:
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
        raise element_error(el, ssd, f"has a malformed number ({exc})", "write the attribute as decimal "
                            "numbers separated by spaces") from None
    for attr, key in (("rainflowResidue", "rainflow_residue"), ("spectrum", "spectrum")):
        if el.get(attr):
            kwargs[key] = el.get(attr)
    try:
        return AnalysisSettings(**kwargs)
    except ScenarioError as exc:
        raise ScenarioError(exc.key, exc.value, exc.expected, source) from None


def _fmu_interfaces(components: dict[str, str], base: Path) -> dict[str, Any]:
    """The model descriptions of the components' FMUs that exist (a missing one is reported by the run's checks)."""
    from ..cosim.fmu_interface import read_fmu_interface

    return {name: read_fmu_interface(base / source, f"components.{name}.fmu")
            for name, source in components.items() if (base / source).is_file()}


def _fmu_defaults(interfaces: dict[str, Any]) -> tuple[float | None, float | None]:
    """(smallest DefaultExperiment stepSize, smallest stopTime) among the FMUs that give one."""
    steps = [i.default_step_s for i in interfaces.values() if i.default_step_s]
    stops = [i.default_stop_s for i in interfaces.values() if i.default_stop_s]
    return (min(steps) if steps else None), (min(stops) if stops else None)


def _check_has_fmu(root, ssd: Path, source: str) -> None:
    """Refuse, before anything else, an SSP whose system has no FMU component (there is nothing to simulate)."""
    components = [el for el in root.iter() if isinstance(el.tag, str) and tag(el) == "ssd:Component"]
    fmus = [el for el in components if (el.get("type") or FMU_TYPE) == FMU_TYPE]
    if fmus:
        return
    others = sorted({el.get("type") for el in components})
    held = (f"its {len(components)} component(s) are of type {', '.join(others)}" if components
            else "it has no ssd:Component at all")
    raise SspError(f"{source}: holds no FMU: {ssd.name} has no ssd:Component of type {FMU_TYPE} ({held}); dtcosim "
                   "simulates systems of FMI 2.0 co-simulation FMUs, so there is nothing to run; add the FMUs "
                   "(resources/*.fmu) with an ssd:Component for each, or run the SSP in the tool that made it")


def import_ssp(path: str | Path, step_s: float | None = None, stop_s: float | None = None,
               report: Callable[[str], None] | None = None) -> Scenario:
    """Read a scenario from an ``.ssp`` archive, an SSP directory or a ``.ssd`` file.

    Parameters
    ----------
    path : path
    step_s, stop_s : float, optional
        Communication step and stop time to use where the SSP gives none
        (``--step``/``--stop``; see the module docstring).
    report : callable(str), optional
        Receives notes: annotations of other tools that were passed over, mapping
        entries with an empty source, parameter values not applied (no mapping
        entry in a binding with a mapping; a name that reaches no variable). The
        scenario keeps them (``Scenario.import_notes``; the run's summary lists them).

    Raises
    ------
    SspError
        Unreadable file, or an element dtcosim does not support (named, with its line).
    ScenarioError
        The content does not form a valid scenario (names the key, e.g. ``simulation.step``).
    """
    path = Path(path)
    ssd, base = locate_ssd(path)
    source = str(path)
    root = parse(ssd)
    if tag(root) != "ssd:SystemStructureDescription":
        raise element_error(root, ssd, "is not ssd:SystemStructureDescription (the root of an SSD, SSP 1.0)",
                            f"name an SSP 1.0 {SSD_NAME}, .ssp archive or SSP folder")
    _check_has_fmu(root, ssd, source)
    notes: list[str] = []
    check_supported(root, ssd, notes)
    units = unit_definitions(child(root, "ssd:Units"), ssd)
    flat = flatten(root, ssd, units, notes)
    interfaces = _fmu_interfaces(flat.components, base)
    ignored = list(flat.ignored)
    for (comp, var), (value, origin) in list(flat.values.items()):
        if comp in interfaces and var not in interfaces[comp].variables:
            del flat.values[(comp, var)]
            ignored.append(f"{var} ({origin}): {flat.components[comp]} ({interfaces[comp].model_name}) has no "
                           f"variable {var!r}")
    notes += [f"parameter value ignored (SSP 1.0, 5.2.3: its name reaches no variable): {entry}" for entry in ignored]
    system = children(root, "ssd:System")[0]
    name = re.sub(r"[^A-Za-z0-9_\-]", "-", root.get("name") or system.get("name") or path.stem)

    exp = child(root, "ssd:DefaultExperiment")
    start = float_attr(exp, "startTime", ssd, 0.0) if exp is not None else 0.0
    stop = float_attr(exp, "stopTime", ssd) if exp is not None else None
    step = None
    sim_kwargs: dict[str, Any] = {}
    initial: list[InitialBinding] = []
    bindings: list[ParameterBinding] = []
    record: list[str] = []
    analysis = AnalysisSettings()
    annotations = child(exp, "ssd:Annotations") if exp is not None else None
    for ann in children(annotations, "ssc:Annotation") if annotations is not None else []:
        if ann.get("type") == OSP_ANNOTATION:
            step = _osp_step(ann, ssd) if step is None else step
        elif ann.get("type") == DTCOSIM_ANNOTATION:
            sim_kwargs, initial, record, analysis, dtc_step, bindings = _dtcosim_settings(ann, ssd, source)
            step = dtc_step if dtc_step is not None else step
    if step is None or stop is None:
        fmu_step, fmu_stop = _fmu_defaults(interfaces)
        if step is None:
            step = step_s if step_s is not None else fmu_step
        if stop is None:
            stop = stop_s if stop_s is not None else fmu_stop
    if step is None:
        raise ScenarioError("simulation.step", None, "a communication step: the SSP has no osp:FixedStepAlgorithm "
                            "(or dtcosim) annotation in ssd:DefaultExperiment and its FMUs give no DefaultExperiment "
                            "stepSize; give it on the command line: --step H", source)
    if stop is None:
        raise ScenarioError("simulation.stop", None, "a stop time: the SSP's ssd:DefaultExperiment has no stopTime "
                            "and its FMUs give none; give it on the command line: --stop T", source)
    sim_kwargs.update(start_s=start, stop_s=stop, step_s=step)
    try:
        settings = SimulationSettings(**{k: v for k, v in sim_kwargs.items() if v is not None})
    except ScenarioError as exc:
        raise ScenarioError(exc.key, exc.value, exc.expected, source) from None

    bound = {str(b.target) for b in (*initial, *bindings)}  # set at initialisation, from their sources
    for (src, dst, origin) in flat.initial:
        initial.append(InitialBinding(VariableRef(*src), VariableRef(*dst)))
        bound.add(f"{dst[0]}.{dst[1]}")
    params: dict[str, dict[str, Any]] = {c: {} for c in flat.components}
    origins: dict[str, dict[str, Origin]] = {c: {} for c in flat.components}
    for (comp, var), (value, origin) in flat.values.items():
        if f"{comp}.{var}" not in bound:  # the binding sets it at initialisation
            params[comp][var] = value
            origins[comp][var] = Origin(origin)  # the ssv:Parameter's file and line: what a message names
    components = tuple(Component(c, Path(src), params[c], origins=origins[c]) for c, src in flat.components.items())
    connections = tuple(Connection(VariableRef(*src), VariableRef(*dst), transform)
                        for src, dst, transform, _ in flat.connections)
    for note in notes:
        if report is not None:
            report(note)
    return Scenario(
        name=name, description=system.get("description", ""), components=components, connections=connections,
        initial=tuple(initial), simulation=settings, recorded=tuple(record), analysis=analysis, base_dir=base,
        source=source, import_notes=tuple(notes), bindings=tuple(bindings),
    )


__all__ = ["import_ssp", "is_ssp", "locate_ssd", "SSD_NAME", "NS", "where"]
