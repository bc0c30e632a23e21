"""What an FMU needs from its host's Python, and a readable failure when it is missing.

This module is copied into every FMU (``resources/_dtcosim_<fmu>_<hash>/runtime_guard.py``)
and imported by the FMU's entry script before anything else, so it uses the
standard library only and keeps to syntax old interpreters can parse. The same
code reads the requirements for ``dtcosim validate``.

``resources/requirements.txt`` (written by :mod:`fmus.requirements` at build
time) is a pip requirements file whose comments carry what pip cannot express::

    # requires-python: >=3.11,<3.12  (tested: 3.11.7)
    numpy>=2.4,<3  # tested: 2.4.6 (import numpy)
    # optional: numba>=0.68,<1  # tested: 0.68.1 (import numba) compiled gearbox kernel ...

An optional package is one the FMU's code can do without (declared next to its
import with the comment ``# optional requirement: <what it gives>``); it is a
comment line, so ``pip install -r`` installs only what is required.

What the FMU does with it (:func:`load_slave`, called by the entry script):

* Python older than the declared minimum, or a module that cannot be imported
  (numpy missing, ...): an :class:`ImportError` whose message names the missing
  module, the requirement and the interpreter, also printed to ``stderr``.
  pythonfmu 0.7's wrapper logs it through the FMI logger (status fmi2Fatal, when
  the host enabled logging) and ``fmi2Instantiate`` returns NULL.
* A version outside the tested range: a warning on ``stderr`` (once per process)
  and, through the slave, on the FMI logger; the FMU runs.
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass
from typing import Callable, Optional, Tuple

REQUIREMENTS_FILE = "requirements.txt"

Version = Tuple[int, ...]

_PYTHON_LINE = re.compile(r"^#\s*requires-python:\s*>=([0-9.]+),<([0-9.]+)\s*\(tested:\s*([^)\s]+)\)")
_PACKAGE_LINE = re.compile(
    r"^([A-Za-z0-9][A-Za-z0-9._-]*)>=([0-9.]+),<([0-9.]+)\s*#\s*tested:\s*(\S+)\s*\(import\s+([A-Za-z_][\w]*)\)"
    r"\s*(.*)$"
)
_OPTIONAL_PREFIX = "# optional:"


class RequirementsFormatError(ValueError):
    """A requirements file that is not in the format :func:`format_requirements` writes."""


def release(version: str) -> Version:
    """Numeric release part of a version string: ``"2.5.0rc1"`` -> ``(2, 5, 0)``."""
    numbers = re.match(r"^\s*v?(\d+(?:\.\d+)*)", str(version))
    if not numbers:
        raise ValueError("not a version: %r" % (version,))
    return tuple(int(p) for p in numbers.group(1).split("."))


def dotted(version: Version) -> str:
    """``(2, 4)`` -> ``"2.4"``."""
    return ".".join(str(p) for p in version)


@dataclass(frozen=True)
class PackageRequirement:
    """One distribution the FMU's code imports.

    Attributes
    ----------
    distribution : str
        Name pip installs (``numpy``).
    module : str
        Top-level module the FMU imports (``numpy``).
    minimum : tuple of int
        Lowest version in the tested range (inclusive).
    below : tuple of int
        Upper end of the range (exclusive).
    tested : str
        Version installed where the FMU was built and tested.
    """

    distribution: str
    module: str
    minimum: Version
    below: Version
    tested: str
    purpose: str = ""

    @property
    def specifier(self) -> str:
        """``numpy>=2.4,<3``."""
        return "%s>=%s,<%s" % (self.distribution, dotted(self.minimum), dotted(self.below))

    def admits(self, version: str) -> bool:
        """Whether ``version`` lies in the tested range."""
        return self.minimum <= release(version) < self.below


@dataclass(frozen=True)
class RuntimeRequirements:
    """The Python and the packages an FMU needs in its host process.

    Attributes
    ----------
    fmu : str
        FMU model name.
    python_minimum, python_below : tuple of int
        Tested Python range ``[minimum, below)``; below ``minimum`` the FMU refuses to start.
    python_tested : str
        Python version of the build.
    packages : tuple of PackageRequirement
        Required: without one of them the FMU cannot start.
    optional : tuple of PackageRequirement
        Used where present (``purpose`` says for what); the FMU runs without them.
    """

    fmu: str
    python_minimum: Version
    python_below: Version
    python_tested: str
    packages: Tuple[PackageRequirement, ...]
    optional: Tuple[PackageRequirement, ...] = ()

    @property
    def python_specifier(self) -> str:
        """``>=3.11,<3.12``."""
        return ">=%s,<%s" % (dotted(self.python_minimum), dotted(self.python_below))

    def summary(self) -> str:
        """``Python >=3.11,<3.12 with numpy>=2.4,<3, scipy>=1.17,<2`` (for descriptions and messages)."""
        text = "Python " + self.python_specifier
        if self.packages:
            text += " with " + ", ".join(p.specifier for p in self.packages)
        if self.optional:
            text += " (optional: " + ", ".join(p.specifier for p in self.optional) + ")"
        return text

    def package(self, module: str) -> Optional[PackageRequirement]:
        """The requirement providing top-level module ``module``, if any."""
        for p in self.packages + self.optional:
            if p.module == module:
                return p
        return None


def format_requirements(req: RuntimeRequirements, header: str = "") -> str:
    """Text of ``resources/requirements.txt`` (pip reads the package lines; the comments are ours)."""
    lines = ["# Runtime requirements of the dtcosim %s FMU: the Python interpreter of the host process" % req.fmu,
             "# must satisfy them (install with: pip install -r requirements.txt)."]
    lines += ["# " + line if line else "#" for line in header.splitlines()]
    lines.append("# requires-python: %s  (tested: %s)" % (req.python_specifier, req.python_tested))
    for p in req.packages:
        lines.append("%s  # tested: %s (import %s)" % (p.specifier, p.tested, p.module))
    for p in req.optional:
        lines.append("%s %s  # tested: %s (import %s) %s" % (_OPTIONAL_PREFIX, p.specifier, p.tested, p.module,
                                                             p.purpose))
    return "\n".join(lines) + "\n"


def parse_requirements(text: str, fmu: str = "") -> RuntimeRequirements:
    """Read what :func:`format_requirements` wrote.

    Raises
    ------
    RequirementsFormatError
        Naming the line that is neither a comment, nor the ``requires-python`` line,
        nor a package line ``name>=A.B,<C  # tested: X (import module)``.
    """
    python = None
    packages = []
    optional = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        m = _PYTHON_LINE.match(line)
        if m:
            python = (release(m.group(1)), release(m.group(2)), m.group(3))
            continue
        target = packages
        if line.startswith(_OPTIONAL_PREFIX):
            line, target = line[len(_OPTIONAL_PREFIX):].strip(), optional
        elif line.startswith("#"):
            continue
        m = _PACKAGE_LINE.match(line)
        if not m:
            raise RequirementsFormatError(
                "line %d %r: expected 'name>=A.B,<C  # tested: X.Y.Z (import module)'" % (number, line))
        target.append(PackageRequirement(m.group(1), m.group(5), release(m.group(2)), release(m.group(3)),
                                         m.group(4), m.group(6).strip()))
    if python is None:
        raise RequirementsFormatError("no '# requires-python: >=A.B,<C.D  (tested: X.Y.Z)' line")
    return RuntimeRequirements(fmu, python[0], python[1], python[2], tuple(packages), tuple(optional))


def read_requirements(resources_dir: str, fmu: str = "") -> Optional[RuntimeRequirements]:
    """The requirements in ``resources_dir``, or None if the FMU carries none."""
    path = os.path.join(resources_dir, REQUIREMENTS_FILE)
    if not os.path.isfile(path):
        return None
    with open(path, encoding="utf-8") as f:
        return parse_requirements(f.read(), fmu)


def installed_version(req: PackageRequirement) -> Optional[str]:
    """Version of the distribution installed for this interpreter (None if unknown)."""
    try:
        from importlib import metadata

        return metadata.version(req.distribution)
    except Exception:  # noqa: BLE001 - not installed, or no metadata (e.g. a vendored copy)
        module = sys.modules.get(req.module)
        return getattr(module, "__version__", None)


def interpreter() -> str:
    """``Python 3.11.7 (prefix /usr)``: the interpreter the FMU runs in."""
    return "Python %s (prefix %s)" % (sys.version.split()[0], sys.prefix)


def python_problem(req: RuntimeRequirements, version: Version = None) -> Optional[str]:
    """Why this Python cannot run the FMU (older than the declared minimum), or None."""
    version = tuple(sys.version_info[:3]) if version is None else tuple(version)
    if version < req.python_minimum:
        return ("it requires Python %s (tested with %s) but the host process runs %s"
                % (req.python_specifier, req.python_tested, interpreter()))
    return None


def version_warnings(req: RuntimeRequirements, version: Version = None,
                     installed: Callable[[PackageRequirement], Optional[str]] = installed_version) -> list:
    """Versions outside the tested ranges (the FMU still runs)."""
    version = tuple(sys.version_info[:3]) if version is None else tuple(version)
    out = []
    if not version < req.python_below:
        out.append("Python %s is outside the tested range %s (tested with %s)"
                   % (dotted(version), req.python_specifier, req.python_tested))
    for p in req.packages + req.optional:
        found = installed(p)
        if found is not None and not p.admits(found):
            out.append("%s %s is outside the tested range %s (tested with %s)"
                       % (p.distribution, found, p.specifier, p.tested))
    return out


def import_failure(fmu: str, exc: ImportError, req: Optional[RuntimeRequirements], resources_dir: str) -> str:
    """One-line message for a failed import of the FMU's code."""
    module = (exc.name or "").split(".")[0] or "?"
    text = "dtcosim %s FMU cannot start: Python module '%s' cannot be imported (%s: %s)" % (
        fmu, module, type(exc).__name__, exc)
    if req is not None:
        text += "; the FMU requires %s (%s)" % (req.summary(), os.path.join(resources_dir, REQUIREMENTS_FILE))
    text += (" in the host process's interpreter, %s: install them there "
             "(pip install -r resources/requirements.txt) or set PYTHONPATH to a site-packages that has them; "
             "see documentation/index.html" % interpreter())
    return text


_reported = set()
_warnings = []


def _stderr(message: str) -> None:
    try:
        sys.stderr.write(message + "\n")
        sys.stderr.flush()
    except Exception:  # noqa: BLE001 - an embedded interpreter may have no usable stderr
        pass


def warnings() -> list:
    """Version warnings found by :func:`load_slave` in this process (for the FMI logger)."""
    return list(_warnings)


def load_slave(fmu: str, entry_file: str, import_slave: Callable[[], type]) -> type:
    """Check the interpreter, import the slave class and explain any failure.

    Parameters
    ----------
    fmu : str
        FMU model name.
    entry_file : str
        ``__file__`` of the entry script (its directory is ``resources/``).
    import_slave : callable
        Imports and returns the slave class.

    Raises
    ------
    ImportError
        With a message naming what is missing (also written to stderr).
    """
    resources_dir = os.path.dirname(os.path.abspath(entry_file))
    if os.sep == "/":
        resources_dir = "/" + resources_dir.lstrip("/")  # hosts pass file:////tmp/... URIs
    req = None
    try:
        req = read_requirements(resources_dir, fmu)
    except (OSError, ValueError) as exc:
        _stderr("[dtcosim %s FMU] cannot read %s: %s" % (fmu, REQUIREMENTS_FILE, exc))
    if req is not None:
        problem = python_problem(req)
        if problem:
            message = "dtcosim %s FMU cannot start: %s; see documentation/index.html" % (fmu, problem)
            _stderr(message)
            raise ImportError(message)
    try:
        slave = import_slave()
    except ImportError as exc:
        message = import_failure(fmu, exc, req, resources_dir)
        _stderr(message)
        raise ImportError(message, name=exc.name) from None
    if req is not None and fmu not in _reported:
        _reported.add(fmu)
        for warning in version_warnings(req):
            text = "dtcosim %s FMU: %s" % (fmu, warning)
            _warnings.append(text)
            _stderr("[warning] " + text)
    return slave
