"""What an FMU offers, read from its ``modelDescription.xml`` (no instantiation).

:func:`read_fmu_interface` gives an :class:`FmuInterface`: the variables with
value reference, type, causality, variability and unit, the direct-feedthrough
dependencies of the outputs (ModelStructure), the co-simulation capabilities,
the file's SHA-256 and, for an FMU dtcosim built, its record
(``resources/dtcosim.json``: declared role, the parameter set it was built from,
the signals of its outputs; :mod:`fmus.slaves.record`). Reading is cached per
(path, size, mtime).
"""

from __future__ import annotations

import hashlib
import json
import os
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..archive_members import shown_path
from ..errors import ScenarioError
from ..frozen_map import FrozenMap
from .unpacked_fmus import is_unpacked


@dataclass(frozen=True)
class FmuVariable:
    """One scalar variable of an FMU.

    Attributes
    ----------
    name : str
    value_reference : int
    type : {"Real", "Integer", "Boolean", "String", "Enumeration"}
    causality : str
        ``parameter``, ``calculatedParameter``, ``input``, ``output``, ``local``, ``independent``.
    variability : str
        ``constant``, ``fixed``, ``tunable``, ``discrete``, ``continuous``.
    unit : str
        Unit string ("" when the FMU declares none).
    description : str
    start : Any
        Start value as declared (None when absent).
    initial : str
        ``exact``, ``approx``, ``calculated`` or "" (FMI 2: ``initial`` attribute, the
        default of its causality and variability when absent; "" where none applies).
    declared_type : str
        Name of the variable's ``declaredType`` ("" when none; an Enumeration's type).
    minimum, maximum : float or int or None
        The ``min`` and ``max`` attributes (None when absent).
    """

    name: str
    value_reference: int
    type: str
    causality: str
    variability: str
    unit: str = ""
    description: str = ""
    start: Any = None
    initial: str = ""
    declared_type: str = ""
    minimum: float | int | None = None
    maximum: float | int | None = None


@dataclass(frozen=True)
class FmuInterface:
    """The interface of one FMU file.

    Attributes
    ----------
    path : pathlib.Path
        Absolute path of the ``.fmu``.
    model_name, model_identifier, guid, fmi_version, generation_tool : str
    variables : mapping of str -> FmuVariable
        By variable name, in declaration order.
    output_dependencies : mapping of str -> tuple of str or None
        For each output (ModelStructure/Outputs): the inputs it depends on
        directly; ``None`` when the FMU gives no ``dependencies`` attribute, which
        per FMI 2 means "depends on all inputs".
    can_handle_variable_step, can_get_and_set_state : bool
    sha256 : str
        Hex digest of the FMU file.
    default_step_s : float or None
        DefaultExperiment stepSize.
    unit_definitions : mapping of str -> mapping of str -> float
        FMI 2 UnitDefinitions: unit name -> SI base-unit exponents (``kg``, ``m``, ``s``,
        ``A``, ``K``, ``mol``, ``cd``, ``rad``) and ``factor``, ``offset`` (non-default entries only).
    record : mapping or None
        The dtcosim record of an FMU dtcosim built (``role``, ``source``, ``model``,
        ``signals``); None for any other FMU.
    platforms : tuple of str
        Platforms the archive has a co-simulation binary for (``binaries/<platform>/<modelIdentifier>.<ext>``,
        e.g. ``("linux64", "win64")``).
    default_start_s, default_stop_s : float or None
        DefaultExperiment startTime and stopTime.
    enumerations : mapping of str -> mapping of str -> int
        Enumeration types (TypeDefinitions): type name -> item name -> value.
    """

    path: Path
    model_name: str
    model_identifier: str
    guid: str
    fmi_version: str
    generation_tool: str
    variables: Mapping[str, FmuVariable]
    output_dependencies: Mapping[str, tuple[str, ...] | None]
    can_handle_variable_step: bool
    can_get_and_set_state: bool
    sha256: str
    default_step_s: float | None = None
    unit_definitions: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    record: Mapping[str, Any] | None = field(default=None, repr=False)
    platforms: tuple[str, ...] = ()
    default_start_s: float | None = None
    default_stop_s: float | None = None
    enumerations: Mapping[str, Mapping[str, int]] = field(default_factory=dict)
    _inputs: tuple[str, ...] = field(default=(), repr=False)

    def variable(self, name: str) -> FmuVariable:
        """The variable called ``name`` (KeyError if absent)."""
        return self.variables[name]

    @property
    def inputs(self) -> tuple[str, ...]:
        """Names of the input variables."""
        return self._inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        """Names of the output variables."""
        return tuple(n for n, v in self.variables.items() if v.causality == "output")

    def direct_inputs_of(self, output: str) -> tuple[str, ...]:
        """Inputs an output depends on directly (all inputs when undeclared)."""
        deps = self.output_dependencies.get(output)
        return self._inputs if deps is None else deps


_CACHE: dict[tuple[str, int, int], FmuInterface] = {}


def _typed_start(type_: str, start: Any) -> Any:
    """A start value from the XML (a string) as a Python value of the variable's type."""
    if start is None:
        return None
    try:
        if type_ == "Real":
            return float(start)
        if type_ in ("Integer", "Enumeration"):
            return int(start)
        if type_ == "Boolean":
            return str(start).strip().lower() in ("true", "1")
    except ValueError:
        return start
    return str(start)


def _initial(v) -> str:
    """The FMI 2.0 ``initial`` of a variable, with the standard's default when absent (Table in 2.2.7)."""
    if v.initial:
        return str(v.initial)
    causality = v.causality or "local"
    variability = v.variability or ("continuous" if v.type == "Real" else "discrete")
    if variability == "constant" or causality == "parameter":
        return "exact"
    if causality in ("calculatedParameter", "output", "local"):
        return "calculated"
    return ""


def _bound(type_: str, text: Any) -> float | int | None:
    """A ``min``/``max`` attribute as a number (None when absent or not a number)."""
    value = _typed_start(type_, text) if type_ in ("Real", "Integer", "Enumeration") else None
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def read_fmu_record(path: Path, key: str) -> dict[str, Any] | None:
    """The dtcosim record in an FMU archive, None if it has none.

    Raises
    ------
    ScenarioError
        A record that is there but unreadable or of another format (names the file).
    """
    from fmus.slaves.record import RECORD_FILE, RECORD_FORMAT, ROLES

    member = f"resources/{RECORD_FILE}"
    try:
        with zipfile.ZipFile(path) as archive:
            if member not in archive.namelist():
                return None
            record = json.loads(archive.read(member))
    except (OSError, zipfile.BadZipFile, zlib.error, EOFError, ValueError) as exc:
        raise ScenarioError(key, shown_path(path), f"an FMU with a readable {member} ({exc})") from None
    if not isinstance(record, dict) or record.get("format") != RECORD_FORMAT or record.get("role") not in ROLES \
            or not isinstance(record.get("model"), dict) or not isinstance(record.get("signals"), dict):
        raise ScenarioError(key, shown_path(path), f"an FMU whose {member} is a dtcosim record of format {RECORD_FORMAT} "
                            f"with a role ({', '.join(ROLES)}), a model and signals")
    return record


def file_sha256(path: str | Path) -> str:
    """SHA-256 hex digest of a file."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def read_fmu_interface(path: str | Path, key: str = "fmu") -> FmuInterface:
    """Read an FMU's model description (XML only; nothing is loaded or instantiated).

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.fmu`` file.
    key : str
        Scenario key reported in errors (e.g. ``"components.gearbox.fmu"``).

    Raises
    ------
    ScenarioError
        If the file is missing, unreadable, no regular file, beyond the archive limits, damaged
        (:func:`fmus.archive_checks.layout_problems`, :func:`fmus.archive_checks.corrupt_member`),
        not FMI 2.0 or not co-simulation, or it
        cannot be loaded here (no binary for this platform, a PythonFMU or dtcosim
        FMU without its resources: :func:`fmus.archive_checks.archive_problems`).
    """
    from fmpy import read_model_description

    p = Path(path).resolve()
    shown = shown_path(path)  # a member of an .ssp as <archive>!<member>, not its temporary copy
    try:
        st = os.stat(p)
    except OSError:
        raise ScenarioError(key, shown, "an existing FMU file") from None
    cache_key = (str(p), st.st_size, st.st_mtime_ns)
    if cache_key in _CACHE:
        return _CACHE[cache_key]
    from fmus.archive_checks import corrupt_member, layout_problems

    problems = layout_problems(p)  # before anything is decompressed: a pipe, a zip bomb, a zip-slip name
    sha256 = None if problems else file_sha256(p)
    # every member is read (CRC checked) unless an archive of this content was unpacked whole before
    damaged = None if problems or is_unpacked(sha256) else corrupt_member(p)
    if problems or damaged:
        raise ScenarioError(key, shown, f"a readable FMU ({'; '.join(problems) or damaged})")
    try:
        md = read_model_description(str(p), validate=False)
    except Exception as exc:  # fmpy raises plain Exceptions for broken archives/XML
        raise ScenarioError(key, shown, f"a readable FMU ({exc})") from None
    if not str(md.fmiVersion).startswith("2."):
        raise ScenarioError(key, shown, f"an FMI 2.0 FMU (this is FMI {md.fmiVersion})")
    if md.coSimulation is None:
        raise ScenarioError(key, shown, "a co-simulation FMU")
    from fmus.archive_checks import archive_problems, binary_platforms

    problems = archive_problems(p, md.coSimulation.modelIdentifier, md.generationTool or "")
    if problems:
        raise ScenarioError(key, shown, f"an FMU this host can load ({'; '.join(problems)})")
    variables: dict[str, FmuVariable] = {}
    for v in md.modelVariables:
        unit = v.unit or (v.declaredType.unit if v.declaredType is not None and getattr(v.declaredType, "unit", None) else "")
        variables[v.name] = FmuVariable(
            name=v.name,
            value_reference=int(v.valueReference),
            type=str(v.type),
            causality=str(v.causality or "local"),
            variability=str(v.variability or ("continuous" if v.type == "Real" else "discrete")),
            unit=unit or "",
            description=v.description or "",
            start=_typed_start(str(v.type), v.start),
            initial=_initial(v),
            declared_type=str(v.declaredType.name) if v.declaredType is not None else "",
            minimum=_bound(str(v.type), getattr(v, "min", None)),
            maximum=_bound(str(v.type), getattr(v, "max", None)),
        )
    inputs = tuple(n for n, v in variables.items() if v.causality == "input")
    deps: dict[str, tuple[str, ...] | None] = {}
    for u in md.outputs:
        name = u.variable.name
        deps[name] = None if u.dependencies is None else tuple(d.name for d in u.dependencies if d.causality == "input")
    for name, v in variables.items():  # outputs missing from ModelStructure: depend on all inputs (FMI 2)
        if v.causality == "output" and name not in deps:
            deps[name] = None
    cs = md.coSimulation
    default_step = default_start = default_stop = None
    if md.defaultExperiment is not None:
        de = md.defaultExperiment
        default_step = float(de.stepSize) if de.stepSize else None
        default_start = float(de.startTime) if de.startTime is not None else None
        default_stop = float(de.stopTime) if de.stopTime is not None else None
    units: dict[str, dict[str, float]] = {}
    for u in md.unitDefinitions or ():
        b = u.baseUnit
        if b is None:
            continue
        entry = {k: getattr(b, k) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad") if getattr(b, k)}
        if b.factor != 1.0:
            entry["factor"] = float(b.factor)
        if b.offset != 0.0:
            entry["offset"] = float(b.offset)
        units[u.name] = entry
    iface = FmuInterface(
        path=p,
        model_name=md.modelName or "",
        model_identifier=cs.modelIdentifier,
        guid=md.guid,
        fmi_version=md.fmiVersion,
        generation_tool=md.generationTool or "",
        variables=FrozenMap(variables),
        output_dependencies=FrozenMap(deps),
        can_handle_variable_step=bool(cs.canHandleVariableCommunicationStepSize),
        can_get_and_set_state=bool(cs.canGetAndSetFMUstate),
        sha256=sha256,
        default_step_s=default_step,
        unit_definitions=FrozenMap(units),
        record=read_fmu_record(p, key),
        platforms=binary_platforms(p, cs.modelIdentifier),
        default_start_s=default_start,
        default_stop_s=default_stop,
        enumerations=FrozenMap({t.name: FrozenMap({i.name: int(i.value) for i in t.items})
                                for t in md.typeDefinitions or () if t.type == "Enumeration"}),
        _inputs=inputs,
    )
    _CACHE[cache_key] = iface
    return iface
