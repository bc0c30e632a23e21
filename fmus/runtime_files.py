"""What an FMU carries to tell a foreign host what it needs, written while it is built.

* ``resources/requirements.txt``: Python and package ranges (:mod:`fmus.requirements`),
  read by the FMU itself at instantiation (:mod:`fmus.runtime_guard`), by
  ``dtcosim validate`` and by ``pip install -r``;
* ``documentation/index.html`` (:mod:`fmus.documentation`);
* the same requirements appended to ``modelDescription.xml``'s ``description``;
* ``runtime_guard.py`` in the embedded package (the check itself; its code is
  part of the build id like the rest of the embedded code).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping
from xml.etree import ElementTree as ET

from .documentation import BuildFacts, carried_platforms
from .documentation import write as write_documentation
from .requirements import from_environment, imported_modules
from .runtime_guard import REQUIREMENTS_FILE, RuntimeRequirements, format_requirements

#: The guard's source and its file name inside the embedded package.
GUARD_SOURCE = Path(__file__).with_name("runtime_guard.py")
GUARD_FILE = "runtime_guard.py"

_HEADER = ("The FMU's linux64 binary finds this Python itself (resources/python.txt, or DTCOSIM_FMU_LIBPYTHON,\n"
           "DTCOSIM_FMU_PYTHONHOME, DTCOSIM_FMU_PYTHONPATH): see documentation/index.html.\n"
           "Ranges: from the tested minor release of each package to its next major release;\n"
           "Python: the minor version the FMU was built and tested with.")


@dataclass(frozen=True)
class RuntimeFiles:
    """The files written for one build.

    Attributes
    ----------
    requirements : RuntimeRequirements
    requirements_file : Path
        ``requirements.txt`` to put into ``resources/``.
    documentation_dir : Path
        Folder to put into the archive as ``documentation/``.
    """

    requirements: RuntimeRequirements
    requirements_file: Path
    documentation_dir: Path


def write(staging_dir: Path, name: str, origin: str, model: Mapping[str, Any], build_id: str, version: str,
          sources: Iterable[Path]) -> RuntimeFiles:
    """Write the requirements and the documentation of one FMU under ``staging_dir``.

    Parameters
    ----------
    staging_dir : Path
        Build staging directory (``runtime/`` is created in it).
    name, origin : str
        FMU model name, what its model was made from.
    model : mapping
        The FMU record's model.
    build_id, version : str
        Build id, dtcosim version.
    sources : iterable of Path
        The embedded source files (their imports decide the packages required).
    """
    out = Path(staging_dir) / "runtime"
    out.mkdir(parents=True, exist_ok=True)
    req = requirements(name, sources)
    requirements_file = out / REQUIREMENTS_FILE
    requirements_file.write_text(format_requirements(req, _HEADER), encoding="utf-8")
    docs = write_documentation(out / "documentation", BuildFacts(name, origin, model, build_id, version, req,
                                                                 carried_platforms()))
    return RuntimeFiles(req, requirements_file, docs)


def requirements(name: str, sources: Iterable[Path]) -> RuntimeRequirements:
    """What FMU ``name``, whose embedded code is ``sources``, requires of its host's Python: the packages its code
    imports, in the ranges of the versions installed here (:func:`fmus.requirements.from_environment`)."""
    required, optional = imported_modules(sources)
    return from_environment(name, required, optional=optional)


def describe(xml: bytes, req: RuntimeRequirements) -> bytes:
    """``modelDescription.xml`` with the requirements appended to its ``description``."""
    root = ET.fromstring(xml)
    root.set("description", f"{root.get('description', '')}. Requires {req.summary()} in the host process "
                            f"(resources/{REQUIREMENTS_FILE}, documentation/index.html)")
    buffer = io.BytesIO()
    ET.ElementTree(root).write(buffer, encoding="UTF-8", xml_declaration=True)
    return buffer.getvalue() + b"\n"
