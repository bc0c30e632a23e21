"""Every FMU a scenario needs: found, or built when missing or stale.

A relative FMU path is looked up next to the scenario file, then in the FMU folder
(:mod:`orchestrator.provision.locate`). ``dtcosim run`` builds a missing project FMU
named by its file (``Gearbox.fmu``, ...: :func:`fmus.registry.of_file`, one the
registry builds from a preset) into the FMU folder with :mod:`fmus.build`, and first
the kernels they step, compiled ahead of time (:mod:`orchestrator.cosim.compiled_kernels`);
any other missing FMU is a scenario error naming the component. A component built from a
drivetrain file (``drivetrain = "..."``) gets its FMUs in the folder of that file's
content (:mod:`orchestrator.provision.drivetrain_fmus`), one built from a load record
in the folder of the selected content (:mod:`orchestrator.provision.series_fmus`), each
built when missing or stale.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from fmus.build import build_all
from fmus.build_lock import build_lock
from fmus.registry import PRESET, of_file

from ..cosim.compiled_kernels import ensure_compiled_kernels
from ..inputs.drivetrain_file import DrivetrainSpec
from ..inputs.scenario import Scenario
from .drivetrain_fmus import ensure_drivetrain_fmus
from .folders import default_fmu_dir, usable_fmu_dir
from .locate import missing_fmus, resolve_fmu_paths
from .other_builds import swap_in
from .staleness import broken_fmu, stale_project_fmus
from .series_fmus import ensure_series_fmu
from .unpack_ahead import unpack_ahead


def ensure_fmus(scenario: Scenario, fmu_dir: str | Path | None = None, build: bool = True,
                report: Callable[[str], None] | None = None, kernels_in_background: bool = False) -> dict[str, Path]:
    """Resolve every FMU path, building the project's missing FMUs first.

    Parameters
    ----------
    scenario : Scenario
    fmu_dir : path, optional
        The FMU folder (default :func:`orchestrator.provision.folders.default_fmu_dir`).
    build : bool
        Build missing project FMUs into ``fmu_dir``; if False a missing FMU is an error.
    report : callable(str), optional
        Receives progress messages ("building Gearbox.fmu ...").
    kernels_in_background : bool
        Missing compiled kernels: built in the background while this process runs them
        interpreted (``dtcosim run``: one run does not pay for a machine's compile), instead of
        built before anything else (studies, whose many points would all run interpreted);
        see :func:`~orchestrator.cosim.compiled_kernels.ensure_compiled_kernels`.

    Returns
    -------
    dict of str -> pathlib.Path
        Absolute FMU file per component.

    Raises
    ------
    ScenarioError
        ``components.<name>.fmu`` for a missing FMU that cannot be built.
    FmuFolderError
        The FMU folder cannot be created (where it was chosen and why).
    """
    managed = fmu_dir is None  # the project's own FMU folder: what is stale there is rebuilt, not only reported
    if not build:
        fmu_dir = default_fmu_dir() if fmu_dir is None else Path(fmu_dir)
    else:
        fmu_dir = usable_fmu_dir(fmu_dir)  # created, or an error naming where it was chosen
        # the kernels the FMUs and the master step, once per machine
        ensure_compiled_kernels(report, background=kernels_in_background)
        wanted: dict[str, tuple[DrivetrainSpec, list[str]]] = {}
        for comp in scenario.components:
            if comp.drivetrain is not None:
                spec, names = wanted.get(comp.drivetrain.sha256, (comp.drivetrain, []))
                wanted[spec.sha256] = (spec, names + [comp.fmu.stem])
        for spec, names in wanted.values():  # in their content's folder, built when missing or stale
            ensure_drivetrain_fmus(spec, fmu_dir, names, report)
        for comp in scenario.components:
            if comp.series is not None:
                ensure_series_fmu(comp.series, fmu_dir, report)
        if _missing_preset_fmus(scenario, fmu_dir, managed):
            with build_lock(fmu_dir, report):  # decided again and built by one process at a time
                names = _missing_preset_fmus(scenario, fmu_dir, managed)  # another process may have built them
                if managed:  # another version's FMUs set aside, this version's taken back where kept
                    names = [n for n in names if not swap_in(fmu_dir / f"{n}.fmu")]
                if names:
                    if report:
                        report(f"building {', '.join(n + '.fmu' for n in names)} into {fmu_dir} ...")
                    build_all(fmu_dir, names=names, after_each=unpack_ahead)
    return resolve_fmu_paths(scenario, fmu_dir)


def _missing_preset_fmus(scenario: Scenario, fmu_dir: Path, rebuild_stale: bool) -> list[str]:
    """The project FMUs built from a preset that ``fmu_dir`` lacks or holds broken (an interrupted build of an
    older version) or, with ``rebuild_stale`` (the project's own folder), built from other code than the
    installed dtcosim (after an upgrade), by model name. In a folder the user names a stale FMU is kept and
    reported (:func:`~orchestrator.provision.staleness.stale_project_fmus`)."""
    def replaced(path: Path) -> bool:
        return bool(broken_fmu(path) or (rebuild_stale and stale_project_fmus({path.stem: path})))

    broken = [comp.name for comp in scenario.components if (fmu_dir / comp.fmu.name).is_file()
              and _preset_fmu(scenario, comp.name) is not None and replaced(fmu_dir / comp.fmu.name)]
    return sorted({_preset_fmu(scenario, comp) for comp in [*missing_fmus(scenario, fmu_dir), *broken]} - {None})


def _preset_fmu(scenario: Scenario, name: str) -> str | None:
    """The model name of the project FMU built from a preset that component ``name`` asks for (None: not one)."""
    comp = scenario.component(name)
    kind = of_file(comp.fmu)
    if kind is None or PRESET not in kind.built_from or comp.drivetrain is not None or comp.series is not None:
        return None
    return kind.name
