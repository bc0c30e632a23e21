"""Analyses of every co-simulation result: contact loss, fatigue loads, contact-force spectra.

:func:`analyse_run` runs on the recorded time series over the scenario's analysis
window (``simulation.window``) with the scenario's ``[analysis]`` settings
(:class:`~orchestrator.inputs.analysis_settings.AnalysisSettings`) and returns the
``summary.json`` entries and the files it wrote:

* **contact loss** (:mod:`components.analysis.contact_loss`) of every recorded contact force
  (``*.F_*``): separations, flank changes, time inside the backlash (``|F| <
  contact_loss_threshold_n``) -> ``summary["contact_loss"]``, ``contact_loss.csv``;
* **fatigue** (:mod:`components.analysis.fatigue`): rainflow counts and damage-equivalent
  loads of every recorded contact force and shaft torque (``*shaftK.torque``) for the
  Woehler exponents, and the load duration distribution of every shaft torque
  (with the load revolution distribution where the shaft's speed is recorded)
  -> ``summary["fatigue"]``, ``fatigue_del.csv``, ``fatigue_ldd.csv``,
  ``load_duration.png``;
* **spectra** (:mod:`components.analysis.spectrum`) of one contact force per mesh kind and
  stage, with every stage's gear-mesh frequency at the mean rotor speed marked ->
  ``summary["spectrum"]``, ``contact_force_spectra.png``; written when a mesh
  stiffness varies in time (``spectrum = "auto"``), always, or never.

Mesh frequencies, shaft speeds and the stiffness variation come from the
drivetrain rebuilt from the Gearbox FMU's parameters
(:func:`orchestrator.run.comparison.monolithic_setup`); a system without the three
dtcosim FMUs still gets contact loss and fatigue loads of whatever it records
under these names.
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
from components.analysis.spectrum import amplitude_spectrum
from components.errors import DtcosimError
from components.reference.results import is_contact_force, is_shaft_torque

from ..cosim.master import RunOutcome
from ..cosim.system import ResolvedSystem

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
        Analyses skipped and why.
    """

    summary: dict[str, Any] = field(default_factory=dict)
    files: dict[str, Path] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _stage_of(column: str) -> str:
    """Stage of a contact-force column: ``"gearbox.stage1.F_sp[1]"`` -> ``"stage1"``."""
    parts = column.split(".")
    return parts[-2] if len(parts) >= 2 else ""


@dataclass(frozen=True)
class _Drivetrain:
    """What the analyses need from the drivetrain behind the Gearbox FMU."""

    gearbox: str
    wind: str
    generator: str
    mesh_rate: dict[str, float]  # stage -> tooth pairs per rotor radian
    variation: dict[str, float]  # stage -> largest stiffness variation of its meshes
    shaft_speed: dict[str, list[str]]  # shaft torque column -> candidate speed columns
    omega0_rad_s: float


def _drivetrain_info(system: ResolvedSystem) -> _Drivetrain | None:
    from components.model.assembly import Assembly

    from .comparison import GEARBOX, GENERATOR, WIND, ReferenceError, monolithic_setup

    try:
        setup = monolithic_setup(system)
    except ReferenceError:
        return None
    by_role = {role: name for name, role in setup.roles.items()}
    g, gen = by_role[GEARBOX], by_role[GENERATOR]
    a = Assembly(setup.drivetrain)
    rate: dict[str, float] = {}
    variation: dict[str, float] = {}
    for m in a.meshes:
        rate.setdefault(m.stage, abs(m.teeth_per_driver_rad))
        variation[m.stage] = max(variation.get(m.stage, 0.0), m.contact.stiffness_variation)
    speeds = {}
    for sh in a.shafts:
        cands = [f"{g}.{sh.upstream}.omega", f"{g}.{sh.downstream}.omega"]
        if sh.downstream == "generator":
            cands.append(f"{gen}.omega")
        speeds[f"{g}.{sh.name}.torque"] = cands
    return _Drivetrain(g, by_role[WIND], gen, rate, variation, speeds, setup.wind.mean_speed_rad_s)


def _window_of(outcome: RunOutcome, window: tuple[float, float]) -> tuple[float, float] | None:
    """The analysis window clipped to the recorded samples (None: fewer than 2 samples inside)."""
    t = outcome.time_s
    if t.size < 2:
        return None
    w0, w1 = window[0], min(window[1], float(t[-1]))
    inside = np.count_nonzero((t >= w0 - 1e-12) & (t <= w1 + 1e-12))
    return (w0, w1) if w1 > w0 and inside >= 2 else None


def analyse_run(system: ResolvedSystem, outcome: RunOutcome, out_dir: str | Path, plots: bool = True) -> RunAnalyses:
    """Contact loss, fatigue loads and (optionally) force spectra of a run, with their files.

    Parameters
    ----------
    system : ResolvedSystem
        The scenario that ran (window and ``[analysis]`` settings).
    outcome : RunOutcome
        Its recorded samples (an incomplete run is analysed up to where it stopped).
    out_dir : path
        Directory of the CSV and PNG files (exists).
    plots : bool
        Write the PNG files.

    Returns
    -------
    RunAnalyses
    """
    out = Path(out_dir)
    settings = system.scenario.analysis
    result = RunAnalyses()
    window = _window_of(outcome, system.scenario.simulation.window_s)
    if window is None:
        result.notes.append("no analyses: fewer than 2 samples inside the analysis window")
        return result
    if not outcome.complete:
        result.notes.append(f"run incomplete: analyses over [{window[0]:g}, {window[1]:g}] s only")
    t = outcome.time_s
    series = {c.column: outcome.values[:, i] for i, c in enumerate(outcome.columns)}
    forces = [c for c in series if is_contact_force(c)]
    torques = [c for c in series if is_shaft_torque(c)]
    info = _drivetrain_info(system)

    if forces:
        try:
            stats = contact_loss_summary(series, settings.contact_loss_threshold_n, window, forces, time_s=t)
        except DtcosimError as exc:
            result.notes.append(f"no contact-loss count: {exc}")
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
            result.files["contact_loss"] = write_contact_loss_csv(out / CONTACT_LOSS_FILE, stats)

    loads = forces + torques
    if loads:
        speeds = {}
        if info is not None:
            for name in torques:
                speed = next((c for c in info.shaft_speed.get(name, []) if c in series), None)
                if speed is not None:
                    speeds[name] = speed
        try:
            report = fatigue_report(series, settings.fatigue_settings(), window, loads, time_s=t, speeds=speeds)
        except DtcosimError as exc:
            result.notes.append(f"no fatigue loads: {exc}")
        else:
            fat = report.as_dict()
            fat["revolution_speeds"] = speeds
            result.summary["fatigue"] = fat
            result.files["fatigue_del"] = write_del_csv(out / DEL_FILE, report)
            if report.ldd:
                result.files["fatigue_ldd"] = write_ldd_csv(out / LDD_FILE, report)
                if plots:
                    from .analysis_plots import plot_load_duration

                    result.files["plot:load_duration"] = plot_load_duration(list(report.ldd.values()), out / LDD_PLOT)

    if plots and system.events and forces:
        result.files["plot:event_response"] = _plot_events(system, outcome, series, forces, torques, info, out / EVENT_PLOT)

    want = settings.spectrum == "always" or (
        settings.spectrum == "auto" and info is not None and any(v > 0.0 for v in info.variation.values()))
    if want and forces:
        spectrum = _spectrum(series, t, window, forces, info)
        if spectrum is not None:
            summary, chosen, marks, fmax = spectrum
            result.summary["spectrum"] = summary
            if plots:
                from .analysis_plots import plot_force_spectra

                result.files["plot:contact_force_spectra"] = plot_force_spectra(
                    t, {n: series[n] for n in chosen}, out / SPECTRUM_PLOT, marks, window, fmax)
                summary["file"] = SPECTRUM_PLOT
        else:
            result.notes.append("no spectrum: the samples are not uniformly spaced")
    return result


def _first_per_stage(forces: list[str]) -> list[str]:
    """One force per stage: the first listed (``F_sp[1]`` of a planetary stage, ``F_mesh`` of a parallel one)."""
    seen: set[str] = set()
    out = []
    for n in forces:
        stage = _stage_of(n)
        if stage not in seen:
            seen.add(stage)
            out.append(n)
    return out


def _plot_events(system: ResolvedSystem, outcome: RunOutcome, series, forces, torques, info: _Drivetrain | None,
                 path: Path) -> Path:
    from .analysis_plots import plot_event_response

    shown: dict[str, np.ndarray] = {}
    if info is not None and f"{info.generator}.generator_torque" in series:
        shown["generator counter torque"] = series[f"{info.generator}.generator_torque"]
    if torques:
        shown[torques[-1]] = series[torques[-1]]  # the output shaft (drives the generator)
    events = [(f"{a.event.kind} ({a.component})", a.event.start_s, a.event.end_s) for a in system.events]
    return plot_event_response(outcome.time_s, shown, {n: series[n] for n in _first_per_stage(forces)}, events, path,
                               system.scenario.analysis.contact_loss_threshold_n)


def _spectrum(series, t, window, forces, info: _Drivetrain | None):
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
    for n in forces:
        stage = _stage_of(n)
        kind = n.rsplit(".", 1)[-1].split("[", 1)[0]
        if (stage, kind) not in kinds:
            kinds.add((stage, kind))
            chosen.append(n)
    mesh_hz: dict[str, float] = {}
    speed = None
    if info is not None:
        wind_col = f"{info.wind}.omega"
        speed = float(np.mean(series[wind_col][sel])) if wind_col in series else info.omega0_rad_s
        mesh_hz = {stage: rate * abs(speed) / (2.0 * math.pi) for stage, rate in info.mesh_rate.items()}
    per_force = {}
    for n in chosen:
        f, amp = amplitude_spectrum(series[n][sel], h)
        df = f[1] - f[0]
        stage = _stage_of(n)
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
        "stiffness_variation": {} if info is None else dict(info.variation),
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
            lines.append(head + f"{len(lost)} of {len(cl['meshes'])} meshes separate, {cl['total_separations']} "
                         f"separations, {cl['total_flank_changes']} flank changes")
            for name, m in cl["meshes"].items():
                if m["separations"] or m["time_in_backlash_s"] > 0:
                    lines.append(f"  {name:<32}{m['separations']:>3} separations {m['flank_changes']:>3} flank changes "
                                 f"{1e3 * m['time_in_backlash_s']:9.2f} ms inside the backlash "
                                 f"(longest {1e3 * m['longest_episode_s']:.2f} ms)")
    fat = summary.get("fatigue")
    if fat:
        exps = [f"m={m:g}" for m in fat["wohler_exponents"]]
        shafts = {n: d for n, d in fat["del"].items() if is_shaft_torque(n)}
        if shafts:
            lines.append(f"damage-equivalent loads (N_ref = {fat['reference_frequency_hz'] or 0:g} Hz x T) [N m]: "
                         + ", ".join(exps))
            for n, d in shafts.items():
                lines.append(f"  {n:<32}" + "".join(f"{d['del'][e]:14.6g}" for e in exps))
    return "\n".join(lines)
