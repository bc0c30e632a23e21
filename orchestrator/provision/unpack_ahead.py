"""An FMU just built for a run, unpacked for it by the process that built it (:func:`unpack_ahead`).

A run loads each FMU from its folder in the unpacked-FMU cache (:mod:`orchestrator.cosim.unpacked_fmus`),
which the first run of a new FMU fills: ~0.05-0.08 s per FMU, after the builds. The builds of a
first run share two processes (:mod:`fmus.build_pool`), and the forked builder is done before the
run's own process is; unpacking each FMU where it was built (:func:`fmus.build.build_several`'s
``after_each``) takes that part off the run's path. The run still checks the folder as at every use.
"""

from __future__ import annotations

from pathlib import Path

from fmus.archive_checks import FmuArchiveError, extract_fmu

from ..cosim.fmu_interface import file_sha256
from ..cosim.unpacked_fmus import unpacked


def unpack_ahead(path: Path) -> Path | None:
    """Unpack the FMU at ``path`` into the unpacked-FMU cache; its folder there, or None where that failed (a
    read-only or full cache, a damaged archive: the run that loads it extracts it as usual and says what is
    wrong)."""
    try:
        return unpacked(Path(path), file_sha256(path), extract_fmu, fallback=False)
    except (OSError, FmuArchiveError):
        return None
