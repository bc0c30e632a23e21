"""The paper's reference cases, run with the monolithic solver.

========  ===========================================  ==========================================
case      set-up (paper)                               reported
========  ===========================================  ==========================================
table2    parallel stage, Table 3 data; drive 5 rpm,   mean contact force (paper 9.67e3 N)
          1 kN m on the driven gear
table4    planetary stage, Table 5 data, 3 planets;    sums of the sun-planet and ring-planet
          carrier 5 rpm, 1 kN m on the sun             forces (paper 9.66e3 N each)
sine      Table 5 stage, omega = 5 sin(10 t) rpm,      flank changes through the backlash
          1 N m on the sun, c0 = 50 N s/mm (Fig. 10)   (force sign, time inside the backlash)
table7    Table 6 gearbox + generator, wind defaults,  mean/std of every contact force over
          25.4 kN m, 60 s (Sec. 4.2)                   [5, 60] s; generator vs 100 x rotor speed
========  ===========================================  ==========================================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable

import numpy as np

from .. import units
from ..errors import ParameterError
from ..model.contact import CONTACT_LOSS_THRESHOLD_N
from ..model.drivetrain import Drivetrain
from ..model.presets import table3_parallel, table5_planetary, table6_gearbox
from ..model.signals import CONTACT_FORCE
from ..model.wind import ConstantSpeed, RotorSpeedProcess, SineSpeed, WindParameters
from .results import SimulationResult, window_statistics

if TYPE_CHECKING:
    from .solver import SpeedDriver

#: Table 7 of the paper: mean and std of F_SP1 of stages 1-3 [N] over [5, 60] s.
TABLE7_PAPER = {
    "stage1.F_sp[1]": (9.0067e5, 1.5123e4),
    "stage2.F_sp[1]": (1.1261e5, 1.8893e3),
    "stage3.F_mesh": (3.3786e5, 5.6738e3),
}



@dataclass(frozen=True)
class ReferenceCase:
    """A paper case: drivetrain, driver, duration and analysis window."""

    name: str
    description: str
    build: Callable[[], tuple[Drivetrain, SpeedDriver]]
    t_end_s: float
    window_s: tuple[float, float]
    output_interval_s: float = 1e-3
    paper: dict = field(default_factory=dict)


def _table2():
    return table3_parallel(output_torque_nm=1000.0), ConstantSpeed(units.rpm(5.0))


def _table4():
    return table5_planetary(output_torque_nm=1000.0), ConstantSpeed(units.rpm(5.0))


def _sine():
    return table5_planetary(output_torque_nm=1.0, c0_ns_per_mm2=50.0), SineSpeed(units.rpm(5.0), 10.0)


def _table7():
    return table6_gearbox(), RotorSpeedProcess(WindParameters())


CASES: dict[str, ReferenceCase] = {
    "table2": ReferenceCase(
        "table2", "Parallel stage (Table 3), drive 5 rpm, 1 kN m on the driven gear", _table2, 1.0, (0.5, 1.0),
        paper={"stage1.F_mesh": 9.67e3},
    ),
    "table4": ReferenceCase(
        "table4", "Planetary stage (Table 5), carrier 5 rpm, 1 kN m on the sun", _table4, 1.0, (0.5, 1.0),
        paper={"sum_F_sp": 9.66e3, "sum_F_rp": 9.66e3},
    ),
    "sine": ReferenceCase(
        "sine", "Planetary stage (Table 5), omega = 5 sin(10 t) rpm, 1 N m, c0 = 50 N s/mm (Fig. 10-11)",
        _sine, 2.0, (0.0, 2.0), output_interval_s=2e-4,
    ),
    "table7": ReferenceCase(
        "table7", "Table 6 gearbox + generator, wind defaults, 25.4 kN m, 60 s (Table 7, Fig. 16)",
        _table7, 60.0, (5.0, 60.0), paper={k: {"mean": m, "std": s} for k, (m, s) in TABLE7_PAPER.items()},
    ),
}


def drivetrain_cases(name: str, drivetrain: Drivetrain, rotor_speed_rad_s: float) -> dict[str, ReferenceCase]:
    """The two reference cases of any drivetrain (a drivetrain file's): constant load and wind.

    ``constant``: the rotor turns at ``rotor_speed_rad_s`` and the load (generator counter torque,
    or the output torque without a generator) is constant; 10 s, statistics over [5, 10] s, when
    the start transient has decayed (the means are then the static forces of the design table).
    ``wind``: the paper's stochastic rotor speed (eq. 13-14, defaults of Sec. 4.2) about
    ``rotor_speed_rad_s``; 60 s, statistics over [5, 60] s as for Table 7.
    """
    rpm_text = f"{units.rad_per_s_to_rpm(rotor_speed_rad_s):.6g} rpm"
    return {
        "constant": ReferenceCase(
            "constant", f"{name}: constant rotor speed {rpm_text}, constant load, 10 s",
            lambda: (drivetrain, ConstantSpeed(rotor_speed_rad_s)), 10.0, (5.0, 10.0)),
        "wind": ReferenceCase(
            "wind", f"{name}: stochastic rotor speed about {rpm_text} (eq. 13-14), constant load, 60 s",
            lambda: (drivetrain, RotorSpeedProcess(WindParameters(mean_speed_rad_s=rotor_speed_rad_s))), 60.0,
            (5.0, 60.0)),
    }


def run_case(name: str, **overrides) -> tuple[SimulationResult, dict[str, dict[str, float]]]:
    """Run a reference case with the monolithic solver.

    Parameters
    ----------
    name : {"table2", "table4", "sine", "table7"}
        Case name.
    **overrides
        ``t_end_s`` or ``output_interval_s`` to shorten or refine the run.

    Returns
    -------
    result : SimulationResult
    statistics : dict
        ``{"<variable>": {"mean", "std", "min", "max"}}`` over the case's window,
        for every contact force, ``omega_gen`` (with a generator), the sums of
        planetary forces per stage and derived measures of the case.
    """
    if name not in CASES:
        raise ParameterError("case", name, "one of " + ", ".join(CASES))
    return run_reference_case(CASES[name], **overrides)


def run_reference_case(case: ReferenceCase, **overrides) -> tuple[SimulationResult, dict[str, dict[str, float]]]:
    """Run a :class:`ReferenceCase` with the monolithic solver (see :func:`run_case`)."""
    drivetrain, driver = case.build()
    t_end = overrides.pop("t_end_s", case.t_end_s)
    dt = overrides.pop("output_interval_s", case.output_interval_s)
    if overrides:
        raise ParameterError("overrides", sorted(overrides), "only t_end_s and output_interval_s")
    from .solver import simulate_monolithic  # scipy.integrate: only when a case runs

    result = simulate_monolithic(drivetrain, driver, t_end, output_interval_s=dt, start="rest")  # the paper's load step
    window = (min(case.window_s[0], t_end), min(case.window_s[1], t_end))
    return result, case_statistics(result, drivetrain, window)


def case_statistics(result: SimulationResult, drivetrain: Drivetrain, window: tuple[float, float]) -> dict:
    """Statistics of a paper case (see :func:`run_case`)."""
    t = result.time_s
    forces = result.names_of(CONTACT_FORCE)  # as the solver declares them
    names = forces + [n for n in ("omega_gen", "omega_rotor", "omega_out", "torque_rotor") if n in result.series]
    stats = result.statistics(window, names)
    for st in drivetrain.stages:
        meshes = {kind: [n for n in forces if result.signals[n].detail("stage") == st.name
                         and result.signals[n].detail("mesh") == kind] for kind in ("sun_planet", "ring_planet")}
        if meshes["sun_planet"]:
            stats[f"{st.name}.sum_F_sp"] = window_statistics(t, sum(result[n] for n in meshes["sun_planet"]), window)
            stats[f"{st.name}.sum_F_rp"] = window_statistics(t, sum(result[n] for n in meshes["ring_planet"]), window)
    for n in forces:
        inside = np.abs(result[n]) < CONTACT_LOSS_THRESHOLD_N
        sel = (t >= window[0]) & (t <= window[1])
        stats[n]["backlash_fraction"] = float(inside[sel].mean()) if sel.any() else float("nan")
    if "omega_gen" in result.series:
        ideal = drivetrain.ratio * result["omega_rotor"]
        stats["omega_gen_deviation"] = window_statistics(t, result["omega_gen"] / ideal - 1.0, window)
    return stats
