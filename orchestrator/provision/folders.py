"""Where built FMUs live: the FMU folder and its content-keyed subfolders (a light module: the CLI imports it at start-up).

The FMU folder is ``$DTCOSIM_FMU_DIR`` if set, else ``fmus/`` in dtcosim's per-user
cache (:func:`components.compile.user_cache.user_cache_root`: ``$DTCOSIM_CACHE_DIR``, else
``$XDG_CACHE_HOME/dtcosim`` or ``~/.cache/dtcosim``), or the folder a command is given
(``--fmu-dir``, ``dtcosim build --out``). Nothing is ever written into the installed
package or a source checkout. Inside it:

``<name>.fmu``
    The project's FMUs built from a preset (``dtcosim build``, a run that misses them).
``drivetrains/<drivetrain name>-<sha256[:16]>/``
    Gearbox and GeneratorRotor built from a drivetrain file, one folder per file content.
``series/<load record stem>-<sha256[:16]>/``
    The TimeSeriesSource built from a scenario's load record, one folder per selected content.
    Each of these content folders has a ``.used`` file that every command using its FMUs touches
    (:func:`mark_used`); in the default FMU folder, ``dtcosim cache --prune`` removes those unused
    for :data:`UNUSED_DAYS` days (a run of one builds its FMUs again).
``.other-builds/<Name>/<build id>.fmu`` (beside each of these FMUs)
    The builds of other dtcosim versions set aside, the last three per FMU
    (:mod:`orchestrator.provision.other_builds`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Protocol

from components.compile.user_cache import CACHE_VARIABLE, user_cache_root
from components.errors import os_error_text

from ..errors import EntryError

#: environment variable naming the FMU folder
FMU_DIR_VARIABLE = "DTCOSIM_FMU_DIR"
#: folder of the FMU folder with the FMUs built from drivetrain files, one subfolder per file content
DRIVETRAIN_FOLDER = "drivetrains"
#: folder of the FMU folder with the FMUs built from load records, one subfolder per selected content
SERIES_FOLDER = "series"


class ContentKeyed(Protocol):
    """What an FMU is built from, named by its content: a drivetrain file or a load record selection.

    (:class:`orchestrator.inputs.drivetrain_file.DrivetrainSpec`,
    :class:`orchestrator.inputs.series_spec.SeriesSpec`; not imported here, to keep this module light.)
    """

    @property
    def key(self) -> str:
        """``<name>-<sha256[:16]>`` of the content."""


def default_fmu_dir() -> Path:
    """The FMU folder: ``$DTCOSIM_FMU_DIR`` if set, else ``<user cache>/fmus`` (not created here)."""
    explicit = os.environ.get(FMU_DIR_VARIABLE)
    if explicit:
        return Path(explicit)
    return user_cache_root() / "fmus"


class FmuFolderError(EntryError):
    """The FMU folder cannot be created: names the setting that chose it, its value and the reason."""

    kind = "setting"


def usable_fmu_dir(fmu_dir: str | Path | None = None, option: str = "--fmu-dir") -> Path:
    """The FMU folder to build into - ``fmu_dir`` (given by the command-line ``option``), else
    :func:`default_fmu_dir` - created if missing.

    Raises
    ------
    FmuFolderError
        It cannot be created (a missing or read-only parent, a file in its place), naming where it was chosen.
    """
    folder = default_fmu_dir() if fmu_dir is None else Path(fmu_dir)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        reason = "a file is there" if folder.exists() and not folder.is_dir() else os_error_text(exc, str(folder))
        if fmu_dir is not None:
            key, value = option, str(fmu_dir)
        elif os.environ.get(FMU_DIR_VARIABLE):
            key, value = FMU_DIR_VARIABLE, os.environ[FMU_DIR_VARIABLE]
        elif os.environ.get(CACHE_VARIABLE):
            key, value = CACHE_VARIABLE, os.environ[CACHE_VARIABLE]
        else:
            key, value = "the FMU folder", str(folder)
        raise FmuFolderError(key, value, f"a place for the FMU folder {folder}, which cannot be created ({reason}); "
                             f"{option} or {FMU_DIR_VARIABLE} chooses another") from None
    return folder


def drivetrain_fmu_dir(fmu_dir: Path, spec: ContentKeyed) -> Path:
    """Where the FMUs built from a drivetrain file live: ``<fmu_dir>/drivetrains/<name>-<sha256[:16]>/``."""
    return Path(fmu_dir) / DRIVETRAIN_FOLDER / spec.key


def series_fmu_dir(fmu_dir: Path, spec: ContentKeyed) -> Path:
    """Where the TimeSeriesSource built from a load record lives: ``<fmu_dir>/series/<stem>-<sha256[:16]>/``."""
    return Path(fmu_dir) / SERIES_FOLDER / spec.key


#: the file a content folder's FMUs touch each time a command uses them (:func:`mark_used`)
USED_MARK = ".used"
#: days after which a content folder of the default FMU folder that no command used is stale (``dtcosim cache``)
UNUSED_DAYS = 30


def mark_used(folder: Path) -> None:
    """Record that a command uses the FMUs of content folder ``folder`` now (best effort: a read-only folder keeps
    its older date)."""
    try:
        (Path(folder) / USED_MARK).touch()
    except OSError:
        pass


def last_used(folder: Path) -> float:
    """When a command last used the FMUs of content folder ``folder`` (POSIX time): its mark's date, else the newest
    of its files' (a folder built before the marks)."""
    folder = Path(folder)
    try:
        return (folder / USED_MARK).stat().st_mtime
    except OSError:
        return max((p.stat().st_mtime for p in folder.rglob("*") if p.is_file()), default=folder.stat().st_mtime)


def content_folders(fmu_dir: Path) -> list[Path]:
    """The content-keyed folders of FMU folder ``fmu_dir`` (drivetrain files' and load records'; not hidden ones)."""
    return sorted(p for kind in (DRIVETRAIN_FOLDER, SERIES_FOLDER) for p in (Path(fmu_dir) / kind).glob("*")
                  if p.is_dir() and not p.name.startswith("."))
