"""The lateral-torsional model with very stiff bearings is the torsional one: Table 7 within 1e-4 (issue 33.1).

The packaged ``paper-table6-lateral`` (Table 6 with bearings) with every bearing 1e13 N/m and the stage-2
carrier's own inertia 1e-3 kg m^2 (the lateral model needs one; 2e-4 of the planets' orbital inertia, which the
torsional model lumps into the carrier) against the paper's torsional Table 6: the monolithic reference of the
Table 7 case (60 s of the stochastic rotor speed, statistics over [5, 60] s), every contact force. The
difference falls like 1 / k: 2.8e-5 of the std at 1e12 N/m, 3.2e-6 at 1e13 N/m.
"""

from __future__ import annotations

import pytest

from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.results import window_statistics
from components.reference.solver import simulate_monolithic
from orchestrator.inputs.drivetrain_entries import with_entries
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

BEARINGS = {0: ("sun", "carrier", "planet"), 1: ("sun", "carrier", "planet"), 2: ("drive", "driven")}


def stiff_lateral(stiffness_n_per_m: float):
    """paper-table6-lateral with every bearing ``stiffness_n_per_m`` (damping 1e-5 s x it), stage-2 carrier 1e-3 kg m^2."""
    entries = {f"stages[{i}].bearings.{b}.{what}": f"{stiffness_n_per_m * scale} {unit}" for i, names in BEARINGS.items()
               for b in names for what, scale, unit in (("stiffness", 1.0, "N/m"), ("damping", 1e-5, "N.s/m"))}
    entries["stages[1].carrier_inertia"] = "1e-3 kg.m2"
    return with_entries(load_drivetrain_file(find_drivetrain("paper-table6-lateral")), entries).drivetrain


def test_stiff_bearings_reproduce_the_torsional_table7_statistics():
    torsional = load_drivetrain_file(find_drivetrain("paper-table6")).drivetrain
    runs = {name: simulate_monolithic(dt, RotorSpeedProcess(WindParameters()), 60.0)
            for name, dt in (("torsional", torsional), ("lateral", stiff_lateral(1e13)))}
    assert all(r.complete for r in runs.values())
    forces = [k for k in runs["torsional"].series if ".F_" in k]
    assert len(forces) == 13
    for name in forces:
        a, b = (window_statistics(r.time_s, r.series[name], (5.0, 60.0)) for r in (runs["torsional"], runs["lateral"]))
        assert b["mean"] == pytest.approx(a["mean"], rel=1e-4), name
        assert b["std"] == pytest.approx(a["std"], rel=1e-4), name
    # the planet bearings carry the planets' tangential mesh forces, 2 F cos(alpha) (Table 7 means)
    f_sp = window_statistics(runs["lateral"].time_s, runs["lateral"].series["stage1.F_sp[1]"], (5.0, 60.0))["mean"]
    bearing = window_statistics(runs["lateral"].time_s, runs["lateral"].series["stage1.planet_bearing[1].F"],
                                (5.0, 60.0))["mean"]
    assert bearing == pytest.approx(2.0 * f_sp * 0.9396926207859084, rel=1e-6)
