"""One study point, run where a Dask worker runs it: the engines.

Everything a worker needs travels with the tasks: a :class:`StudyPayload`
shared by all points of a sweep (scattered to the cluster once: the base
system or model, the measures, and for the co-simulation engine the FMU files
as bytes) and a small :class:`PointTask` per point (its key, index and parameter
values). No shared file system is assumed: a worker writes the FMU bytes into
its own temporary directory, once per FMU content (SHA-256), and runs from there.

Engines
-------
``monolithic``
    :func:`components.reference.solver.simulate_monolithic` (LSODA with the analytic
    Jacobian) on the monolithic model: a scenario's (same drivetrain, wind seed and
    generator, :func:`orchestrator.cosim.physics_view.physics_view`) or a built-in model
    (:mod:`orchestrator.study.models`).
``cosim``
    The scenario's FMUs stepped by :class:`orchestrator.cosim.master.CoSimulation`.

With a payload's ``run_data`` (a load-case set, :mod:`orchestrator.study.run_data`)
a co-simulation point also returns the rainflow cycles and load levels of its load
channels, extracted in the worker so the samples never travel; with a
``progress_topic`` it publishes its progress while it runs.

:func:`run_point` never raises for a failure of the point itself (a parameter
the model rejects, a solver or FMU failure): it returns a record with
``status = "failed"`` and the error message. Anything else (a bug, a lost
worker) reaches the client as an exception and is recorded there.
"""

from __future__ import annotations

import atexit
import hashlib
import math
import os
import shutil
import socket
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

from components.errors import DtcosimError, WallTimeLimitError

from ..inputs.measures import Measure
from .measure_values import max_abs_rate, window_load_sharing, window_statistic

#: joins the force columns of a stage measure in ``StudyPayload.series_names``
STAGE_COLUMNS = "|"

#: outcome statuses of a point
OK, FAILED = "ok", "failed"


@dataclass(frozen=True)
class StudyPayload:
    """What every point of a sweep shares (scattered to the workers once).

    Attributes
    ----------
    study : str
        Study name.
    engine : {"monolithic", "cosim"}
    measures : tuple of Measure
    system : ResolvedSystem or None
        Scenario base: the checked scenario with the study's simulation overrides
        and fixed parameters applied (and the variables the measures need recorded).
    model : str or None
        Built-in model name (:data:`orchestrator.study.models.MODELS`).
    model_parameters : mapping
        A built-in model's fixed parameter values.
    time_grid : (float, float, float)
        Built-in model: start, stop and output interval [s].
    window_s : (float, float)
        Analysis window of the statistics [s].
    solver : mapping
        :class:`components.reference.solver.SolverSettings` fields (monolithic engine).
    series_names : mapping of str -> str
        Monolithic engine: measure variable ``component.variable`` -> series name of
        :class:`components.reference.results.SimulationResult`. A stage measure
        (``gearbox.stage1:load_sharing``) -> its planets' force columns (co-simulation) or series
        (monolithic), joined by :data:`STAGE_COLUMNS`.
    fmu_blobs : mapping of str -> bytes
        Co-simulation: FMU file content by SHA-256.
    timeout_s : float or None
        Wall-clock time [s] one point may take (``Study.timeout_s``); None: no limit.
    structures : mapping of str -> ResolvedSystem
        A study varying drivetrain file entries: the system of each drivetrain structure
        (:mod:`orchestrator.study.drivetrain_variants`).
    variants : mapping of int -> PointVariant
        Point index -> its structure and the FMU parameter values that replace its file entries.
    run_data : RunDataSpec or None
        Co-simulation: also extract cycles and level histograms of these load channels
        (:mod:`orchestrator.study.run_data`; a load-case set), returned as the record's ``data``.
    progress_topic : str or None
        Co-simulation in a Dask worker: publish ``{"key", "index", "done", "total"}`` (communication
        steps) on this topic while a point runs (``Worker.log_event``, at most twice a second).
    """

    study: str
    engine: str
    measures: tuple[Measure, ...]
    system: Any = None
    model: str | None = None
    model_parameters: Mapping[str, Any] = field(default_factory=dict)
    time_grid: tuple[float, float, float] | None = None
    window_s: tuple[float, float] | None = None
    solver: Mapping[str, Any] = field(default_factory=dict)
    series_names: Mapping[str, str] = field(default_factory=dict)
    fmu_blobs: Mapping[str, bytes] = field(default_factory=dict)
    timeout_s: float | None = None
    structures: Mapping[str, Any] = field(default_factory=dict)
    variants: Mapping[int, Any] = field(default_factory=dict)
    run_data: Any = None
    progress_topic: str | None = None


@dataclass(frozen=True)
class PointTask:
    """One point to run.

    Attributes
    ----------
    key : str
        The point's identity (see :func:`orchestrator.study.prepare.point_key`).
    index : int
        Position in the study.
    parameters : mapping of str -> value
        ``"component.parameter"`` values of this point (on top of the base's).
    """

    key: str
    index: int
    parameters: Mapping[str, Any]


# ------------------------------------------------------------------ FMU files
_FMU_DIR: Path | None = None
_FMU_FILES: dict[str, Path] = {}


def local_fmu(sha256: str, blob: bytes, filename: str) -> Path:
    """The FMU with this content as a file in this process's temporary directory.

    Written once per content hash and process; the directory is removed at
    interpreter exit.

    Parameters
    ----------
    sha256 : str
        Hex digest the content must have (checked).
    blob : bytes
        The FMU file's content.
    filename : str
        File name to use (the original's, e.g. ``Gearbox.fmu``).
    """
    global _FMU_DIR
    cached = _FMU_FILES.get(sha256)
    if cached is not None and cached.is_file():
        return cached
    if hashlib.sha256(blob).hexdigest() != sha256:
        raise DtcosimError(f"FMU {filename}: content does not match its SHA-256 {sha256[:12]}... (corrupted in transfer?)")
    if _FMU_DIR is None:
        _FMU_DIR = Path(tempfile.mkdtemp(prefix="dtcosim-sweep-fmus-"))
        atexit.register(shutil.rmtree, _FMU_DIR, True)
    folder = _FMU_DIR / sha256[:16]
    folder.mkdir(exist_ok=True)
    path = folder / filename
    tmp = folder / (filename + ".part")
    tmp.write_bytes(blob)
    os.replace(tmp, path)
    _FMU_FILES[sha256] = path
    return path


def _point_system(payload: StudyPayload, task: PointTask, local_files: bool):
    """The payload's system with the point's parameters (and local FMU files for the co-simulation)."""
    from ..inputs.study import split_parameter

    system = payload.system
    parameters = dict(task.parameters)
    variant = payload.variants.get(task.index)
    if variant is not None:  # drivetrain file entries: the structure's FMUs and the flat values they give
        system = payload.structures[variant.structure]
        parameters = {k: v for k, v in parameters.items() if ".drivetrain." not in k}
        parameters.update(variant.parameters)
    scenario = system.scenario
    by_component: dict[str, dict[str, Any]] = {}
    for name, value in parameters.items():
        comp, param = split_parameter(name)
        by_component.setdefault(comp, {})[param] = value
    for comp, values in by_component.items():
        scenario = scenario.with_parameters(comp, **values)
    system = replace(system, scenario=scenario)
    if local_files:
        paths = {}
        interfaces = {}
        for comp, iface in system.interfaces.items():
            path = local_fmu(iface.sha256, payload.fmu_blobs[iface.sha256], Path(iface.path).name)
            paths[comp] = path
            interfaces[comp] = replace(iface, path=path)
        system = replace(system, fmu_paths=paths, interfaces=interfaces)
    return system


# -------------------------------------------------------------------- engines
def _monolithic(payload: StudyPayload, task: PointTask) -> tuple[dict[str, float], None]:
    from components.reference.acceleration import peak_output_acceleration
    from components.reference.solver import SolverSettings, simulate_monolithic

    wall0 = time.perf_counter()
    settings = SolverSettings(**payload.solver, wall_time_limit_s=payload.timeout_s or 0.0)
    if payload.model is not None:
        from .models import MODELS

        values = {**payload.model_parameters, **task.parameters}
        drivetrain, driver = MODELS[payload.model].build(values)
        start, stop, interval = payload.time_grid
        initial = MODELS[payload.model].start
    else:
        from components.model.wind import RotorSpeedProcess

        from ..cosim.physics_view import physics_view

        system = _point_system(payload, task, local_files=False)
        view = physics_view(system)
        drivetrain, driver = view.drivetrain, RotorSpeedProcess(view.wind)
        sim = system.scenario.simulation
        start, stop, interval = sim.start_s, sim.stop_s, sim.output_interval_s
        initial = view.start
    result = simulate_monolithic(drivetrain, driver, stop, output_interval_s=interval, settings=settings,
                                 t_start_s=start, raise_on_failure=True, start=initial)
    out: dict[str, float] = {}
    for m in payload.measures:
        if m.name == "cpu_time":
            out[m.name] = float(result.info["cpu_time_s"])
        elif m.name == "wall_time":
            out[m.name] = float(result.wall_time_s)
        elif m.name == "steps":
            out[m.name] = float(result.info["steps"])
        elif m.name == "rhs_calls":
            out[m.name] = float(result.info["rhs_calls"])
        elif m.name == "I_max_acc":
            if payload.timeout_s:  # the point's limit covers this second integration too
                left = payload.timeout_s - (time.perf_counter() - wall0)
                if left <= 0.0:
                    raise WallTimeLimitError(payload.timeout_s, stop)
                settings = replace(settings, wall_time_limit_s=left)
            try:
                peak = peak_output_acceleration(drivetrain, driver, stop, settings=settings, t_start_s=start)
            except WallTimeLimitError as exc:  # name the point's limit, not what was left of it
                raise WallTimeLimitError(payload.timeout_s, exc.time_s) from None
            out[m.name] = peak.value_rad_s2
        elif m.of_stage:
            forces = [result.series[c] for c in payload.series_names[m.name].split(STAGE_COLUMNS)]
            out[m.name] = window_load_sharing(result.time_s, forces, payload.window_s)
        else:
            series = result.series[payload.series_names[m.variable]]
            out[m.name] = window_statistic(result.time_s, series, payload.window_s, m.statistic)
    return out, None


def _progress_publisher(topic: str | None, task: PointTask, here: Callable[[dict], None] | None = None):
    """A master progress callback: to ``here`` (a point run in the sweep's own process), else published on
    ``topic`` from this Dask worker (None outside a worker); at most twice a second."""
    if here is not None:
        send = here
    else:
        if not topic:
            return None
        try:
            from distributed import get_worker

            worker = get_worker()
        except (ImportError, ValueError):
            return None

        def send(event: dict) -> None:
            worker.log_event(topic, event)

    last = [0.0]

    def publish(done: int, total: int) -> None:
        now = time.monotonic()
        if done < total and now - last[0] < 0.5:
            return
        last[0] = now
        send({"key": task.key, "index": task.index, "done": int(done), "total": int(total)})

    return publish


def _cosim(payload: StudyPayload, task: PointTask, progress=None, stop=None) -> tuple[dict[str, float], dict | None]:
    from ..cosim.master import CoSimulation

    system = _point_system(payload, task, local_files=True)
    cpu0 = time.process_time()
    outcome = CoSimulation(system).run(progress=_progress_publisher(payload.progress_topic, task, progress),
                                       handle_sigint=False, wall_time_limit_s=payload.timeout_s, stop=stop)
    cpu = time.process_time() - cpu0
    if outcome.interrupted:
        raise PointInterrupted(outcome.error or "interrupted")
    if not outcome.complete:
        raise DtcosimError(outcome.error or "the co-simulation stopped early")
    out: dict[str, float] = {}
    for m in payload.measures:
        if m.name == "cpu_time":
            out[m.name] = cpu
        elif m.name == "wall_time":
            out[m.name] = float(outcome.wall_time_s)
        elif m.name == "I_max_acc":
            variable = payload.series_names["I_max_acc"]
            if variable.endswith(".alpha_out_max"):  # running maximum: its last value is eq. 11
                out[m.name] = float(outcome.column(variable)[-1])
            else:
                out[m.name] = max_abs_rate(outcome.time_s, outcome.column(variable))
        elif m.of_stage:
            forces = [outcome.column(c) for c in payload.series_names[m.name].split(STAGE_COLUMNS)]
            out[m.name] = window_load_sharing(outcome.time_s, forces, system.scenario.simulation.window_s)
        else:
            values = outcome.column(m.variable)
            out[m.name] = window_statistic(outcome.time_s, values, system.scenario.simulation.window_s, m.statistic)
    data = None
    if payload.run_data is not None:
        from .run_data import collect_run_data

        data = collect_run_data(payload.run_data, outcome.time_s, outcome.column)
    return out, data


def _clean(value: float) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


class PointInterrupted(Exception):
    """A point run in the sweep's own process stopped by a stop request: neither done nor failed."""


def run_point(payload: StudyPayload, task: PointTask, progress: Callable[[dict], None] | None = None,
              stop=None) -> dict[str, Any]:
    """Run one point and compute its measures (in a Dask worker, or in the sweep's own process).

    Parameters
    ----------
    payload : StudyPayload
    task : PointTask
    progress : callable(event), optional
        In the sweep's own process: receives the progress events a worker publishes on the
        payload's ``progress_topic``.
    stop : orchestrator.cosim.stop_requests.StopRequests, optional
        In the sweep's own process: the sweep's stop requests; a co-simulation checks them
        between blocks of steps and a stopped point raises :class:`PointInterrupted`.

    Returns
    -------
    dict
        ``key``, ``index``, ``status`` (``"ok"`` or ``"failed"``), ``measures``
        (name -> value, non-finite as None), ``error`` (message or None),
        ``error_type``, ``worker`` (``host:pid``), ``task_wall_time_s``; with a payload's
        ``run_data`` also ``data`` (:func:`orchestrator.study.run_data.collect_run_data`).
    """
    wall0 = time.perf_counter()
    record: dict[str, Any] = {"key": task.key, "index": task.index, "status": OK, "measures": {}, "error": None,
                              "error_type": None}
    try:
        values, data = (_monolithic(payload, task) if payload.engine == "monolithic"
                        else _cosim(payload, task, progress, stop))
        record["measures"] = {k: _clean(v) for k, v in values.items()}
        if data is not None:
            record["data"] = data
    except DtcosimError as exc:
        record["status"] = FAILED
        record["error"] = str(exc)
        record["error_type"] = type(exc).__name__
    record["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    record["task_wall_time_s"] = time.perf_counter() - wall0
    return record

