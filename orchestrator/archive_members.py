"""How a file that dtcosim extracted from an archive the user named is shown in messages: ``<archive>!<member>``.

An ``.ssp`` archive is extracted into a temporary folder before its SSD and FMUs
are read (:mod:`orchestrator.interop.ssp_import`); a message naming the extracted
copy (``/tmp/dtcosim-ssp-.../resources/Gearbox.fmu``) would name a file the user
cannot find and that is gone when dtcosim exits. The importer records each folder
it extracts (:func:`record_extraction`), and every message that names an FMU or an
SSP file shows it as :func:`shown_path` does: ``system.ssp!resources/Gearbox.fmu``,
the convention of :mod:`fmus.cross_check` for members of an FMU.
"""

from __future__ import annotations

from pathlib import Path

#: extracted folder (resolved) -> the archive as the user named it
_EXTRACTED: dict[Path, str] = {}


def record_extraction(folder: Path, archive: str | Path) -> None:
    """Files under ``folder`` are members of ``archive`` (the name the user gave it)."""
    _EXTRACTED[Path(folder).resolve()] = str(archive)


def shown_path(path: str | Path) -> str:
    """``path`` as a message names it: ``<archive>!<member>`` for a file extracted from an archive, else as given."""
    if _EXTRACTED:
        resolved = Path(path).resolve()
        for folder, archive in _EXTRACTED.items():
            if resolved.is_relative_to(folder):
                return f"{archive}!{resolved.relative_to(folder).as_posix()}"
    return str(path)
