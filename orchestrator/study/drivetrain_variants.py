"""Studies that vary entries of a drivetrain file: one FMU set per structure, flat parameters for the rest.

A study parameter ``<component>.drivetrain.<key path>`` (``gearbox.drivetrain.stages[0].planets``,
``gearbox.drivetrain.stages[1].teeth.drive``, ``gearbox.drivetrain.generator.inertia``) changes an
entry of the drivetrain file the component is built from
(:func:`orchestrator.inputs.drivetrain_file.with_entries`). Each point's file is read
again (so a derived mass follows a changed face width, and an invalid combination is a
study error naming the point before anything runs) and becomes a drivetrain ``D``.

Points whose drivetrains share a *structure* run on the same FMUs: the first such
drivetrain ``T`` is built (into its content folder of the FMU directory) and another
point's ``D`` is its flat parameter values on ``T``'s FMUs, which is exact because the
structure test is ``unflatten(T, flatten(D)) == D``
(:mod:`components.model.parameter_map`). A point that changes the structure (the
number of planets, planet angles, stage kinds, ...) gets FMUs of its own structure.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Mapping

from components.model.drivetrain import Drivetrain
from components.model.parameter_map import flatten, unflatten
from fmus.registry import of_file, with_role
from fmus.slaves.record import GEARBOX, GENERATOR

from ..errors import EntryError
from ..inputs.drivetrain_entries import with_entries
from ..inputs.drivetrain_file import DrivetrainSpec
from ..inputs.study import Point, Study, StudyError, split_parameter

#: ``<component>.drivetrain.<key path>``
FILE_ENTRY = re.compile(r"^(?P<component>[A-Za-z_][A-Za-z0-9_\-]*)\.drivetrain\.(?P<path>.+)$")


def is_file_entry(name: str) -> bool:
    """Whether a study parameter changes a drivetrain file entry."""
    return FILE_ENTRY.match(name) is not None


@dataclass(frozen=True)
class PointVariant:
    """How one point runs: the structure's system and the FMU parameter values its drivetrain needs.

    Attributes
    ----------
    structure : str
        Key of :attr:`DrivetrainVariants.systems`.
    parameters : mapping of str -> float
        ``"component.parameter"`` values replacing the point's file entries.
    """

    structure: str
    parameters: Mapping[str, float]


@dataclass(frozen=True)
class DrivetrainVariants:
    """Per structure a resolved system, per point index a :class:`PointVariant`."""

    systems: Mapping[str, Any]
    points: Mapping[int, PointVariant]


def _study_key(study: Study, name: str, point: Point) -> str:
    """The study key that set ``name`` for ``point`` (an axis, an explicit point or the base)."""
    for i, axis in enumerate(study.axes):
        if name in axis.parameters:
            return f"axes[{i}].parameter"
    for i, pt in enumerate(study.points):
        if name in pt:
            return f"points[{i}].{name}"
    return f"base.parameters.{name}"


def _gearbox_values(drivetrain: Drivetrain) -> dict[str, float]:
    return {k: v for k, v in flatten(drivetrain).items() if not k.startswith(("generator.", "output_torque"))}


def _project_role(component) -> str | None:
    """The role of the project FMU a component names (:func:`fmus.registry.of_file`; None: not one)."""
    kind = of_file(component.fmu)
    return kind.role if kind is not None else None


def drivetrain_variants(study: Study, scenario, points: list[Point], fmu_dir: Path,
                        build: bool) -> DrivetrainVariants | None:
    """The structures and per-point parameters of a study that varies drivetrain file entries (None if it does not).

    Raises
    ------
    StudyError
        A file entry of a component without a drivetrain file, a key path the file does not have, a
        point whose changed file is invalid, or a file entry together with an FMU parameter it would set.
    """
    from ..cosim.system import resolve_system
    from ..provision.drivetrain_fmus import ensure_drivetrain_fmus
    from ..provision.locate import resolve_fmu_paths

    src = study.source
    names = list(study.base.parameters) + study.varied_parameters
    entries = [n for n in names if is_file_entry(n)]
    if not entries:
        return None
    by_component: dict[str, DrivetrainSpec] = {}
    for name in entries:
        comp = FILE_ENTRY.match(name)["component"]
        component = next((c for c in scenario.components if c.name == comp), None)
        if component is None or component.drivetrain is None:
            raise StudyError(_study_key(study, name, Point(0, {}, ())), name,
                             "a file entry <component>.drivetrain.<key> of a component built from a drivetrain file"
                             + (f" ({comp} names none)" if component is not None else f" (no component {comp})"), src)
        if _project_role(component) != GEARBOX:
            raise StudyError(_study_key(study, name, Point(0, {}, ())), name,
                             f"a file entry of the gearbox component (the one whose fmu is the project's "
                             f"{with_role(GEARBOX).file_name}, not {comp})", src)
        by_component[comp] = component.drivetrain
    if len(by_component) > 1:
        raise StudyError("axes", sorted(by_component), "file entries of one gearbox component", src)
    (gear_name, original), = by_component.items()
    users = [c for c in scenario.components if c.drivetrain is not None and c.drivetrain.sha256 == original.sha256]
    generators = [c.name for c in users if _project_role(c) == GENERATOR]
    fixed = {n: v for n, v in study.base.parameters.items() if is_file_entry(n)}
    allow = [k.split(".", 1)[1] for k in study.allow_implausible if k.split(".", 1)[0] == gear_name]

    templates: list[tuple[str, DrivetrainSpec]] = []
    variants: dict[str, PointVariant] = {}
    for point in points:
        changes = {**fixed, **{n: v for n, v in point.parameters.items() if is_file_entry(n)}}
        try:
            spec = original if not changes else with_entries(
                original, {FILE_ENTRY.match(n)["path"]: v for n, v in changes.items()}, allow)
        except EntryError as exc:
            culprit = next((n for n in changes if FILE_ENTRY.match(n)["path"] == exc.key), next(iter(changes)))
            origin = {**study.base_origins(), **study.origins(point)}[culprit]  # where the study gives it
            raise origin.refusal(culprit, changes.get(culprit), f"a drivetrain file entry that gives a valid "
                                 f"drivetrain ({exc.key} = {exc.value!r}: expected {exc.expected})") from None
        dt = spec.cosim_drivetrain()
        values = flatten(dt)
        structure = None
        for sid, template in templates:
            t = template.drivetrain
            if flatten(t).keys() == values.keys() and unflatten(t, values) == dt:
                structure = sid
                break
        if structure is None:
            structure = spec.key
            templates.append((structure, spec))
        template = dict(templates)[structure].drivetrain
        base_values = flatten(template)
        params = {f"{gear_name}.{k}": v for k, v in _gearbox_values(dt).items() if v != base_values[k]}
        for gen in generators:
            for flat, fmu_name in (("generator.inertia", "inertia"), ("generator.counter_torque", "counter_torque")):
                if values[flat] != base_values[flat]:
                    params[f"{gen}.{fmu_name}"] = values[flat]
        for name in params:
            comp, param = split_parameter(name)
            if name in point.parameters or name in study.base.parameters or \
                    param in scenario.component(comp).parameters:
                raise StudyError(_study_key(study, next(iter(changes)), point), name,
                                 "file entries that do not change an FMU parameter the study or the scenario also sets "
                                 f"({name})", src)
        variants[point.index] = PointVariant(structure, params)

    systems = {}
    for sid, spec in templates:
        comps = tuple(replace(c, drivetrain=spec) if c in users else c for c in scenario.components)
        variant_scenario = replace(scenario, components=comps)
        if build:
            ensure_drivetrain_fmus(spec, fmu_dir, [c.fmu.stem for c in users])
        systems[sid] = resolve_system(variant_scenario, fmu_paths=resolve_fmu_paths(variant_scenario, fmu_dir))
    return DrivetrainVariants(systems, variants)
