"""TimeSeriesSource FMUs built from recorded series, kept apart by content.

The FMU of a scenario's ``[components.<name>.series]`` lives in
``<FMU directory>/series/<record stem>-<sha256[:16]>/TimeSeriesSource.fmu``
(:func:`orchestrator.inputs.scenario.series_fmu_dir`): the hash covers the selected, converted
samples and every option, so a changed record or selection gets a new FMU. The samples are packed
into the FMU (``resources/series.npz``); the record file is not needed to run it.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Callable

from ..inputs.scenario import SERIES_FMU_FILE, series_fmu_dir
from ..inputs.series_spec import SeriesSpec


def build_series_fmu(spec: SeriesSpec, out_dir: Path, report: Callable[[str], None] | None = None,
                     validate: bool = True):
    """Build the TimeSeriesSource of ``spec`` into ``out_dir``; returns the ``fmus.build.BuiltFmu``."""
    from fmus.build import build_fmu
    from fmus.slaves.time_series_source import DATA_FILE

    if report:
        report(f"building {SERIES_FMU_FILE} from {spec.record.name} into {out_dir} ...")
    with tempfile.TemporaryDirectory(prefix="dtcosim_series_") as tmp:
        data = Path(tmp) / DATA_FILE
        data.write_bytes(spec.npz_bytes())
        return build_fmu("TimeSeriesSource", out_dir, model=spec.model(), origin=f"record {spec.record.name}",
                         resources={DATA_FILE: data}, validate=validate)


def ensure_series_fmu(spec: SeriesSpec, fmu_dir: Path, report: Callable[[str], None] | None = None) -> Path:
    """The TimeSeriesSource FMU of ``spec`` in ``fmu_dir``, built when missing or stale."""
    from .fmu_store import stale_project_fmus

    path = series_fmu_dir(fmu_dir, spec) / SERIES_FMU_FILE
    if not path.is_file() or stale_project_fmus({"series": path}):
        build_series_fmu(spec, path.parent, report)
    return path
