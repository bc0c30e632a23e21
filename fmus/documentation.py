"""``documentation/index.html`` of each FMU (FMI 2.0's place for it), written at build time.

One self-contained HTML page (no scripts, no external files) per FMU:

* what the component is and its equations with the paper's equation numbers
  (hand-written per FMU in ``fmus/doc_content/<FMU>.html``);
* a table of every variable (value reference, causality, type, unit, default,
  accepted range, description) generated from the slave's interface
  (:func:`fmus.docs.variable_rows`, the rows of ``docs/fmus.md`` too) and the
  parameter validation (:func:`fmus.parameter_ranges.accepted_ranges`);
* the initialisation order, the error semantics, the runtime requirements
  and the preload recipe for C/C++ hosts, which hosts were tried, and the
  platforms whose binaries the FMU carries and which were tested
  (``fmus/doc_content/hosts.html`` with the build's values filled in).
"""

from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path
from string import Template
from typing import Any, Mapping

import pythonfmu

from .docs import start_text, unit_text, variable_rows
from .parameter_ranges import accepted_ranges
from .runtime_guard import RuntimeRequirements

CONTENT_DIR = Path(__file__).with_name("doc_content")
INDEX = "index.html"
#: Id of the variable table (tests parse it).
VARIABLE_TABLE_ID = "variables-table"

#: Platforms on which dtcosim runs the FMUs (its test suite), with what was run there.
TESTED_PLATFORMS = {
    "linux64": "yes: fmpy, libcosim (libcosimpy), ecos (ecospy) and a plain C host in dtcosim's test suite "
               "on Linux x86-64 (glibc)",
}
UNTESTED = "no: carried as pythonfmu ships it, never run by dtcosim"

#: What each FMU's part of the initialisation order is.
INIT_NOTES = {
    "WindSource": "it has no inputs and comes first; its outputs at the start time depend on its parameters only, "
                  "and after each step they are the values at t + h computed in the FMU.",
    "Gearbox": "set omega_rotor and phi_rotor before reading omega_out; omega_gen and phi_gen come from the "
               "GeneratorRotor (or, standalone, must advance consistently with each other: angles held while speeds "
               "are not zero twist the shafts).",
    "GeneratorRotor": "set initial_speed (the Gearbox's omega_out) and initial_angle before "
                      "fmi2ExitInitializationMode; its input shaft_torque is used from the first fmi2DoStep on.",
    "Rotor": "set initial_speed (and aero_torque, which sets a main shaft's initial twist) before "
             "fmi2ExitInitializationMode; its outputs omega and phi drive the Gearbox's omega_rotor and phi_rotor, "
             "the Gearbox's torque_rotor comes back as gearbox_torque from the first fmi2DoStep on.",
    "TorqueController": "set generator_speed (the generator's initial speed) and pitch before "
                        "fmi2ExitInitializationMode: they set the filter state and the initial torque.",
    "TimeSeriesSource": "it has no inputs and comes first; set time_offset so that the run lies inside the "
                        "record (out_of_record = error refuses a start outside it in fmi2ExitInitializationMode).",
}

_STYLE = """body{font-family:sans-serif;max-width:72em;margin:1em auto;padding:0 1em;line-height:1.4}
table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:2px 6px;vertical-align:top;text-align:left}
th{background:#eee}pre{background:#f6f6f6;padding:0.5em;overflow-x:auto}code{font-size:95%}
td.name{white-space:nowrap;font-family:monospace}"""


@dataclass(frozen=True)
class BuildFacts:
    """What the documentation of one build states.

    Attributes
    ----------
    name : str
        FMU model name.
    origin : str
        What the model was made from (``"preset table6"``, a drivetrain file).
    model : mapping
        The record's model (structure and defaults the variables come from).
    build_id : str
        Hash of the embedded code and configuration.
    version : str
        dtcosim version.
    requirements : RuntimeRequirements
    platforms : tuple of str
        Platforms whose binaries the FMU carries (``linux64``, ``win64``).
    """

    name: str
    origin: str
    model: Mapping[str, Any]
    build_id: str
    version: str
    requirements: RuntimeRequirements
    platforms: tuple[str, ...]


def carried_platforms() -> tuple[str, ...]:
    """Platforms of the binaries pythonfmu copies into every FMU (its ``resources/binaries``)."""
    binaries = Path(pythonfmu.__file__).parent / "resources" / "binaries"
    return tuple(sorted(p.name for p in binaries.iterdir() if p.is_dir() and any(p.iterdir())))


def _cell(text: str, css: str = "") -> str:
    attr = f' class="{css}"' if css else ""
    return f"<td{attr}>{html.escape(text)}</td>"


def variable_table(name: str, model: Mapping[str, Any]) -> str:
    """The HTML table of every variable of FMU ``name`` built from ``model``: inputs, outputs, parameters."""
    ranges = accepted_ranges(name, model)
    head = ("name", "vr", "causality", "type", "unit", "default", "range", "description")
    lines = [f'<table id="{VARIABLE_TABLE_ID}">', "<tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr>"]
    for vr, var in variable_rows(name, model=model):
        cells = [_cell(var.name, "name"), _cell(str(vr)), _cell(var.causality), _cell(var.type), _cell(unit_text(var)),
                 _cell(start_text(var, exact=True)), _cell(ranges[var.name]), _cell(var.description)]
        lines.append("<tr>" + "".join(cells) + "</tr>")
    lines.append("</table>")
    return "\n".join(lines)


def requirements_table(req: RuntimeRequirements) -> str:
    """Python and the packages: requirement, version tested, module imported."""
    rows = [("Python (CPython)", req.python_specifier, req.python_tested, "-")]
    rows += [(p.distribution, p.specifier, p.tested, p.module) for p in req.packages]
    rows += [(f"{p.distribution} (optional: {p.purpose})", p.specifier, p.tested, p.module) for p in req.optional]
    lines = ['<table id="requirements-table">',
             "<tr><th>what</th><th>requirement</th><th>tested with</th><th>imported as</th></tr>"]
    lines += ["<tr>" + "".join(_cell(c) for c in row) + "</tr>" for row in rows]
    lines.append("</table>")
    return "\n".join(lines)


def platforms_table(name: str, platforms: tuple[str, ...]) -> str:
    """Carried binaries and whether dtcosim tested them."""
    suffix = {"linux64": ".so", "linux32": ".so", "win64": ".dll", "win32": ".dll", "darwin64": ".dylib"}
    lines = ['<table id="platforms-table">', "<tr><th>platform</th><th>binary</th><th>tested</th></tr>"]
    for platform in platforms:
        binary = f"binaries/{platform}/{name}{suffix.get(platform, '')}"
        lines.append("<tr>" + _cell(platform) + _cell(binary) + _cell(TESTED_PLATFORMS.get(platform, UNTESTED)) + "</tr>")
    lines.append("</table>")
    return "\n".join(lines)


def index_html(facts: BuildFacts) -> str:
    """The whole page."""
    name, req = facts.name, facts.requirements
    component = (CONTENT_DIR / f"{name}.html").read_text(encoding="utf-8")
    common = Template((CONTENT_DIR / "hosts.html").read_text(encoding="utf-8")).substitute(
        fmu=name, init_note=html.escape(INIT_NOTES[name]), pythonfmu=pythonfmu.__version__,
        python_specifier=html.escape(req.python_specifier), requirements_table=requirements_table(req),
        python_dll="python%d%d.dll" % req.python_minimum[:2],
        platforms_table=platforms_table(name, facts.platforms),
    )
    title = f"dtcosim {name} FMU"
    sections = (("component", "What it is"), ("equations", "Equations"), ("variables", "Variables"),
                ("initialisation", "Initialisation order"), ("errors", "Errors"),
                ("hosts", "Using this FMU in other hosts"), ("platforms", "Platforms"))
    nav = " | ".join(f'<a href="#{key}">{label}</a>' for key, label in sections)
    build = (f"Build {facts.build_id}: dtcosim {facts.version}, built from {facts.origin}, PythonFMU {pythonfmu.__version__}, "
             f"FMI 2.0 Co-Simulation. Needs {req.summary()} in the host process; binaries for "
             f"{', '.join(facts.platforms)}.")
    variables = (f'<section id="variables">\n<h2>Variables</h2>\n<p>Every variable of this build ({facts.origin}), '
                 "inputs, outputs, then parameters; SI units; <i>default</i> is the start value in modelDescription.xml, "
                 "<i>range</i> what the FMU's own validation accepts (a parameter outside it fails "
                 "<code>fmi2ExitInitializationMode</code> with fmi2Fatal and a message naming it).</p>\n"
                 f"{variable_table(name, facts.model)}\n</section>")
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{title}</title>\n'
            f"<style>\n{_STYLE}\n</style>\n</head>\n<body>\n<h1>{title}</h1>\n<p>{html.escape(build)}</p>\n"
            f"<p>{nav}</p>\n{component}\n{variables}\n{common}\n</body>\n</html>\n")


def write(directory: Path | str, facts: BuildFacts) -> Path:
    """Write ``index.html`` into ``directory`` (created); returns the directory (pythonfmu's documentation folder)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    (directory / INDEX).write_text(index_html(facts), encoding="utf-8")
    return directory
