"""TimeSeriesSource FMUs built from load records, kept apart by content.

The FMU of a scenario's ``[components.<name>.series]`` (the FMU :func:`fmus.registry.built_from`
a load record) lives in ``<FMU folder>/series/<load record stem>-<sha256[:16]>/TimeSeriesSource.fmu``
(:func:`orchestrator.provision.folders.series_fmu_dir`): the hash covers the selected, converted
samples and every option, so a changed load record or selection gets a new FMU. The samples are
packed into the FMU (``resources/series.npz``); the load record file is not needed to run it.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Callable

from fmus.build import BuiltFmu, build_fmu
from fmus.build_lock import build_lock
from fmus.registry import LOAD_RECORD, built_from
from fmus.slaves.time_series_source import DATA_FILE

from ..inputs.series_spec import SeriesSpec
from .folders import mark_used, series_fmu_dir
from .other_builds import swap_in
from .staleness import broken_fmu, stale_project_fmus

#: the FMU a load record is built into
(SERIES_FMU,) = built_from(LOAD_RECORD)


def build_series_fmu(spec: SeriesSpec, out_dir: Path, report: Callable[[str], None] | None = None,
                     validate: bool = True) -> BuiltFmu:
    """Build the TimeSeriesSource of ``spec`` into ``out_dir``."""
    if report:
        report(f"building {SERIES_FMU.file_name} from {spec.record.name} into {out_dir} ...")
    with tempfile.TemporaryDirectory(prefix="dtcosim_series_") as tmp:
        data = Path(tmp) / DATA_FILE
        data.write_bytes(spec.npz_bytes())
        return build_fmu(SERIES_FMU.name, out_dir, model=spec.model(), origin=f"record {spec.record.name}",
                         resources={DATA_FILE: data}, validate=validate)


def ensure_series_fmu(spec: SeriesSpec, fmu_dir: Path, report: Callable[[str], None] | None = None) -> Path:
    """The TimeSeriesSource FMU of ``spec`` in ``fmu_dir``, built when missing or stale."""
    path = series_fmu_dir(fmu_dir, spec) / SERIES_FMU.file_name

    def needed() -> bool:
        return not path.is_file() or broken_fmu(path) is not None or bool(stale_project_fmus({"series": path}))

    if needed():
        with build_lock(path.parent, report):  # decided again and built by one process at a time
            if needed() and not swap_in(path):  # built meanwhile, or kept aside (other_builds)
                build_series_fmu(spec, path.parent, report)
    mark_used(path.parent)
    return path
