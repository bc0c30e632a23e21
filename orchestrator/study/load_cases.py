"""A load-case set as a study: its runs (bin x seed), its load channels, ready for the sweep machinery.

:func:`prepare_load_cases` checks a :class:`~orchestrator.inputs.load_cases.LoadCaseSet`
against its base scenario and its FMUs and turns it into a
:class:`~orchestrator.study.prepare.PreparedStudy` of the co-simulation engine
whose explicit points are the runs, bins outermost and seeds innermost: each
sets the bin's operating point and the seed. The sweep
(:func:`orchestrator.study.sweep.run_sweep`) then runs it on Dask, journals it
and resumes it like any study.

Where the operating point goes is found by the declared roles
(:mod:`orchestrator.cosim.roles`): the mean rotor speed, its fluctuation and
spectral level are the wind source's ``omega0``, ``sigma`` and ``a``
(:data:`components.model.parameter_map.WIND_FIELDS`), the generator torque the
generator's ``counter_torque``; the seed is the wind source's ``seed`` unless the
set names another parameter.

Seeds: every bin gets realisations of its own. The seed parameter of run ``s`` in
bin ``b`` is ``s + SEED_STRIDE * b`` (:data:`SEED_STRIDE`), so bins at the same
operating point (every region-3 bin under the law) are independent samples, not
the same run counted twice; ``{seed}`` in a string parameter is the seed as
listed (e.g. the record ``DLC1.2_{seed}.outb`` of the bin's own row).

Channels
--------
Every load the gearbox declares (its record's signals): the ``rotor_torque``,
every ``shaft_torque``, every ``contact_force`` (with the load cycles of its two
gears, :mod:`orchestrator.study.rating_plan`) and every ``bearing_force`` (with the
bearing's revolutions); plus the recorded channels the set names. Nothing is chosen by a variable's name. The gears of the load
revolution distributions come from the declarations too: a shaft torque acts
on the bodies at its ``upstream`` and ``downstream`` ends, each with the speed
the gearbox declares for that body (``body_speed``), an end that is no body of
the gearbox being the generator (its ``generator_speed``); the rotor torque acts
on the rotor, with the wind source's ``rotor_speed``.

Point keys are the study's (:func:`orchestrator.study.prepare.point_key`) with
what the runs' data depend on added (channels, window, rainflow gate and
residue); the wind distribution, the life, the S-N curves and the equivalent
cycle count are applied afterwards and change no key, so changing them
re-runs nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

from ..errors import EntryError, ScenarioError, suggestion
from ..inputs.load_cases import SEED_PLACEHOLDER, LoadBin, LoadCaseError, LoadCaseSet
from ..inputs.origins import Origin
from ..inputs.study import Base, Study
from .prepare import PreparedStudy, point_key, prepare_study
from .rating_plan import RatingPlan, bearing_channels, mesh_channel, plan_ratings
from .run_data import Channel, RunDataSpec

#: the seed parameter of a run is its listed seed + SEED_STRIDE x its bin index (independent bins)
SEED_STRIDE = 1000
#: operating-point field -> (role, parameter of the dtcosim FMU of that role, load-case key)
TARGETS = {
    "rotor_speed_rad_s": ("wind_source", "omega0", "rotor_speed_rpm"),
    "sigma_rad_s": ("wind_source", "sigma", "sigma_rpm"),
    "spectrum_level": ("wind_source", "a", "spectrum_level"),
    "generator_torque_nm": ("generator", "counter_torque", "generator_torque"),
}


@dataclass(frozen=True)
class Case:
    """One run of a load-case set.

    Attributes
    ----------
    index : int
        Point index of the study.
    bin : int
        Wind-speed bin index.
    seed : int
        The seed as listed in the set (the seed parameter gets ``seed + SEED_STRIDE * bin``).
    parameters : mapping
        ``component.parameter`` values of the run.
    """

    index: int
    bin: int
    seed: int
    parameters: Mapping[str, Any]


@dataclass(frozen=True)
class PreparedLoadCases:
    """A load-case set checked against its base, ready to run.

    Attributes
    ----------
    load_cases : LoadCaseSet
    bins : tuple of LoadBin
    cases : tuple of Case
    channels : tuple of Channel
    prepared : PreparedStudy
        The study the sweep runs (its payload extracts the channels' data).
    high_speed_shaft : str or None
        Column of the shaft torque whose downstream end is outside the gearbox (the generator).
    meshes : mapping of str -> tuple of str
        ``"<stage> <mesh>"`` -> contact-force columns of that stage's mesh kind (one per planet).
    notes : tuple of str
    settling : mapping or None
        The base drivetrain's settling time at the base scenario's start, with the mode it comes from.
    """

    load_cases: LoadCaseSet
    bins: tuple[LoadBin, ...]
    cases: tuple[Case, ...]
    channels: tuple[Channel, ...]
    prepared: PreparedStudy
    high_speed_shaft: str | None
    meshes: Mapping[str, tuple[str, ...]]
    notes: tuple[str, ...] = ()
    #: the base drivetrain's settling time (:meth:`components.analysis.settling.Settling.as_dict`), None without one
    settling: Mapping[str, Any] | None = None
    #: the meshes and bearings rated by ISO 6336 and ISO 281 (:mod:`orchestrator.study.rating_plan`)
    ratings: RatingPlan = field(default_factory=RatingPlan)

    @property
    def keys(self) -> tuple[str, ...]:
        """Point key of each case."""
        return self.prepared.keys


def _settled(lcs: LoadCaseSet, fmu_dir, build: bool,
             report: Callable[[str], None] | None) -> tuple[LoadCaseSet, dict | None, list[str]]:
    """The set with transient and length in seconds (``"settled"``, ``"to_stop"`` resolved), the base drivetrain's
    settling time and the warnings about the window (the FMUs of the base scenario are instantiated once)."""
    from ..cosim.operating_point import start_analyses
    from ..cosim.system import resolve_system
    from ..inputs.overrides import apply_parameters
    from ..provision.project_fmus import ensure_fmus
    from ..run.runner import load_any

    try:
        scenario = apply_parameters(load_any(lcs.base_path), lcs.base_parameters,
                                    lcs.base_origins()).with_allowed(*lcs.allow_implausible)
        system = resolve_system(scenario, fmu_paths=ensure_fmus(scenario, fmu_dir, build=build, report=report))
    except ScenarioError as exc:
        raise LoadCaseError("base.scenario", lcs.base_scenario, f"a valid scenario with its FMUs ({exc})",
                            lcs.source) from None
    settling, limit = start_analyses(system)
    resolved, notes = lcs.settled(None if settling is None else settling.time_s,
                                  "" if settling is None else settling.describe(), scenario.simulation.stop_s)
    return resolved, None if settling is None else settling.as_dict(), notes + _grid_notes(resolved, scenario, limit)


def _grid_notes(lcs: LoadCaseSet, scenario, limit) -> list[str]:
    """Warnings about the runs' step, output interval and window against the drivetrain's modes split across FMUs
    (``limit``: :mod:`components.analysis.coupling_step`); none where the grid is refused later
    (:func:`_base_system`)."""
    if limit is None:
        return []
    try:
        sim = lcs.time_grid().apply(scenario)[0].simulation
    except ScenarioError:
        return []
    return list(limit.warnings(sim.step_s, sim.step_s * sim.output_stride, sim.window_s).values())


def _base_system(lcs: LoadCaseSet, fmu_dir, build: bool):
    """The base scenario with the fixed parameters and the runs' time grid, resolved against its FMUs."""
    from ..provision.project_fmus import ensure_fmus
    from ..cosim.system import resolve_system
    from ..inputs.overrides import apply_parameters
    from ..run.runner import load_any

    src = lcs.source
    try:
        scenario = load_any(lcs.base_path)
        scenario, _ = lcs.time_grid().apply(scenario)
        paths = ensure_fmus(scenario, fmu_dir, build=build)
        return resolve_system(apply_parameters(scenario, lcs.base_parameters,
                                               lcs.base_origins()).with_allowed(*lcs.allow_implausible),
                              fmu_paths=paths)
    except ScenarioError as exc:
        raise LoadCaseError("base.scenario", lcs.base_scenario, f"a valid scenario with its FMUs ({exc})", src) from None


def _one_role(system, role: str, what: str, src: str | None) -> Any:
    found = system.with_role(role)
    if len(found) != 1:
        raise LoadCaseError("base.scenario", str(system.scenario.source or system.scenario.name),
                            f"a scenario with exactly one component of role {role} ({what}); found {len(found)}", src)
    return found[0]


def _channels(system, lcs: LoadCaseSet) -> tuple[tuple[Channel, ...], str | None, dict[str, tuple[str, ...]],
                                                 RatingPlan]:
    src = lcs.source
    gearbox = _one_role(system, "gearbox", "its declared shaft torques and mesh forces are the load channels", src)
    comp = gearbox.component
    ratings = plan_ratings(system, gearbox, lcs)
    units = {name: v.unit for name, v in system.interfaces[comp].variables.items()}
    bodies = {s.info.get("body"): f"{comp}.{s.variable}" for s in gearbox.of_kind("body_speed")}
    winds = system.with_role("wind_source")
    gens = system.with_role("generator")
    rotor_speed = winds[0].column("rotor_speed") if len(winds) == 1 else None
    generator_speed = gens[0].column("generator_speed") if len(gens) == 1 else None
    out: list[Channel] = []
    hss = None
    meshes: dict[str, list[str]] = {}
    for sig in gearbox.signals:
        column = f"{comp}.{sig.variable}"
        unit = units.get(sig.variable, "")
        if sig.kind == "rotor_torque":
            gears = (("rotor", rotor_speed),) if rotor_speed else ()
            out.append(Channel(column, unit, sig.kind, dict(sig.info), gears))
        elif sig.kind == "shaft_torque":
            gears = []
            for end in (sig.info.get("upstream"), sig.info.get("downstream")):
                if not end:
                    continue
                if end in bodies:
                    gears.append((end, bodies[end]))
                elif generator_speed:  # the end outside the gearbox: the generator it drives
                    gears.append((end, generator_speed))
                    hss = column
            out.append(Channel(column, unit, sig.kind, dict(sig.info), tuple(gears)))
        elif sig.kind == "contact_force":
            out.append(mesh_channel(ratings, column, unit, sig.kind, sig.info))
            label = f"{sig.info.get('stage', '')} {sig.info.get('mesh', '')}".strip()
            meshes.setdefault(label, []).append(column)
    if hss is None:  # no generator speed declared: the shaft whose downstream end is no gearbox body
        for ch in out:
            if ch.kind == "shaft_torque" and ch.info.get("downstream") and ch.info["downstream"] not in bodies:
                hss = ch.column
    out += bearing_channels(ratings, units)
    taken = {c.column for c in out}
    for i, name in enumerate(lcs.fatigue.channels):
        c, _, var = name.partition(".")
        iface = system.interfaces.get(c)
        fv = iface.variables.get(var) if iface is not None else None
        if fv is None or fv.type != "Real" or fv.causality not in ("output", "local"):
            choices = [f"{k}.{n}" for k, f in system.interfaces.items() for n, v in f.variables.items()
                       if v.type == "Real" and v.causality == "output"]
            raise LoadCaseError(f"fatigue.channels[{i}]", name, f"a Real output of the base scenario's FMUs"
                                f"{suggestion(name, choices)}", src)
        if name not in taken:
            out.append(Channel(name, fv.unit, "recorded"))
            taken.add(name)
    if not out:
        raise LoadCaseError("base.scenario", lcs.base_scenario, "a gearbox that declares shaft torques or contact "
                            "forces, or fatigue.channels", src)
    return tuple(out), hss, {k: tuple(v) for k, v in meshes.items()}, ratings


def _targets(system, lcs: LoadCaseSet, bins: tuple[LoadBin, ...]) -> dict[str, str]:
    """Operating-point field -> ``component.parameter`` for every field some bin gives."""
    src = lcs.source
    out = {}
    for field_name, (role, param, key) in TARGETS.items():
        if all(getattr(b.point, field_name) is None for b in bins):
            continue
        where = "operating_law" if lcs.law is not None else f"operating_points[].{key}"
        comp = _one_role(system, role, f"it takes the operating point's {key}", src).component
        if param not in system.interfaces[comp].variables:
            raise LoadCaseError(where, key, f"a {role} FMU with a parameter {param} (component {comp} has none: give "
                                "this bin's input as operating_points[].parameters instead)", src)
        out[field_name] = f"{comp}.{param}"
    return out


def _seed_parameter(system, lcs: LoadCaseSet) -> str | None:
    if lcs.seed_parameter == "":
        return None
    if lcs.seed_parameter is not None:
        return lcs.seed_parameter
    winds = system.with_role("wind_source")
    if len(winds) == 1 and "seed" in system.interfaces[winds[0].component].variables:
        return f"{winds[0].component}.seed"
    if len(lcs.seeds) > 1:
        raise LoadCaseError("runs.seed_parameter", None, 'the parameter the seeds set (no wind source with a "seed" '
                            'parameter; "" for none: the seeds then only fill {seed} in string parameters)', lcs.source)
    return None


def _with_seed(value: Any, seed: int) -> Any:
    return value.replace(SEED_PLACEHOLDER, str(seed)) if isinstance(value, str) else value


def _cases(lcs: LoadCaseSet, bins, targets: Mapping[str, str], seed_parameter: str | None) -> tuple[Case, ...]:
    out = []
    for b in bins:
        fixed = {target: float(getattr(b.point, f)) for f, target in targets.items() if getattr(b.point, f) is not None}
        for seed in lcs.seeds:
            params: dict[str, Any] = dict(fixed)
            params.update({k: _with_seed(v, seed) for k, v in b.parameters.items()})
            if seed_parameter is not None:
                params[seed_parameter] = seed + SEED_STRIDE * b.index
            out.append(Case(len(out), b.index, seed, params))
    return tuple(out)


def _case_origins(lcs: LoadCaseSet, bins, case: Case, targets: Mapping[str, str],
                  seed_parameter: str | None) -> dict[str, Origin]:
    """Where each value of a run was given: the bin's row or the law, the row's parameters, the seeds."""
    b = bins[case.bin]
    run = f"run {case.index}, bin {b.label}, seed {case.seed}"
    out = {target: lcs.row_origin(b, target, run, (f, TARGETS[f][2])) for f, target in targets.items()}
    out.update({name: lcs.row_origin(b, name, run) for name in b.parameters})
    if seed_parameter is not None:
        out[seed_parameter] = Origin(lcs.source, f"runs.seeds ({seed_parameter})", run, LoadCaseError)
    return {name: origin for name, origin in out.items() if name in case.parameters}


def _measures(channels: tuple[Channel, ...]):
    from ..inputs.measures import parse_measure

    names = ["cpu_time", "wall_time"]
    for ch in channels:
        names += [f"{ch.column}:mean", f"{ch.column}:max"]
        names += [f"{speed}:mean" for _, speed in ch.gears]
    return tuple(parse_measure(n) for n in dict.fromkeys(names))


def prepare_load_cases(lcs: LoadCaseSet, fmu_dir: str | Path | None = None, build: bool = True,
                       report: Callable[[str], None] | None = None) -> PreparedLoadCases:
    """Check a load-case set against its base scenario and build its study (nothing runs); ``report`` receives what
    preparing the FMUs does (:func:`~orchestrator.study.prepare.prepare_study`).

    Raises
    ------
    LoadCaseError
        Naming the key of the first problem.
    """
    src = lcs.source
    bins = lcs.bins
    lcs, settling, window_notes = _settled(lcs, fmu_dir, build, report)
    system = _base_system(lcs, fmu_dir, build)
    channels, hss, meshes, ratings = _channels(system, lcs)
    targets = _targets(system, lcs, bins)
    seed_parameter = _seed_parameter(system, lcs)
    cases = _cases(lcs, bins, targets, seed_parameter)
    try:
        study = Study(name=lcs.name, engine="cosim",
                      base=Base("scenario", lcs.base_scenario, lcs.base_path, lcs.base_parameters),
                      measures=_measures(channels), points=tuple(c.parameters for c in cases),
                      simulation=lcs.time_grid(), timeout_s=lcs.timeout_s, description=lcs.description,
                      base_dir=None if src is None else Path(src).resolve().parent, source=src,
                      allow_implausible=lcs.allow_implausible,
                      point_origins=tuple(_case_origins(lcs, bins, c, targets, seed_parameter) for c in cases))
        prepared = prepare_study(study, fmu_dir=fmu_dir, build=build, report=report)
    except LoadCaseError:
        raise  # a run's value, named where the set gives it
    except EntryError as exc:
        raise LoadCaseError(exc.key, exc.value, exc.expected, src) from None
    spec = RunDataSpec(channels, lcs.time_grid().window_s, lcs.fatigue.gate_fraction, lcs.fatigue.residue)
    identity = {**prepared.identity, "load_cases": spec.identity()}
    # a run's key names its bin too: two bins with the same parameters are still two runs
    keys = tuple(point_key({**identity, "bin": [bins[c.bin].low_m_s, bins[c.bin].high_m_s]}, p)
                 for c, p in zip(cases, prepared.points))
    payload = replace(prepared.payload, run_data=spec)
    prepared = replace(prepared, payload=payload, identity=identity, keys=keys)
    return PreparedLoadCases(lcs, bins, cases, channels, prepared, hss, meshes,
                             tuple(window_notes) + tuple(prepared.notes), settling, ratings)
