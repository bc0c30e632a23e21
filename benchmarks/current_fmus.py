"""The FMUs a benchmark measures: the scenario's, built where missing, and refused where stale.

``dtcosim run`` only warns about a project FMU built from other code than the installed
dtcosim; a benchmark would then time the old code and print its figures as today's
(it happened in issue 14: a 600 s run measured 314 MB with FMUs of the session before).
"""

from __future__ import annotations

from pathlib import Path


def current_fmu_paths(scenario, fmu_dir: str | Path | None = None) -> dict[str, Path]:
    """:func:`orchestrator.provision.project_fmus.ensure_fmus`, then exit naming every stale project FMU."""
    from orchestrator.provision.project_fmus import ensure_fmus
    from orchestrator.provision.staleness import stale_project_fmus

    paths = ensure_fmus(scenario, fmu_dir)
    stale = stale_project_fmus(paths)
    if stale:
        raise SystemExit("benchmark refused: it would measure old code\n  " + "\n  ".join(stale))
    return paths
