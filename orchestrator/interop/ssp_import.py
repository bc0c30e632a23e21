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
    window, algorithm, extrapolation, order, records, initial bindings, analysis).

* without either annotation the step is ``--step`` (``step_s``), else the
  smallest DefaultExperiment ``stepSize`` of the FMUs, else a ScenarioError that
  says to give ``--step``; the stop time is the SSD's ``stopTime``, else
  ``--stop``, else the FMUs' DefaultExperiment ``stopTime``, else an error naming
  ``--stop``.

Everything else in the file that dtcosim does not support is refused naming the
element, the file and the line (:func:`orchestrator.interop.ssp_xml.check_supported`);
annotations of other tools are reported as notes.
"""

from __future__ import annotations

import atexit
import hashlib
import re
import shutil
import tempfile
import zipfile
from pathlib import Path
from typing import Any, Callable

from lxml import etree

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
from .ssp_system import flatten
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


def locate_ssd(path: Path) -> tuple[Path, Path]:
    """(the SSD file, the folder component sources are relative to) of an archive, folder or ``.ssd``."""
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
    return ssd, base


def _osp_step(annotation, ssd: Path) -> float | None:
    """baseStepSize of an OSP annotation (any content other than the fixed-step algorithm is refused)."""
    step = None
    for el in annotation:
        if not isinstance(el.tag, str):
            continue
        qname = etree.QName(el)
        if qname.namespace not in OSP_NAMESPACES or qname.localname != "Algorithm":
            raise element_error(el, ssd, "is not supported in the OSP annotation (dtcosim reads osp:Algorithm)")
        for alg in el:
            if not isinstance(alg.tag, str):
                continue
            q = etree.QName(alg)
            if q.namespace not in OSP_NAMESPACES or q.localname != "FixedStepAlgorithm":
                raise element_error(alg, ssd, "is not supported (dtcosim runs osp:FixedStepAlgorithm)")
            step = float_attr(alg, "baseStepSize", ssd)
            if step is None:
                raise element_error(alg, ssd, "has no baseStepSize")
    return step


def _dtcosim_settings(annotation, ssd: Path, source: str) -> tuple[dict, list, list, AnalysisSettings, float | None]:
    """(simulation keyword arguments, initial bindings, record patterns, analysis settings, step) of dtcosim's annotation."""
    sim: dict[str, Any] = {}
    initial: list[InitialBinding] = []
    record: list[str] = []
    analysis = AnalysisSettings()
    step = None
    scenario_el = child(annotation, "dtc:Scenario")
    if scenario_el is None:
        raise element_error(annotation, ssd, "of type org.dtcosim.scenario has no dtc:Scenario")
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
        elif name == "dtc:Record":
            if el.get("variable"):
                record.append(el.get("variable"))
        elif name == "dtc:Analysis":
            analysis = _analysis_settings(el, ssd, source)
        else:
            raise element_error(el, ssd, "is not an element of dtcosim's annotation")
    return sim, initial, record, analysis, step


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
        raise element_error(el, ssd, f"has a malformed number ({exc})") from None
    for attr, key in (("rainflowResidue", "rainflow_residue"), ("spectrum", "spectrum")):
        if el.get(attr):
            kwargs[key] = el.get(attr)
    try:
        return AnalysisSettings(**kwargs)
    except ScenarioError as exc:
        raise ScenarioError(exc.key, exc.value, exc.expected, source) from None


def _fmu_defaults(components: dict[str, str], base: Path) -> tuple[float | None, float | None]:
    """(smallest DefaultExperiment stepSize, smallest stopTime) among the components' FMUs that give one."""
    from ..cosim.fmu_interface import read_fmu_interface

    steps, stops = [], []
    for name, source in components.items():
        path = base / source
        if path.is_file():
            iface = read_fmu_interface(path, f"components.{name}.fmu")
            if iface.default_step_s:
                steps.append(iface.default_step_s)
            if iface.default_stop_s:
                stops.append(iface.default_stop_s)
    return (min(steps) if steps else None), (min(stops) if stops else None)


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
        Receives notes (annotations of other tools that were passed over).

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
        raise element_error(root, ssd, "is not ssd:SystemStructureDescription (the root of an SSD)")
    notes: list[str] = []
    check_supported(root, ssd, notes)
    units = unit_definitions(child(root, "ssd:Units"), ssd)
    flat = flatten(root, ssd, units, notes)
    system = children(root, "ssd:System")[0]
    name = re.sub(r"[^A-Za-z0-9_\-]", "-", root.get("name") or system.get("name") or path.stem)

    exp = child(root, "ssd:DefaultExperiment")
    start = float_attr(exp, "startTime", ssd, 0.0) if exp is not None else 0.0
    stop = float_attr(exp, "stopTime", ssd) if exp is not None else None
    step = None
    sim_kwargs: dict[str, Any] = {}
    initial: list[InitialBinding] = []
    record: list[str] = []
    analysis = AnalysisSettings()
    annotations = child(exp, "ssd:Annotations") if exp is not None else None
    for ann in children(annotations, "ssc:Annotation") if annotations is not None else []:
        if ann.get("type") == OSP_ANNOTATION:
            step = _osp_step(ann, ssd) if step is None else step
        elif ann.get("type") == DTCOSIM_ANNOTATION:
            sim_kwargs, initial, record, analysis, dtc_step = _dtcosim_settings(ann, ssd, source)
            step = dtc_step if dtc_step is not None else step
    if step is None or stop is None:
        fmu_step, fmu_stop = _fmu_defaults(flat.components, base)
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

    bound = {str(b.target) for b in initial}
    for (src, dst, origin) in flat.initial:
        initial.append(InitialBinding(VariableRef(*src), VariableRef(*dst)))
        bound.add(f"{dst[0]}.{dst[1]}")
    params: dict[str, dict[str, Any]] = {c: {} for c in flat.components}
    for (comp, var), (value, origin) in flat.values.items():
        if f"{comp}.{var}" not in bound:  # the binding sets it at initialisation
            params[comp][var] = value
    components = tuple(Component(c, Path(src), params[c]) for c, src in flat.components.items())
    connections = tuple(Connection(VariableRef(*src), VariableRef(*dst), transform)
                        for src, dst, transform, _ in flat.connections)
    for note in notes:
        if report is not None:
            report(note)
    return Scenario(
        name=name, description=system.get("description", ""), components=components, connections=connections,
        initial=tuple(initial), simulation=settings, recorded=tuple(record), analysis=analysis, base_dir=base,
        source=source,
    )


__all__ = ["import_ssp", "locate_ssd", "SSD_NAME", "NS", "where"]
