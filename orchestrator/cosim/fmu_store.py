"""Locating the scenario's FMUs and building the project's own FMUs when they are missing.

A relative FMU path is looked up next to the scenario file, then in the FMU
directory (:func:`orchestrator.cosim.fmu_folder.default_fmu_dir`). ``dtcosim run`` builds a
missing ``WindSource.fmu``, ``Gearbox.fmu`` or ``GeneratorRotor.fmu`` (the FMUs
this project makes, with ``fmus.build``) into the FMU directory, and the kernels they step
compiled ahead of time (:mod:`orchestrator.cosim.compiled_kernels`); any other
missing FMU is a scenario error naming the component. A component built from a
drivetrain file (``drivetrain = "..."``) gets its FMU in the folder of that file's
content (:mod:`orchestrator.cosim.drivetrain_fmus`), built when missing or stale.
"""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path
from typing import Callable, Mapping

from ..inputs.scenario import Scenario
from .fmu_folder import default_fmu_dir
from .system import resolve_fmu_paths


def buildable_fmu_names() -> tuple[str, ...]:
    """FMU model names that ``fmus.build`` can make (empty if the builder is unavailable)."""
    try:
        from fmus.build import PRESET_FMU_NAMES
    except ImportError:
        return ()
    return tuple(PRESET_FMU_NAMES)


def missing_fmus(scenario: Scenario, fmu_dir: Path) -> dict[str, Path]:
    """Components whose FMU file exists nowhere: ``{component: relative FMU path}``."""
    out = {}
    for comp in scenario.components:
        if not any(p.is_file() for p in scenario.fmu_candidates(comp, fmu_dir)):
            out[comp.name] = comp.fmu
    return out


def ensure_fmus(scenario: Scenario, fmu_dir: str | Path | None = None, build: bool = True,
                report: Callable[[str], None] | None = None) -> dict[str, Path]:
    """Resolve every FMU path, building the project's missing FMUs first.

    Parameters
    ----------
    scenario : Scenario
    fmu_dir : path, optional
        FMU directory (default :func:`orchestrator.cosim.fmu_folder.default_fmu_dir`).
    build : bool
        Build missing project FMUs into ``fmu_dir``; if False a missing FMU is an error.
    report : callable(str), optional
        Receives progress messages ("building Gearbox.fmu ...").

    Returns
    -------
    dict of str -> pathlib.Path
        Absolute FMU file per component.

    Raises
    ------
    ScenarioError
        ``components.<name>.fmu`` for a missing FMU that cannot be built.
    """
    fmu_dir = default_fmu_dir() if fmu_dir is None else Path(fmu_dir)
    if build:  # the kernels the FMUs and the master step, compiled ahead of time once per machine
        from .compiled_kernels import ensure_compiled_kernels

        ensure_compiled_kernels(report)
    if build:  # FMUs of drivetrain files: in their content's folder, built when missing or stale
        from .drivetrain_fmus import ensure_drivetrain_fmus

        wanted: dict[str, tuple] = {}
        for comp in scenario.components:
            if comp.drivetrain is not None:
                spec, names = wanted.get(comp.drivetrain.sha256, (comp.drivetrain, []))
                wanted[spec.sha256] = (spec, names + [comp.fmu.stem])
        for spec, names in wanted.values():
            ensure_drivetrain_fmus(spec, fmu_dir, names, report)
        from .series_fmus import ensure_series_fmu

        for comp in scenario.components:
            if comp.series is not None:
                ensure_series_fmu(comp.series, fmu_dir, report)
    missing = missing_fmus(scenario, fmu_dir)
    if missing and build:
        buildable = buildable_fmu_names()
        names = sorted({scenario.component(c).fmu.stem for c, p in missing.items() if p.parent == Path(".")
                        and p.suffix == ".fmu" and p.stem in buildable and scenario.component(c).drivetrain is None
                        and scenario.component(c).series is None})
        if names:
            from fmus.build import build_all

            if report:
                report(f"building {', '.join(n + '.fmu' for n in names)} into {fmu_dir} ...")
            build_all(fmu_dir, names=names)
    return resolve_fmu_paths(scenario, fmu_dir)



_BUILD_ID = re.compile(r"^_dtcosim_[a-z]+_([0-9a-f]{12})_slave$")


def stale_project_fmus(paths: Mapping[str, Path]) -> list[str]:
    """Warnings for project FMUs built from other code than the installed ``components``/``fmus``.

    A project FMU carries the hash of its code and of the model it was built from
    in its pythonfmu entry module name (``resources/slavemodule.txt``) and that
    model in its record (``resources/dtcosim.json``); it is stale when the
    installed sources, built from the same model, would give another hash.
    Other FMUs are not checked.
    """
    try:
        from fmus.build import FMU_NAMES, code_hash
        from fmus.slaves.record import RECORD_FILE
    except ImportError:
        return []
    out = []
    for comp, path in paths.items():
        try:
            with zipfile.ZipFile(path) as zf:
                module = zf.read("resources/slavemodule.txt").decode().strip()
                record = json.loads(zf.read(f"resources/{RECORD_FILE}"))
            model = record["model"]
        except (KeyError, OSError, ValueError, TypeError, zipfile.BadZipFile):
            continue
        m = _BUILD_ID.match(module)
        name = record.get("fmu")
        if not m or name not in FMU_NAMES:
            continue
        if m.group(1) != code_hash(name, model):
            out.append(f"{path} ({comp}) was built from other code than the installed dtcosim (build {m.group(1)}); "
                       f"rebuild it with `dtcosim build --out {path.parent}`")
    return out
