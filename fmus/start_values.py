"""A copy of a dtcosim FMU whose parameters start at given values (for hosts that apply no parameter set).

A host that does not set a parameter runs the FMU with its start value. Some hosts
apply an SSP parameter set only when the user names it (ecos 0.7's
``--parameterSet``), so an exported SSP would run there with the FMUs' build
defaults. :func:`write_with_start_values` writes a copy of a dtcosim FMU in which
the values are the defaults, in both places a default lives:

* ``modelDescription.xml``: the ``start`` attribute of each variable (what hosts and
  ``fmpy`` read), a new GUID (the description changed; pythonfmu does not check it)
  and a sentence in the model's ``description`` saying which start values were set;
* ``resources/dtcosim.json``: the record's ``start_values`` (name -> value), which
  the slave applies right after it has built its interface from the record's model
  (:class:`fmus.slaves.base.DtcosimSlave`), before the host sets anything.

Everything else in the archive (code, binaries, documentation) is copied unchanged.
Only parameters and inputs can take start values (FMI 2.0: outputs of a dtcosim FMU
are ``initial="calculated"``).
"""

from __future__ import annotations

import hashlib
import io
import json
import uuid
import zipfile
from pathlib import Path
from typing import Mapping, Union
from xml.etree import ElementTree as ET

from .model_description import MODEL_DESCRIPTION, _format_real
from .slaves.record import RECORD_FILE, START_VALUES_KEY

Value = Union[float, int, bool, str]
_GUID_NAMESPACE = uuid.UUID("0c5e3c7a-8d1f-4b5e-a3f2-6f1d9b7e2a44")
_SETTABLE = ("parameter", "input")


class StartValueError(ValueError):
    """A start value that the FMU cannot take (names the FMU, the variable and why)."""


def _typed(fmu: str, name: str, fmi_type: str, value: Value) -> Value:
    """``value`` as the FMI type of variable ``name`` (no silent conversion of a wrong kind)."""
    if fmi_type == "Real":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise StartValueError(f"{fmu}: {name} is a Real variable; its start value must be a number, not {value!r}")
        return float(value)
    if fmi_type in ("Integer", "Enumeration"):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or int(value) != value:
            raise StartValueError(f"{fmu}: {name} is an {fmi_type} variable; its start value must be a whole number, "
                                  f"not {value!r}")
        return int(value)
    if fmi_type == "Boolean":
        if not isinstance(value, bool) and value not in (0, 1):
            raise StartValueError(f"{fmu}: {name} is a Boolean variable; its start value must be true or false, "
                                  f"not {value!r}")
        return bool(value)
    if not isinstance(value, str):
        raise StartValueError(f"{fmu}: {name} is a String variable; its start value must be a string, not {value!r}")
    return value


def _text(fmi_type: str, value: Value) -> str:
    if fmi_type == "Real":
        return _format_real(value)
    if fmi_type == "Boolean":
        return "true" if value else "false"
    return str(value)


def start_value_description(values: Mapping[str, Value]) -> str:
    """The sentence appended to the model's description of a copy with start values."""
    return (f" Start values of {len(values)} variable{'s' if len(values) != 1 else ''} set by dtcosim export-ssp "
            f"({', '.join(sorted(values))}; resources/{RECORD_FILE}, key {START_VALUES_KEY}).")


def write_with_start_values(source: str | Path, target: str | Path, values: Mapping[str, Value]) -> Path:
    """Write ``target``: a copy of the dtcosim FMU ``source`` whose variables in ``values`` start there.

    Parameters
    ----------
    source : path
        A dtcosim FMU (with ``resources/dtcosim.json``).
    target : path
        The copy to write (replaced if it exists).
    values : mapping of str -> value
        Variable name -> start value (parameters and inputs only).

    Returns
    -------
    pathlib.Path
        ``target``.

    Raises
    ------
    StartValueError
        ``source`` has no dtcosim record, or a name is not a parameter or input of it, or a
        value is not of the variable's type (all before anything is written).
    """
    source, target = Path(source), Path(target)
    record_member = f"resources/{RECORD_FILE}"
    with zipfile.ZipFile(source) as archive:
        members = [(info, archive.read(info)) for info in archive.infolist()]
    content = {info.filename: data for info, data in members}
    if record_member not in content:
        raise StartValueError(f"{source}: not a dtcosim FMU (no {record_member}); its start values cannot be set")
    root = ET.fromstring(content[MODEL_DESCRIPTION])
    nodes = {sv.get("name"): sv for sv in root.iter("ScalarVariable")}
    typed: dict[str, Value] = {}
    for name, value in values.items():
        node = nodes.get(name)
        if node is None:
            raise StartValueError(f"{source}: has no variable {name!r}")
        if node.get("causality", "local") not in _SETTABLE:
            raise StartValueError(f"{source}: {name} has causality {node.get('causality', 'local')!r}; only a "
                                  f"parameter or an input takes a start value here")
        element = next(child for child in node if child.tag in ("Real", "Integer", "Boolean", "String", "Enumeration"))
        typed[name] = _typed(source.name, name, element.tag, value)
        element.set("start", _text(element.tag, typed[name]))
    digest = hashlib.sha256(json.dumps(typed, sort_keys=True).encode()).hexdigest()
    root.set("guid", "{" + str(uuid.uuid5(_GUID_NAMESPACE, f"{root.get('guid')}:{digest}")) + "}")
    description = root.get("description", "").rstrip()
    root.set("description", description + ("" if not description or description.endswith(".") else ".")
             + start_value_description(typed))
    buffer = io.BytesIO()
    ET.ElementTree(root).write(buffer, encoding="UTF-8", xml_declaration=True)
    record = json.loads(content[record_member])
    record[START_VALUES_KEY] = {**record.get(START_VALUES_KEY, {}), **typed}
    replacements = {MODEL_DESCRIPTION: buffer.getvalue() + b"\n",
                    record_member: json.dumps(record, indent=1).encode()}
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(target.name + ".tmp")
    with zipfile.ZipFile(tmp, "w") as archive:
        for info, data in members:
            archive.writestr(info, replacements.get(info.filename, data))
    tmp.replace(target)
    return target
