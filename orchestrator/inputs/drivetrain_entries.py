"""Changing entries of a drivetrain file by key path (``stages[0].planets``), for studies."""

from __future__ import annotations

import copy
import hashlib
import json
from typing import Any, Mapping, Sequence

from .drivetrain_file import DrivetrainSpec, drivetrain_from_dict
from .drivetrain_plausibility import split_path
from .drivetrain_schema import DrivetrainFileError


def with_entries(spec: DrivetrainSpec, entries: Mapping[str, Any], allow: Sequence[str] = ()) -> DrivetrainSpec:
    """The file's document with entries changed by key path (``stages[0].planets``, ``generator.inertia``), read again.

    ``allow``: flat parameter names kept although implausible besides the file's own (a study's).

    The content hash of the result is that of the changed document (canonical JSON), so
    FMUs built from it are kept apart from the original's.

    Raises
    ------
    DrivetrainFileError
        A key path that is not in the document, or a changed document that is invalid.
    """
    data = copy.deepcopy(dict(spec.data))
    for path, value in entries.items():
        set_entry(data, path, value, spec.source)
    sha = hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()
    return drivetrain_from_dict(data, name=spec.name, source=spec.source, sha256=sha, allow=allow)


def set_entry(data: dict, path: str, value: Any, source: str | None = None) -> None:
    """Set the entry at a key path (``stages[1].teeth.ring``) of a parsed document; the entry must exist."""
    try:
        parts = split_path(path)
    except ValueError:
        raise DrivetrainFileError(path, value, "a key path such as stages[0].planets", source) from None
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        ok = (isinstance(part, int) and isinstance(node, list) and 0 <= part < len(node)) or (
            isinstance(part, str) and isinstance(node, dict) and part in node)
        if not ok:
            raise DrivetrainFileError(path, value, "an entry the drivetrain file has (only existing entries can "
                                      "be changed)", source)
        if last:
            if isinstance(node[part], (dict, list)):
                raise DrivetrainFileError(path, value, "a number entry, not a table or list", source)
            node[part] = value
        else:
            node = node[part]
