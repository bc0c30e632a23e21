"""The design table of a drivetrain file as text (``dtcosim drivetrain show``)."""

from __future__ import annotations

import math

from components.model.design_table import DesignTable
from components.units import rad_per_s_to_rpm

_MESH_LABEL = {"sun_planet": "sun-planet", "ring_planet": "ring-planet", "parallel": "mesh"}


def _mm(value_m: float) -> str:
    return f"{1e3 * value_m:.6g}"


def _check(passed: bool | None) -> str:
    """A failed geometry check is an error before any table: one shown here is allowed ([plausibility])."""
    return {True: "ok", False: "not met", None: "n/a"}[passed]


def format_design_table(table: DesignTable, source: str = "") -> str:
    """Readable design table: per stage ratio, radii, centre distance, bodies, mesh frequency, static forces, checks."""
    lines = [f"drivetrain {table.name}" + (f" ({source})" if source else ""),
             f"total ratio {table.ratio:.3f} (= {table.ratio:.10g}); operating point: rotor {rad_per_s_to_rpm(table.rotor_speed_rad_s):.6g} rpm, "
             f"input torque {table.input_torque_nm:.6g} N m"]
    for st in table.stages:
        lines.append("")
        head = f"{st.name}: {st.kind}, ratio {st.ratio:.6g}, module {_mm(st.module_m)} mm, pressure angle " \
               f"{math.degrees(st.pressure_angle_rad):.6g} deg, face width {_mm(st.face_width_m)} mm"
        if st.n_planets is not None:
            angles = ", ".join(f"{math.degrees(a):.6g}" for a in st.planet_angles_rad)
            head += f", {st.n_planets} planet(s) at {angles} deg"
        lines.append(head)
        lines.append(f"  {'member':<10}{'teeth':>10}{'pitch r [mm]':>14}{'base r [mm]':>14}")
        for member, r in st.pitch_radius_m.items():
            z = st.teeth[member]
            teeth = f"{z:.0f}" if abs(z - round(z)) < 1e-9 else f"{z:.4f}"
            lines.append(f"  {member:<10}{teeth:>10}{_mm(r):>14}{_mm(st.base_radius_m[member]):>14}")
        lines.append(f"  centre distance {_mm(st.centre_distance_m)} mm; input {rad_per_s_to_rpm(st.input_speed_rad_s):.6g} rpm, "
                     f"{st.input_torque_nm:.6g} N m -> output {st.output_torque_nm:.6g} N m; "
                     f"mesh frequency {st.mesh_frequency_hz:.6g} Hz")
        for m in st.meshes:
            per = f" per planet (x{m.count})" if m.count > 1 or st.n_planets is not None else ""
            lines.append(f"  static {_MESH_LABEL[m.kind]} force {m.static_force_n:.10g} N{per} "
                         f"= T / ({m.count} x r_b {_mm(m.base_radius_m)} mm)" if m.kind != "ring_planet" else
                         f"  static {_MESH_LABEL[m.kind]} force {m.static_force_n:.10g} N{per} (planet moment balance)")
        lines.append(f"  {'body':<24}{'mass [kg]':>12}{'inertia [kg m2]':>18}  source")
        for b in st.bodies:
            mass = f"{b.mass_kg:.6g}" if b.mass_kg is not None else "-"
            lines.append(f"  {b.name:<24}{mass:>12}{b.inertia_kgm2:>18.6g}  {b.source}")
        for c in st.checks:
            lines.append(f"  check {c.name}: {_check(c.passed)} ({c.detail})")
    lines.append("")
    for sh in table.shafts:
        lines.append(f"shaft {sh['name']}: stiffness {sh['stiffness_nm_per_rad']:.6g} N m/rad, "
                     f"damping {sh['damping_nms_per_rad']:.6g} N m s/rad")
    if table.generator is not None:
        g = table.generator
        lines.append(f"generator: inertia {g['inertia_kgm2']:.6g} kg m2, counter torque {g['counter_torque_nm']:.6g} N m, "
                     f"speed {rad_per_s_to_rpm(g['speed_rad_s']):.6g} rpm, "
                     f"power {g['counter_torque_nm'] * g['speed_rad_s'] / 1e3:.6g} kW")
    else:
        lines.append(f"no generator: counter torque {table.output_torque_nm:.6g} N m on the last output member")
    return "\n".join(lines)
