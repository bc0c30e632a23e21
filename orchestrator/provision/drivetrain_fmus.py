"""FMUs built from drivetrain files, kept apart by the file's content.

The FMUs built from a drivetrain file (:func:`fmus.registry.built_from` a drivetrain file: the
Gearbox and its GeneratorRotor) live in ``<FMU folder>/drivetrains/<name>-<sha256[:16]>/``
(:func:`orchestrator.provision.folders.drivetrain_fmu_dir`), so two scenarios with different
drivetrains never overwrite each other's FMUs and a changed file gets new FMUs. The FMUs'
records name the file and its content hash (``source``) and carry the drivetrain
(``model``), which the reference, the comparison and ``dtcosim modes`` read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Iterable

from fmus.build import BuiltFmu, build_several
from fmus.build_lock import build_lock
from fmus.registry import DRIVETRAIN_FILE, names_built_from

from ..inputs.drivetrain_file import DrivetrainSpec
from .folders import drivetrain_fmu_dir, mark_used
from .other_builds import swap_in
from .staleness import broken_fmu, stale_project_fmus
from .unpack_ahead import unpack_ahead

#: the FMUs a drivetrain file is built into
DRIVETRAIN_FMU_NAMES = names_built_from(DRIVETRAIN_FILE)


def build_drivetrain_fmus(spec: DrivetrainSpec, out_dir: Path, names: Iterable[str] = DRIVETRAIN_FMU_NAMES,
                          report: Callable[[str], None] | None = None, validate: bool = True) -> list[BuiltFmu]:
    """Build FMUs ``names`` from a drivetrain file into ``out_dir``.

    Returns
    -------
    list of fmus.build.BuiltFmu

    Raises
    ------
    DrivetrainFileError
        The file has no generator (a Gearbox FMU is cut at the generator).
    """
    drivetrain = spec.cosim_drivetrain()
    names = list(names)
    if report:
        report(f"building {', '.join(n + '.fmu' for n in names)} from {spec.origin} into {out_dir} ...")
    return build_several(names, out_dir, report, drivetrain=drivetrain, origin=spec.origin,
                         rotor_speed_rad_s=spec.rotor_speed_rad_s, validate=validate, after_each=unpack_ahead)


def ensure_drivetrain_fmus(spec: DrivetrainSpec, fmu_dir: Path, names: Iterable[str],
                           report: Callable[[str], None] | None = None) -> Path:
    """The folder of ``spec``'s FMUs in ``fmu_dir``, with FMUs ``names`` built if missing or stale.

    Stale: built from other code than the installed dtcosim (:func:`~orchestrator.provision.staleness.stale_project_fmus`);
    these folders are the project's own cache, so a stale FMU is rebuilt, not only reported.
    """
    folder = drivetrain_fmu_dir(fmu_dir, spec)
    names = list(dict.fromkeys(names))
    paths = {n: folder / f"{n}.fmu" for n in names}

    def todo() -> list[str]:
        present = {n: p for n, p in paths.items() if p.is_file()}
        return sorted({n for n in paths if n not in present}
                      | {n for n, p in present.items() if broken_fmu(p) or stale_project_fmus({n: p})})

    if todo():
        with build_lock(folder, report):  # decided again and built by one process at a time
            names = [n for n in todo() if not swap_in(paths[n])]  # built meanwhile, or kept aside (other_builds)
            if names:
                build_drivetrain_fmus(spec, folder, names, report)
    mark_used(folder)
    return folder
