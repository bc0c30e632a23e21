"""Where a scenario's FMUs are: the scenario's own folder, then the FMU folder.

A relative FMU path is looked up next to the scenario file, then in the FMU folder
(:func:`~orchestrator.provision.folders.default_fmu_dir` unless a command names one);
an absolute one is used as is (:meth:`orchestrator.inputs.scenario.Scenario.fmu_candidates`).
A component built from a drivetrain file or a load record has one place: the
subfolder of that content in the FMU folder (:mod:`orchestrator.provision.folders`).
"""

from __future__ import annotations

from pathlib import Path

from ..cosim.system import find_fmu
from ..inputs.scenario import Component, Scenario
from .folders import default_fmu_dir, drivetrain_fmu_dir, series_fmu_dir


def fmu_candidates(scenario: Scenario, component: Component, fmu_dir: Path | None) -> list[Path]:
    """Where the component's FMU is looked for, in order.

    Parameters
    ----------
    scenario : Scenario
    component : Component
        One of the scenario's components.
    fmu_dir : path or None
        The FMU folder (None: the current directory stands in for it when a component
        is built from a drivetrain file or a load record).
    """
    if component.series is not None:  # built from a load record: only its content-keyed folder
        root = Path(fmu_dir) if fmu_dir is not None else Path.cwd()
        return [series_fmu_dir(root, component.series) / component.fmu.name]
    if component.drivetrain is not None:  # built from a drivetrain file: only its content-keyed folder
        root = Path(fmu_dir) if fmu_dir is not None else Path.cwd()
        return [drivetrain_fmu_dir(root, component.drivetrain) / component.fmu.name]
    return scenario.fmu_candidates(component, fmu_dir)


def missing_fmus(scenario: Scenario, fmu_dir: Path) -> dict[str, Path]:
    """Components whose FMU file exists nowhere: ``{component: relative FMU path}``."""
    return {comp.name: comp.fmu for comp in scenario.components
            if not any(p.is_file() for p in fmu_candidates(scenario, comp, fmu_dir))}


def resolve_fmu_paths(scenario: Scenario, fmu_dir: str | Path | None = None) -> dict[str, Path]:
    """Absolute FMU path of every component (nothing is built).

    Parameters
    ----------
    scenario : Scenario
    fmu_dir : path, optional
        The FMU folder searched after the scenario's own (default :func:`default_fmu_dir`).

    Raises
    ------
    ScenarioError
        ``components.<name>.fmu`` when the file is found nowhere; the message lists
        the places searched.
    """
    fmu_dir = default_fmu_dir() if fmu_dir is None else Path(fmu_dir)
    return {comp.name: find_fmu(scenario, comp, fmu_candidates(scenario, comp, fmu_dir))
            for comp in scenario.components}
