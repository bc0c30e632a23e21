"""Monolithic reference of a co-simulation scenario and the co-simulation-vs-monolithic report.

The reference is :func:`components.reference.solver.simulate_monolithic` (one stiff ODE,
LSODA, analytic Jacobian) on the *same* system: the drivetrain is rebuilt from the
scenario's effective Gearbox FMU parameter values with
:func:`components.model.parameter_map.unflatten` (template: the
:func:`~components.model.presets.cosim_preset` whose flat parameter names the FMU
has), the rotor-speed process from the WindSource parameters (same seed, same
harmonics), the generator from the GeneratorRotor parameters (inertia, counter
torque, load events).

Components are recognised by their FMU's model name (``WindSource``,
``Gearbox``, ``GeneratorRotor``), not by their instance names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from components.errors import DtcosimError, ParameterError
from components.reference.results import SimulationResult, window_statistics

from ..cosim.master import RunOutcome
from ..cosim.system import ResolvedSystem

WIND, GEARBOX, GENERATOR = "WindSource", "Gearbox", "GeneratorRotor"
STATISTICS = ("mean", "std", "min", "max")


class ReferenceError(DtcosimError, ValueError):
    """The scenario cannot be expressed as a monolithic reference (names the reason)."""


@dataclass(frozen=True)
class MonolithicSetup:
    """Inputs of the monolithic reference rebuilt from a scenario.

    Attributes
    ----------
    drivetrain : components.model.drivetrain.Drivetrain
    wind : components.model.wind.WindParameters
    roles : dict of str -> str
        Component name -> role (``WindSource``, ``Gearbox``, ``GeneratorRotor``).
    preset : str
        Template preset the gearbox parameters were mapped onto.
    notes : list of str
        Differences between the two set-ups that the reference cannot represent.
    """

    drivetrain: Any
    wind: Any
    roles: dict[str, str]
    preset: str
    notes: list[str]


def component_roles(system: ResolvedSystem) -> dict[str, str]:
    """Component name -> role, from each FMU's model name; exactly one of each role is required."""
    roles = {}
    for name, iface in system.interfaces.items():
        if iface.model_name in (WIND, GEARBOX, GENERATOR):
            roles[name] = iface.model_name
    for role in (WIND, GEARBOX, GENERATOR):
        found = [n for n, r in roles.items() if r == role]
        if len(found) != 1:
            raise ReferenceError(
                f"the monolithic reference needs exactly one {role} FMU in the scenario; found {len(found)}"
                + (f" ({', '.join(found)})" if found else "")
            )
    return roles


def monolithic_setup(system: ResolvedSystem) -> MonolithicSetup:
    """Rebuild drivetrain and rotor-speed process from the scenario's effective FMU parameters.

    Raises
    ------
    ReferenceError
        If the scenario lacks one of the three FMUs or uses parameters the
        monolithic model cannot represent.
    """
    from components.model.generator import EVENT_KINDS, GeneratorParameters, LoadEvent
    from components.model.parameter_map import flatten, unflatten
    from components.model.presets import PRESETS, cosim_preset
    from components.model.wind import AMPLITUDE_CONVENTIONS, WindParameters

    roles = component_roles(system)
    by_role = {r: n for n, r in roles.items()}
    notes: list[str] = []

    w = system.parameter_values(by_role[WIND])
    amp = w.get("amplitude", 0)
    amplitude = AMPLITUDE_CONVENTIONS[int(amp)] if isinstance(amp, (int, float)) else str(amp)
    try:
        wind = WindParameters(
            mean_speed_rad_s=float(w["omega0"]), spectrum_level=float(w["a"]), sigma_rad_s=float(w["sigma"]),
            n_harmonics=int(w["n_harmonics"]), f_min_rad_s=float(w["f_min"]), f_max_rad_s=float(w["f_max"]),
            seed=int(w["seed"]), amplitude=amplitude,
        )
    except KeyError as exc:
        raise ReferenceError(f"WindSource FMU has no parameter {exc.args[0]!r}") from None

    gear_values = system.parameter_values(by_role[GEARBOX])
    gen_keys = ("generator.inertia", "generator.counter_torque")
    template = None
    preset_name = ""
    # the FMU's drivetrain parameters (stageN.*, shaftN.*), not its solver options (solver.*, shaft_torque_mode, ...)
    structural = {k for k in gear_values if "." in k and k.split(".")[0].startswith(("stage", "shaft"))}
    for name in PRESETS:
        candidate = cosim_preset(name)
        if set(flatten(candidate)) - set(gen_keys) == structural:
            template, preset_name = candidate, name
            break
    if template is None:
        raise ReferenceError(
            "the Gearbox FMU's parameters match no drivetrain preset of components.model.parameter_map "
            f"(presets tried: {', '.join(PRESETS)})"
        )
    keys = set(flatten(template)) - set(gen_keys)
    g = system.parameter_values(by_role[GENERATOR])
    try:
        events = []
        i = 1
        while f"event{i}.kind" in g:
            code = int(g[f"event{i}.kind"])
            if code:
                events.append(LoadEvent(kind=EVENT_KINDS[code - 1], start_s=float(g[f"event{i}.start"]),
                                        duration_s=float(g[f"event{i}.duration"]), factor=float(g[f"event{i}.factor"])))
            i += 1
        values = {k: gear_values[k] for k in keys}
        values["generator.inertia"] = float(g["inertia"])
        values["generator.counter_torque"] = float(g["counter_torque"])
    except KeyError as exc:
        raise ReferenceError(f"GeneratorRotor FMU has no parameter {exc.args[0]!r}") from None
    except (ParameterError, IndexError) as exc:
        raise ReferenceError(f"generator load events not representable in the reference model: {exc}") from None
    try:
        drivetrain = unflatten(template, values)
    except ParameterError as exc:
        raise ReferenceError(f"gearbox/generator parameters rejected by the reference model: {exc}") from None
    if events:
        from dataclasses import replace

        drivetrain = replace(drivetrain, generator=GeneratorParameters(
            inertia_kgm2=drivetrain.generator.inertia_kgm2,
            counter_torque_nm=drivetrain.generator.counter_torque_nm,
            events=tuple(events),
        ))
    bound = {str(b.target) for b in system.scenario.initial}
    gen_name = by_role[GENERATOR]
    if f"{gen_name}.initial_speed" not in bound:
        notes.append("the generator's initial speed is not bound to the gearbox output speed; the reference starts "
                     "kinematically consistent")
    return MonolithicSetup(drivetrain, wind, roles, preset_name, notes)


def reference_name(column: str, roles: Mapping[str, str], series: Mapping[str, np.ndarray],
                   last_shaft: str) -> str | None:
    """Name in the monolithic result of a co-simulation column ``component.variable`` (None: no counterpart)."""
    comp, _, var = column.partition(".")
    role = roles.get(comp)
    if role == WIND:
        name = {"omega": "omega_rotor", "phi": "phi_rotor"}.get(var)
    elif role == GENERATOR:
        name = {"omega": "omega_gen", "phi": "phi_gen", "generator_torque": "load_torque"}.get(var)
    elif role == GEARBOX:
        name = f"{last_shaft}.torque" if var in ("shaft_torque", "shaft_torque_end", "shaft_torque_avg") else var
    else:
        name = None
    return name if name in series else None


def run_reference(system: ResolvedSystem, setup: MonolithicSetup | None = None) -> SimulationResult:
    """The monolithic solution on the scenario's time grid (start, stop, output interval)."""
    from components.model.wind import RotorSpeedProcess
    from components.reference.solver import simulate_monolithic

    setup = setup or monolithic_setup(system)
    sim = system.scenario.simulation
    return simulate_monolithic(
        setup.drivetrain, RotorSpeedProcess(setup.wind), sim.stop_s,
        output_interval_s=sim.output_interval_s, t_start_s=sim.start_s,
    )


def _rel(a: float, b: float, scale: float) -> float:
    return float((a - b) / scale) if scale > 0 else (0.0 if a == b else math.inf)


def compare(outcome: RunOutcome, reference: SimulationResult, system: ResolvedSystem,
            setup: MonolithicSetup) -> dict[str, Any]:
    """Every statistic, co-simulation vs monolithic, over the scenario's analysis window.

    Returns
    -------
    dict
        ``{"variables": {column: {"reference": name, "cosim": {stat}, "monolithic": {stat},
        "relative_difference": {stat}, "rms_difference": float, "rms_relative_to_std": float}},
        "notes": [...]}``. Relative differences of mean, min and max are relative to
        the monolithic mean's magnitude, the std's to the monolithic std;
        ``rms_difference`` is the RMS of the pointwise difference on the common time
        grid within the window.
    """
    window = system.scenario.simulation.window_s
    last_shaft = setup.drivetrain.output_shaft.name if setup.drivetrain.output_shaft is not None else "shaft3"
    t_co = outcome.time_s
    t_ref = reference.time_s
    n = min(t_co.size, t_ref.size)
    same_grid = n > 0 and np.allclose(t_co[:n], t_ref[:n], rtol=0, atol=1e-9)
    sel = (t_co[:n] >= window[0] - 1e-12) & (t_co[:n] <= window[1] + 1e-12)
    result: dict[str, Any] = {}
    for i, col in enumerate(outcome.columns):
        ref_name = reference_name(col.column, setup.roles, reference.series, last_shaft)
        if ref_name is None:
            continue
        co = outcome.values[:, i]
        ref = reference.series[ref_name]
        s_co = window_statistics(t_co, co, window)
        s_ref = window_statistics(t_ref, ref, window)
        scale_mean = abs(s_ref["mean"])
        rel = {
            "mean": _rel(s_co["mean"], s_ref["mean"], scale_mean),
            "std": _rel(s_co["std"], s_ref["std"], s_ref["std"]),
            "min": _rel(s_co["min"], s_ref["min"], scale_mean),
            "max": _rel(s_co["max"], s_ref["max"], scale_mean),
        }
        entry = {"reference": ref_name, "cosim": s_co, "monolithic": s_ref, "relative_difference": rel}
        if same_grid and sel.any():
            d = co[:n][sel] - ref[:n][sel]
            rms = float(np.sqrt(np.mean(d * d)))
            entry["rms_difference"] = rms
            entry["rms_relative_to_std"] = rms / s_ref["std"] if s_ref["std"] > 0 else math.inf
        result[col.column] = entry
    return {
        "reference": "monolithic LSODA (components.reference.solver.simulate_monolithic)",
        "preset": setup.preset,
        "window_s": list(window),
        "reference_complete": bool(reference.complete),
        "reference_wall_time_s": float(reference.wall_time_s),
        "notes": list(setup.notes),
        "variables": result,
    }


def format_comparison(report: Mapping[str, Any]) -> str:
    """A plain-text table of :func:`compare`'s report."""
    w0, w1 = report["window_s"]
    lines = [f"co-simulation vs monolithic reference over [{w0:g}, {w1:g}] s (relative differences; mean/min/max "
             "relative to |monolithic mean|, std to monolithic std)"]
    head = f"{'variable':<30}{'mean co-sim':>14}{'mean mono':>14}{'d mean':>10}{'std co-sim':>13}{'std mono':>13}{'d std':>9}{'d min':>9}{'d max':>9}{'rms/std':>9}"
    lines.append(head)
    for name, e in report["variables"].items():
        c, m, r = e["cosim"], e["monolithic"], e["relative_difference"]
        lines.append(
            f"{name:<30}{c['mean']:14.6g}{m['mean']:14.6g}{r['mean']:10.2e}{c['std']:13.5g}{m['std']:13.5g}"
            f"{r['std']:9.2e}{r['min']:9.1e}{r['max']:9.1e}{e.get('rms_relative_to_std', float('nan')):9.2e}"
        )
    for note in report.get("notes", []):
        lines.append(f"note: {note}")
    return "\n".join(lines)
