"""Planet load sharing against the size of a pin position error: models, hand estimate, and a co-simulated point.

A tangential pin position error ``e`` (0-100 um) of stage-1 planet 1 of the paper's Table 6 gearbox at the
rated point (16 rpm, 25.4 kN m), load-sharing factor ``K = max_i F_sp,i / mean_i F_sp,i`` of stage 1 from the
static equilibrium (:meth:`components.model.assembly.Assembly.static_deflection`) of

* the torsional model (paper-table6 with the error): sun and carrier turn about fixed axes, rigid pins;
* the lateral-torsional model with the sun and carrier held stiff (1e13 N/m) and the file's planet bearings
  (paper-table6-lateral, 5e9 N/m): what the hand estimate assumes;
* the lateral-torsional model as packaged (sun bearing 2e9 N/m: the sun gives way a little and evens the
  planets' loads);

and the hand estimate of :func:`components.analysis.load_sharing.pin_error_factor` for rigid and for the file's
planet bearings (the mesh's tangent stiffness ``1.5 F / d`` at the static indentation ``d``). One co-simulated
point: the packaged scenario paper-60s-pin-error (50 um; wind-driven, 60 s), its summary's factor.

Run: ``python benchmarks/load_sharing.py [--out docs/img/load_sharing.png] [--no-run] [--fmu-dir DIR]``.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

ERRORS_UM = np.arange(0.0, 101.0, 10.0)


def stage1_factor(drivetrain, error_m: float) -> float:
    """K of stage 1 at the rated load with a tangential error ``error_m`` of planet 1 (static equilibrium)."""
    from components.analysis.load_sharing import load_sharing
    from components.model.assembly import Assembly

    st = drivetrain.stages[0]
    errors = ((0.0, error_m),) + ((0.0, 0.0),) * (st.n_planets - 1)
    a = Assembly(replace(drivetrain, stages=(replace(st, pin_errors_m=errors),) + drivetrain.stages[1:]))
    q, _, _ = a.static_deflection(drivetrain.generator.counter_torque_nm)
    forces = a.loads(q, np.zeros_like(q)).contact_force_n
    planets = [i for i, m in enumerate(a.meshes) if m.stage == st.name and m.kind == "sun_planet"]
    return load_sharing(st.name, forces[planets][None, :]).factor


def hand_inputs(drivetrain) -> tuple[float, float, float]:
    """Mean planet force F [N], the mesh's tangent stiffness 1.5 F / d [N/m] and the pressure angle of stage 1."""
    from components.model.assembly import Assembly

    st = drivetrain.stages[0]
    a = Assembly(drivetrain)
    q, _, _ = a.static_deflection(drivetrain.generator.counter_torque_nm)
    loads = a.loads(q, np.zeros_like(q))
    i = next(i for i, m in enumerate(a.meshes) if m.stage == st.name and m.kind == "sun_planet")
    force = float(loads.contact_force_n[i])
    indentation = (force / st.sun_mesh.stiffness) ** (1.0 / st.sun_mesh.exponent)  # CFS beyond the backlash (eq. 2)
    return force, st.sun_mesh.exponent * force / indentation, st.sun_mesh.pressure_angle_rad


def stiff_centre(drivetrain):
    """The lateral drivetrain with stage 1's sun and carrier bearings 1e13 N/m."""
    st = drivetrain.stages[0]
    lat = st.lateral
    stiff = replace(lat.sun_bearing, stiffness_n_per_m=1e13)
    lat = replace(lat, sun_bearing=stiff, carrier_bearing=replace(lat.carrier_bearing, stiffness_n_per_m=1e13))
    return replace(drivetrain, stages=(replace(st, lateral=lat),) + drivetrain.stages[1:])


def cosimulated(fmu_dir: str | None) -> float:
    """The stage-1 factor of `dtcosim run paper-60s-pin-error` (its summary.json)."""
    from orchestrator.commands.cli import main as dtcosim

    with tempfile.TemporaryDirectory(prefix="dtcosim-ls-") as tmp:
        code = dtcosim(["run", "paper-60s-pin-error", "--out", tmp, "--no-plots", "-q"]
                       + (["--fmu-dir", fmu_dir] if fmu_dir else []))
        if code != 0:
            raise SystemExit(f"dtcosim run paper-60s-pin-error failed ({code})")
        summary = json.loads((Path(tmp) / "summary.json").read_text())
    return summary["load_sharing"]["stages"]["gearbox.stage1"]["factor"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/img/load_sharing.png"), help="the figure")
    parser.add_argument("--no-run", action="store_true", help="skip the co-simulated point")
    parser.add_argument("--fmu-dir", default=None, help="FMU directory of the co-simulated run")
    args = parser.parse_args()

    from components.analysis.load_sharing import pin_error_factor
    from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

    torsional = load_drivetrain_file(find_drivetrain("paper-table6")).drivetrain
    lateral = load_drivetrain_file(find_drivetrain("paper-table6-lateral")).drivetrain
    held = stiff_centre(lateral)
    k_b = lateral.stages[0].lateral.planet_bearing.stiffness_n_per_m
    force, k_mesh, alpha = hand_inputs(torsional)
    n = torsional.stages[0].n_planets
    curves = {
        "torsional model (rigid pins, sun and carrier)": [stage1_factor(torsional, e * 1e-6) for e in ERRORS_UM],
        "hand estimate, rigid": [pin_error_factor(e * 1e-6, force, k_mesh, n, alpha) for e in ERRORS_UM],
        "lateral, stiff sun and carrier, planet bearings 5e9 N/m": [stage1_factor(held, e * 1e-6) for e in ERRORS_UM],
        "hand estimate, planet bearings 5e9 N/m": [pin_error_factor(e * 1e-6, force, k_mesh, n, alpha, k_b)
                                                   for e in ERRORS_UM],
        "lateral as packaged (sun bearing 2e9 N/m)": [stage1_factor(lateral, e * 1e-6) for e in ERRORS_UM],
    }
    print(f"stage 1 at 25.4 kN m: planet force F = {force:.6g} N, indentation d = {1.5 * force / k_mesh * 1e6:.1f} um, "
          f"mesh tangent stiffness 1.5 F / d = {k_mesh:.4g} N/m, {n} planets")
    print("load-sharing factor K of stage 1 against the tangential pin error of planet 1:")
    print(f"{'error [um]':>10}  " + "  ".join(f"{i + 1:>8}" for i in range(len(curves))))
    for j, e in enumerate(ERRORS_UM):
        print(f"{e:>10.0f}  " + "  ".join(f"{c[j]:>8.5f}" for c in curves.values()))
    for i, name in enumerate(curves):
        print(f"  {i + 1}: {name}")
    point = None if args.no_run else cosimulated(args.fmu_dir)
    if point is not None:
        print(f"co-simulated paper-60s-pin-error (50 um, wind, 60 s): K = {point:.5f} (max over [5, 60] s), static "
              f"{curves['lateral as packaged (sun bearing 2e9 N/m)'][5]:.5f}")

    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.add_subplot()
    styles = ["-o", "--", "-s", ":", "-^"]
    for (name, values), style in zip(curves.items(), styles):
        ax.plot(ERRORS_UM, values, style, label=name, markersize=4)
    if point is not None:
        ax.plot([50.0], [point], "k*", markersize=11, label="co-simulated paper-60s-pin-error (max over the window)")
    ax.set_xlabel("tangential pin position error of stage-1 planet 1 [um]")
    ax.set_ylabel("load-sharing factor K_gamma of stage 1 [-]")
    ax.set_title("Table 6 gearbox, 25.4 kN m: planet load sharing against a pin error")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper left")
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    assert all(math.isfinite(v) for c in curves.values() for v in c)


if __name__ == "__main__":
    main()
