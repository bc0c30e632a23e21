"""Analyses of every co-simulation result: contact loss, fatigue loads, contact-force spectra.

:func:`analyse_run` runs on the recorded time series over the scenario's analysis
window (``simulation.window``) with the scenario's ``[analysis]`` settings
(:class:`~orchestrator.inputs.analysis_settings.AnalysisSettings`) and returns the
``summary.json`` entries and the files it wrote. Which series an analysis uses is
decided by the signals the components declare (:mod:`orchestrator.cosim.roles`),
never by a variable's name:

* **contact loss** (:mod:`components.analysis.contact_loss`) of every recorded
  ``contact_force`` of a gearbox: separations, flank changes, time inside the
  backlash (``|F| < contact_loss_threshold_n``) -> ``summary["contact_loss"]``,
  ``contact_loss.csv``;
* **fatigue** (:mod:`components.analysis.fatigue`): rainflow counts and
  damage-equivalent loads of every recorded contact force and ``shaft_torque``
  for the Woehler exponents, and the load duration distribution of every shaft
  torque (with the load revolution distribution where a speed of the shaft's
  bodies is recorded) -> ``summary["fatigue"]``, ``fatigue_del.csv``,
  ``fatigue_ldd.csv``, ``load_duration.png``;
* **spectra** (:mod:`components.analysis.spectrum`) of one contact force per mesh kind and
  stage, with every stage's gear-mesh frequency at the mean rotor speed marked ->
  ``summary["spectrum"]``, ``contact_force_spectra.png``; written when a mesh
  stiffness varies in time (``spectrum = "auto"``), always, or never;
* the **event response** plot with load events;
* **load sharing** (:mod:`components.analysis.load_sharing`) of every planetary stage whose
  planets' sun-planet ``contact_force`` are all recorded (declared ``stage``, ``mesh`` and
  ``planet``): the load-sharing factor over the window -> ``summary["load_sharing"]``.

Mesh frequencies, shaft speeds and the stiffness variation come from the Gearbox
FMU's record (:func:`orchestrator.cosim.physics_view.gearbox_drivetrain`). An
analysis that cannot run (no gearbox, nothing declared, nothing recorded, no
record) is listed in :attr:`RunAnalyses.skipped` with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from components.analysis.contact_loss import (
    contact_loss_summary,
    write_contact_loss_csv,
)
from components.analysis.fatigue import fatigue_report, write_del_csv, write_ldd_csv
from components.analysis.load_sharing import load_sharing
from components.analysis.spectrum import amplitude_spectrum
from components.errors import DtcosimError

from ..atomic_files import atomic_path
from ..cosim.outcome import RunOutcome
from ..cosim.physics_view import PhysicsUnavailable, gearbox_drivetrain, wind_parameters
from ..cosim.roles import GEARBOX, GENERATOR, WIND_SOURCE
from ..cosim.resolved import ResolvedSystem
from .text_tables import fit_table, number


def _atomic(write, path: Path, *args) -> Path:
    """``write(path, *args)`` through a temporary file and rename (the file is whole or not there)."""
    with atomic_path(path) as tmp:
        write(tmp, *args)
    return path


CONTACT_LOSS_FILE = "contact_loss.csv"
DEL_FILE = "fatigue_del.csv"
LDD_FILE = "fatigue_ldd.csv"
LDD_PLOT = "load_duration.png"
SPECTRUM_PLOT = "contact_force_spectra.png"
EVENT_PLOT = "event_response.png"


@dataclass
class RunAnalyses:
    """What :func:`analyse_run` produced.

    Attributes
    ----------
    summary : dict
        ``summary.json`` entries: ``contact_loss``, ``fatigue``, optionally ``spectrum``.
    files : dict of str -> pathlib.Path
        Written files by role (``contact_loss``, ``fatigue_del``, ``fatigue_ldd``,
        ``plot:load_duration``, ``plot:contact_force_spectra``, ``plot:event_response``).
    notes : list of str
        Limits of the analyses that ran (an incomplete run, ...).
    skipped : list of dict
        ``{"analysis": name, "reason": text}`` for each analysis that did not run.
    """

    summary: dict[str, Any] = field(default_factory=dict)
    files: dict[str, Path] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    skipped: list[dict[str, str]] = field(default_factory=list)

    def skip(self, analysis: str, reason: str) -> None:
        """Record that ``analysis`` did not run and why."""
        self.skipped.append({"analysis": analysis, "reason": reason})


@dataclass(frozen=True)
class _Signals:
    """The declared drivetrain signals a run recorded."""

    forces: list[str]  # contact-force columns of the gearboxes
    torques: list[str]  # shaft-torque columns
    stage: dict[str, str]  # contact-force column -> stage
    mesh: dict[str, str]  # contact-force column -> mesh kind (sun_planet, ring_planet, parallel)
    shaft_speed: dict[str, list[str]]  # shaft-torque column -> recorded speed columns of its bodies
    planets: dict[str, dict[int, str | None]]  # planetary stage -> planet -> its sun-planet force column (None: not
    # recorded)


def _recorded_signals(system: ResolvedSystem, series: dict[str, np.ndarray]) -> _Signals:
    forces, torques, stage, mesh, speeds = [], [], {}, {}, {}
    planets: dict[str, dict[int, str | None]] = {}
    generator_speed = [r.column("generator_speed") for r in system.with_role(GENERATOR)]
    for role in system.with_role(GEARBOX):
        body_speed = {s.info.get("body"): f"{role.component}.{s.variable}" for s in role.of_kind("body_speed")}
        for s in role.of_kind("contact_force"):
            col = f"{role.component}.{s.variable}"
            if s.info.get("mesh") == "sun_planet" and str(s.info.get("planet", "")).isdigit():
                key = f"{role.component}.{s.info.get('stage', '')}"
                planets.setdefault(key, {})[int(s.info["planet"])] = col if col in series else None
            if col in series:
                forces.append(col)
                stage[col] = s.info.get("stage", role.component)
                mesh[col] = s.info.get("mesh", "mesh")
        for s in role.of_kind("shaft_torque"):
            col = f"{role.component}.{s.variable}"
            if col not in series:
                continue
            torques.append(col)
            cands = [body_speed.get(s.info.get("upstream")), body_speed.get(s.info.get("downstream"))]
            if s.info.get("downstream") == "generator":
                cands += generator_speed
            speeds[col] = [c for c in cands if c is not None and c in series]
    return _Signals(forces, torques, stage, mesh, speeds, planets)


@dataclass(frozen=True)
class _Drivetrain:
    """What the spectra need from the drivetrain of the Gearbox FMU's record."""

    mesh_rate: dict[str, float]  # stage -> tooth pairs per rotor radian
    variation: dict[str, float]  # stage -> largest stiffness variation of its meshes
    rotor_speed_column: str | None  # the declared, recorded rotor speed
    omega0_rad_s: float | None  # the wind source's mean speed (its record), if known


def _drivetrain_info(system: ResolvedSystem, series: dict[str, np.ndarray]) -> _Drivetrain:
    """Mesh rates and stiffness variation of the one dtcosim gearbox (PhysicsUnavailable otherwise)."""
    from components.model.assembly import Assembly

    gearboxes = [r for r in system.with_role(GEARBOX) if r.record is not None]
    if len(gearboxes) != 1:
        raise PhysicsUnavailable(f"needs exactly one dtcosim Gearbox FMU (with a record of its drivetrain), "
                                 f"the scenario has {len(gearboxes)}")
    a = Assembly(gearbox_drivetrain(system, gearboxes[0].component))
    rate: dict[str, float] = {}
    variation: dict[str, float] = {}
    for m in a.meshes:
        rate.setdefault(m.stage, abs(m.teeth_per_driver_rad))
        variation[m.stage] = max(variation.get(m.stage, 0.0), m.contact.stiffness_variation)
    winds = system.with_role(WIND_SOURCE)
    column = winds[0].column("rotor_speed") if len(winds) == 1 else None
    omega0 = None
    if len(winds) == 1 and winds[0].record is not None:
        omega0 = wind_parameters(system, winds[0].component).mean_speed_rad_s
    return _Drivetrain(rate, variation, column if column in series else None, omega0)


def _window_of(outcome: RunOutcome, window: tuple[float, float]) -> tuple[float, float] | None:
    """The analysis window clipped to the recorded samples (None: fewer than 2 samples inside)."""
    t = outcome.time_s
    if t.size < 2:
        return None
    w0, w1 = window[0], min(window[1], float(t[-1]))
    inside = np.count_nonzero((t >= w0 - 1e-12) & (t <= w1 + 1e-12))
    return (w0, w1) if w1 > w0 and inside >= 2 else None


_NO_FORCES = "no contact force of a gearbox is declared and recorded (dtcosim Gearbox FMU, or role and signals)"


def analyse_run(system: ResolvedSystem, outcome: RunOutcome, out_dir: str | Path, plots: bool = True,
                into: RunAnalyses | None = None) -> RunAnalyses:
    """Contact loss, fatigue loads and (optionally) force spectra of a run, with their files.

    Parameters
    ----------
    system : ResolvedSystem
        The scenario that ran (window, ``[analysis]`` settings, declared roles).
    outcome : RunOutcome
        Its recorded samples (an incomplete run is analysed up to where it stopped).
    out_dir : path
        Directory of the CSV and PNG files (exists).
    plots : bool
        Write the PNG files.
    into : RunAnalyses, optional
        Filled as the analyses go (default: a new one): when a file cannot be written (a full
        disk raises ``OSError``) the caller still has what was computed and written before.

    Returns
    -------
    RunAnalyses
    """
    out = Path(out_dir)
    settings = system.scenario.analysis
    result = RunAnalyses() if into is None else into
    window = _window_of(outcome, system.scenario.simulation.window_s)
    if window is None:
        for name in ("contact_loss", "fatigue", "spectrum"):
            result.skip(name, "fewer than 2 samples inside the analysis window")
        return result
    if not outcome.complete:
        result.notes.append(f"run incomplete: analyses over [{window[0]:g}, {window[1]:g}] s only")
    t = outcome.time_s
    series = {c.column: outcome.values[:, i] for i, c in enumerate(outcome.columns)}
    sig = _recorded_signals(system, series)
    forces, torques = sig.forces, sig.torques
    try:
        info: _Drivetrain | None = _drivetrain_info(system, series)
        no_info = ""
    except PhysicsUnavailable as exc:
        info, no_info = None, str(exc)

    if not forces:
        result.skip("contact_loss", _NO_FORCES)
    else:
        try:
            stats = contact_loss_summary(series, settings.contact_loss_threshold_n, window, forces, time_s=t)
        except DtcosimError as exc:
            result.skip("contact_loss", str(exc))
        else:
            meshes = {n: {k: v for k, v in s.as_dict().items() if k not in ("name", "threshold_n", "analysed_time_s")}
                      for n, s in stats.items()}
            result.summary["contact_loss"] = {
                "definition": "inside the backlash while |F| < threshold (F linear between samples); separation = "
                              "contact -> no contact; flank change = contact resumes on the other flank",
                "threshold_n": settings.contact_loss_threshold_n,
                "window_s": list(window),
                "analysed_time_s": window[1] - window[0],
                "total_separations": int(sum(s.separations for s in stats.values())),
                "total_flank_changes": int(sum(s.flank_changes for s in stats.values())),
                "meshes_with_contact_loss": [n for n, s in stats.items() if s.separations > 0],
                "meshes": meshes,
            }
            result.files["contact_loss"] = _atomic(write_contact_loss_csv, out / CONTACT_LOSS_FILE, stats)

    loads = forces + torques
    if not loads:
        result.skip("fatigue", "no contact force or shaft torque of a gearbox is declared and recorded")
    else:
        speeds = {name: cands[0] for name, cands in sig.shaft_speed.items() if cands}
        try:
            units = {c.column: c.unit for c in outcome.columns}  # as the FMUs' model descriptions declare them
            report = fatigue_report(series, settings.fatigue_settings(), window, loads, time_s=t, speeds=speeds,
                                    torques=torques, units=units)
        except DtcosimError as exc:
            result.skip("fatigue", str(exc))
        else:
            fat = report.as_dict()
            fat["revolution_speeds"] = speeds
            fat["shaft_torques"] = list(torques)
            result.summary["fatigue"] = fat
            result.files["fatigue_del"] = _atomic(write_del_csv, out / DEL_FILE, report)
            if report.ldd:
                result.files["fatigue_ldd"] = _atomic(write_ldd_csv, out / LDD_FILE, report)
                if plots:
                    from .analysis_plots import plot_load_duration

                    result.files["plot:load_duration"] = plot_load_duration(list(report.ldd.values()), out / LDD_PLOT)

    _load_sharing(result, series, t, window, sig)

    if system.events and plots:
        if forces:
            result.files["plot:event_response"] = _plot_events(system, outcome, series, sig, out / EVENT_PLOT)
        else:
            result.skip("event_response", _NO_FORCES)

    if settings.spectrum != "never":
        if info is None:
            if settings.spectrum == "always":
                result.skip("spectrum", f"mesh frequencies unknown: {no_info}")
        elif settings.spectrum == "always" or any(v > 0.0 for v in info.variation.values()):
            if not forces:
                result.skip("spectrum", _NO_FORCES)
            else:
                spectrum = _spectrum(series, t, window, sig, info)
                if spectrum is None:
                    result.skip("spectrum", "the samples are not uniformly spaced")
                else:
                    summary, chosen, marks, fmax = spectrum
                    result.summary["spectrum"] = summary
                    if plots:
                        from .analysis_plots import plot_force_spectra

                        result.files["plot:contact_force_spectra"] = plot_force_spectra(
                            t, {n: series[n] for n in chosen}, out / SPECTRUM_PLOT, marks, window, fmax)
                        summary["file"] = SPECTRUM_PLOT
    return result


def _load_sharing(result: RunAnalyses, series, t, window, sig: _Signals) -> None:
    """``summary["load_sharing"]``: the load-sharing factor of every planetary stage with every planet recorded."""
    if not sig.planets:
        result.skip("load_sharing", "no planetary stage's sun-planet contact forces are declared")
        return
    inside = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    out, missing = {}, []
    for stage, planets in sig.planets.items():
        columns = [planets[i] for i in sorted(planets)]
        if len(columns) < 2 or any(c is None for c in columns):
            missing.append(stage)
            continue
        try:
            out[stage] = load_sharing(stage, np.column_stack([series[c][inside] for c in columns]),
                                      tuple(columns)).as_dict()
        except DtcosimError as exc:
            missing.append(f"{stage} ({exc})")
    if out:
        result.summary["load_sharing"] = {"window_s": list(window), "stages": out}
    if missing:
        result.skip("load_sharing", "not every planet's sun-planet force recorded (or no load) for: "
                    + ", ".join(missing))


def _first_per_stage(sig: _Signals) -> list[str]:
    """One force per stage: the first declared (``F_sp[1]`` of a planetary stage, ``F_mesh`` of a parallel one)."""
    seen: set[str] = set()
    out = []
    for n in sig.forces:
        if sig.stage[n] not in seen:
            seen.add(sig.stage[n])
            out.append(n)
    return out


def _plot_events(system: ResolvedSystem, outcome: RunOutcome, series, sig: _Signals, path: Path) -> Path:
    from .analysis_plots import plot_event_response

    shown: dict[str, np.ndarray] = {}
    for gen in system.with_role(GENERATOR):
        col = gen.column("generator_torque")
        if col in series:
            shown["generator counter torque"] = series[col]
    if sig.torques:
        shown[sig.torques[-1]] = series[sig.torques[-1]]  # the output shaft (drives the generator)
    events = [(f"{a.event.kind} ({a.component})", a.event.start_s, a.event.end_s) for a in system.events]
    return plot_event_response(outcome.time_s, shown, {n: series[n] for n in _first_per_stage(sig)}, events, path,
                               system.scenario.analysis.contact_loss_threshold_n)


def _spectrum(series, t, window, sig: _Signals, info: _Drivetrain):
    """Spectrum summary, the forces to plot, the mesh-frequency marks and the plot's upper frequency."""
    sel = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    tw = t[sel]
    dt = np.diff(tw)
    if tw.size < 8 or np.ptp(dt) > 1e-6 * dt.mean():
        return None
    h = float(dt.mean())
    nyquist = 0.5 / h
    # one force per stage and mesh kind: the first planet's sun and ring mesh, the parallel mesh
    chosen: list[str] = []
    kinds: set[tuple[str, str]] = set()
    for n in sig.forces:
        stage, kind = sig.stage[n], sig.mesh[n]
        if (stage, kind) not in kinds:
            kinds.add((stage, kind))
            chosen.append(n)
    mesh_hz: dict[str, float] = {}
    col = info.rotor_speed_column
    speed = float(np.mean(series[col][sel])) if col is not None else info.omega0_rad_s
    if speed is not None:
        mesh_hz = {stage: rate * abs(speed) / (2.0 * math.pi) for stage, rate in info.mesh_rate.items()}
    per_force = {}
    for n in chosen:
        f, amp = amplitude_spectrum(series[n][sel], h)
        df = f[1] - f[0]
        stage = sig.stage[n]
        fm = mesh_hz.get(stage)
        if fm is None or fm >= nyquist:
            continue
        near = np.abs(f - fm) <= df  # the bins next to f_mesh (scalloping)
        band = np.abs(f - fm) <= max(0.05 * fm, df)
        k = int(np.flatnonzero(band)[np.argmax(amp[band])])
        per_force[n] = {
            "stage": stage,
            "mesh_frequency_hz": fm,
            "amplitude_at_mesh_frequency_n": float(amp[near].max()),
            "peak_within_5_percent_hz": float(f[k]),
            "peak_within_5_percent_amplitude_n": float(amp[k]),
        }
    marks = {f"{stage} mesh": fm for stage, fm in mesh_hz.items() if fm < nyquist}
    top = max(marks.values(), default=0.0)
    fmax = min(nyquist, 2.2 * top) if top > 0 else nyquist  # up to the second mesh harmonic
    summary = {
        "window_s": list(window),
        "sample_interval_s": h,
        "resolution_hz": 1.0 / (tw.size * h),  # FFT bin width
        "nyquist_hz": nyquist,
        "rotor_speed_rad_s": speed,
        "mesh_frequency_hz": mesh_hz,
        "stiffness_variation": dict(info.variation),
        "forces": per_force,
    }
    return summary, chosen, marks, fmax


def format_analyses(summary: dict[str, Any]) -> str:
    """A few lines for the terminal: load events, contact loss per mesh, DELs of the shaft torques."""
    lines = []
    for ev in summary.get("events", []):
        dur = "permanent" if ev["duration_s"] is None else f"{ev['duration_s']:g} s"
        factor = "" if ev["factor"] is None else f", factor {ev['factor']:g}"
        lines.append(f"load event: {ev['kind']} at {ev['start_s']:g} s for {dur}{factor} ({ev['component']}, slot {ev['slot']})")
    cl = summary.get("contact_loss")
    if cl:
        w0, w1 = cl["window_s"]
        head = f"contact loss over [{w0:g}, {w1:g}] s (|F| < {cl['threshold_n']:g} N): "
        lost = cl["meshes_with_contact_loss"]
        if not lost and not any(m["time_in_backlash_s"] > 0 for m in cl["meshes"].values()):
            lines.append(head + f"none ({len(cl['meshes'])} meshes)")
        else:
            lines.append(head.rstrip())
            lines.append(f"  {len(lost)} of {len(cl['meshes'])} meshes separate, {cl['total_separations']} "
                         f"separations, {cl['total_flank_changes']} flank changes (times in ms)")
            rows = [[name, str(m["separations"]), str(m["flank_changes"]), f"{1e3 * m['time_in_backlash_s']:.2f}",
                     f"{1e3 * m['longest_episode_s']:.2f}"]
                    for name, m in cl["meshes"].items() if m["separations"] or m["time_in_backlash_s"] > 0]
            lines += fit_table(["mesh", "separations", "flank changes", "in backlash", "longest"], rows)
    sharing = summary.get("load_sharing")
    if sharing:
        lines.append("planet load sharing (largest planet sun-mesh force / mean, max over the window):")
        lines += [f"  {stage.partition('.')[2] or stage} {s['factor']:.4f} (planet {s['most_loaded_planet']})"
                  for stage, s in sharing["stages"].items()]
    fat = summary.get("fatigue")
    if fat:
        exps = [f"m={m:g}" for m in fat["wohler_exponents"]]
        shafts = {n: d for n, d in fat["del"].items() if n in fat.get("shaft_torques", ())}
        if shafts:
            lines.append(f"damage-equivalent loads (N_ref = {fat['reference_frequency_hz'] or 0:g} Hz x T) [N m]: "
                         + ", ".join(exps))
            lines += fit_table(["shaft", *exps], [[n, *(number(d["del"][e], ".6g") for e in exps)]
                                                  for n, d in shafts.items()])
    return "\n".join(lines)
