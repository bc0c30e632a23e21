"""Post-processing of the ``modelDescription.xml`` that pythonfmu writes.

pythonfmu emits neither units nor ``InitialUnknowns``; this module adds

* ``UnitDefinitions`` (FMI 2 ``Unit`` with ``BaseUnit`` exponents where the unit
  has an integer SI expression, plus display units such as rpm and deg) and the
  ``unit`` attribute of every Real variable;
* ``ModelStructure/InitialUnknowns`` listing the outputs (they are
  ``initial="calculated"``: computed from parameters and inputs in
  initialisation mode) and ``dependencies=""`` on every output (no direct
  feedthrough: outputs change only in ``doStep``);
* a deterministic GUID derived from the build hash and the generation tool;
* ``VendorAnnotations`` with the dtcosim tool entry: the component's declared
  role and where its record is (``resources/dtcosim.json``);
* ``min`` and ``max`` of every parameter whose validation has a simple range
  (:class:`components.validation.Bounds`; FMI bounds are inclusive like these),
  so any host can check a value before it instantiates the FMU.
"""

from __future__ import annotations

import io
import uuid
import zipfile
from pathlib import Path
from typing import Any, Iterable, Mapping
from xml.etree import ElementTree as ET

from .slaves.interface import OUTPUT, REAL, UNITS, Variable

MODEL_DESCRIPTION = "modelDescription.xml"
#: zlib level of the members an FMU's archive is written with: 4 rather than zlib's default 6 (the members of a run's
#: three FMUs compressed in 70 against 118 ms of CPU here; level 1: 50 ms), archives ~2 % larger
#: (``benchmarks/bench_builds.py --baseline REV`` prints the sizes against REV's)
COMPRESS_LEVEL = 4
_GUID_NAMESPACE = uuid.UUID("7b0f4c3e-52a1-4d6e-9f43-1d2f0c6a9e11")


class ModelDescriptionError(RuntimeError):
    """The generated model description does not match the slave's declared interface."""


def _format_factor(x: float) -> str:
    return repr(float(x))


def _format_real(x: float) -> str:
    """xs:double text that reads back as exactly ``x``."""
    x = float(x)
    if x != x:
        return "NaN"
    if x in (float("inf"), float("-inf")):
        return "INF" if x > 0 else "-INF"
    return repr(x)


def unit_definitions(unit_names: Iterable[str]) -> ET.Element:
    """``UnitDefinitions`` element for the given units (sorted by name)."""
    root = ET.Element("UnitDefinitions")
    for name in sorted(set(unit_names)):
        unit = UNITS[name]
        node = ET.SubElement(root, "Unit", name=unit.name)
        if unit.base_exponents is not None:
            ET.SubElement(node, "BaseUnit", {k: str(v) for k, v in unit.base_exponents.items()})
        for display, factor in unit.display_units.items():
            ET.SubElement(node, "DisplayUnit", name=display, factor=_format_factor(factor))
    return root


def finalize(xml: bytes, variables: tuple[Variable, ...], build_id: str, generation_tool: str,
             role: str = "", record_file: str = "", bounds: Mapping[str, Any] | None = None) -> bytes:
    """Add units, InitialUnknowns, output dependencies, a deterministic GUID and the vendor annotation.

    Parameters
    ----------
    xml : bytes
        modelDescription.xml as written by pythonfmu.
    variables : tuple of Variable
        The slave's interface, in value-reference order.
    build_id : str
        Hash of the code and configuration the FMU was built from.
    generation_tool : str
        Value of the ``generationTool`` attribute.
    role, record_file : str
        The component's role and its record's path in the archive, written as
        ``<VendorAnnotations><Tool name="dtcosim"><Component role=... record=.../></Tool>``
        (omitted when empty).
    bounds : mapping of str -> Bounds, optional
        Parameter ranges, written as the ``min``/``max`` attributes of their type element.

    Returns
    -------
    bytes
        The new modelDescription.xml (UTF-8).
    """
    root = ET.fromstring(xml)
    model_variables = root.find("ModelVariables")
    scalars = model_variables.findall("ScalarVariable")
    if [s.get("name") for s in scalars] != [v.name for v in variables]:
        raise ModelDescriptionError("modelDescription.xml variables differ from the slave's interface")
    for index, (node, var) in enumerate(zip(scalars, variables)):
        if int(node.get("valueReference")) != index:
            raise ModelDescriptionError(f"{var.name}: value reference {node.get('valueReference')} != {index}")
        if var.type == REAL:
            real = node.find(REAL)
            real.set("unit", var.unit)
            if var.start is not None:  # exact round trip (pythonfmu writes 16 significant digits)
                real.set("start", _format_real(var.start))
        b = (bounds or {}).get(var.name)
        if b is not None and var.type in (REAL, "Integer"):
            element = node.find(var.type)
            text = _format_real if var.type == REAL else (lambda x: str(int(x)))
            element.set("min", text(b.minimum))
            element.set("max", text(b.maximum))

    root.set("guid", "{" + str(uuid.uuid5(_GUID_NAMESPACE, f"{root.get('modelName')}:{build_id}:{generation_tool}")) + "}")
    root.set("generationTool", generation_tool)

    co_simulation = root.find("CoSimulation")
    position = list(root).index(co_simulation) + 1
    root.insert(position, unit_definitions(v.unit for v in variables if v.type == REAL))
    if role:
        annotations = ET.Element("VendorAnnotations")
        tool = ET.SubElement(annotations, "Tool", name="dtcosim")
        ET.SubElement(tool, "Component", role=role, record=record_file)
        before = next((i for i, child in enumerate(root) if child.tag in ("ModelVariables",)), len(root))
        for existing in root.findall("VendorAnnotations"):
            root.remove(existing)
        root.insert(before, annotations)

    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    output_indices = [i + 1 for i, v in enumerate(variables) if v.causality == OUTPUT]
    if output_indices:
        outputs = ET.SubElement(structure, "Outputs")
        for index in output_indices:
            ET.SubElement(outputs, "Unknown", index=str(index), dependencies="")
        initial = ET.SubElement(structure, "InitialUnknowns")
        for index in output_indices:
            ET.SubElement(initial, "Unknown", index=str(index))

    ET.indent(root, space="  ")
    buffer = io.BytesIO()
    ET.ElementTree(root).write(buffer, encoding="UTF-8", xml_declaration=True)
    return buffer.getvalue() + b"\n"


def read_member(fmu_path: Path, name: str = MODEL_DESCRIPTION) -> bytes:
    """One file of an FMU archive."""
    with zipfile.ZipFile(fmu_path) as archive:
        return archive.read(name)


def _new_member(name: str) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
    return info


def add_members(fmu_path: Path, members: dict[str, bytes]) -> None:
    """Append new members to an FMU archive in place, without recompressing the others.

    For an archive still being built (under a temporary name: an interrupted append leaves a damaged
    file, which the build discards); a name already in the archive is an error (:func:`rewrite_archive`
    replaces members).
    """
    with zipfile.ZipFile(fmu_path, "a") as archive:
        present = set(archive.namelist()) & set(members)
        if present:
            raise ValueError(f"{fmu_path} already has {', '.join(sorted(present))}")
        for name in sorted(members):
            archive.writestr(_new_member(name), members[name], compresslevel=COMPRESS_LEVEL)


def rewrite_archive(fmu_path: Path, replacements: dict[str, bytes]) -> None:
    """Rewrite an FMU archive (deflate-compressed) with some members replaced; new names are added."""
    fmu_path = Path(fmu_path)
    with zipfile.ZipFile(fmu_path) as archive:
        members = [(info, archive.read(info)) for info in archive.infolist()]
    tmp = fmu_path.with_suffix(".fmu.tmp")
    present = {info.filename for info, _ in members}
    with zipfile.ZipFile(tmp, "w") as archive:
        for info, data in members:
            archive.writestr(info, replacements.get(info.filename, data), zipfile.ZIP_DEFLATED, COMPRESS_LEVEL)
        for name in sorted(set(replacements) - present):
            archive.writestr(_new_member(name), replacements[name], compresslevel=COMPRESS_LEVEL)
    tmp.replace(fmu_path)
