"""Presets (Tables 3, 5, 6; Sec. 4.1) and the assembly matrices."""

import math
from dataclasses import replace

import numpy as np
import pytest

from components import units
from components.analysis.equilibrium import static_equilibrium
from components.model.assembly import Assembly
from components.model.parameter_map import flatten, unflatten
from components.model.presets import (
    cosim_preset,
    sensitivity_variant,
    table3_parallel,
    table5_planetary,
    table6_gearbox,
)
from components.model.stages import ParallelStage, PlanetaryStage, solid_disc

COS20 = math.cos(math.radians(20.0))


def test_table6_gear_sizes_and_ratios():
    s1, s2, s3 = table6_gearbox().stages
    assert (s1.sun_radius_m, s1.planet_radius_m, s1.ring_radius_m) == pytest.approx((0.1, 0.4, 0.9))  # Z 20/80/180
    assert (s2.sun_radius_m, s2.planet_radius_m, s2.ring_radius_m) == pytest.approx((0.1, 0.3, 0.7))  # Z 20/60/140
    assert (s3.drive_radius_m, s3.driven_radius_m) == pytest.approx((0.1, 0.08))  # Z 20/16
    assert (s1.ratio, s2.ratio, s3.ratio) == pytest.approx((10.0, 8.0, 1.25))
    assert table6_gearbox().ratio == pytest.approx(100.0)


def _discs(dt):
    """(name, table value, solid steel disc value) for every mass and inertia."""
    rows = []
    for st in dt.stages:
        if isinstance(st, PlanetaryStage):
            parts = [("sun", st.sun_radius_m, st.sun_mass_kg, st.sun_inertia_kgm2),
                     ("planet", st.planet_radius_m, st.planet_mass_kg, st.planet_inertia_kgm2)]
        else:
            parts = [("drive", st.drive_radius_m, st.drive_mass_kg, st.drive_inertia_kgm2),
                     ("driven", st.driven_radius_m, st.driven_mass_kg, st.driven_inertia_kgm2)]
        for part, r, m, inertia in parts:
            # Table 6's stage-2 sun (12.25 kg) is a 50 mm wide disc although stage 2 is 5 mm wide
            width = 0.05 if (st.name == "stage2" and part == "sun") else st.width_m
            m_disc, i_disc = solid_disc(r, width)
            rows.append((f"{st.name}.{part}_mass", m, m_disc))
            rows.append((f"{st.name}.{part}_inertia", inertia, i_disc))
    return rows


@pytest.mark.parametrize("name,table,disc", _discs(table6_gearbox()))
def test_table6_masses_and_inertias_are_solid_steel_discs(name, table, disc):
    assert table == pytest.approx(disc, rel=0.02), name


def test_table6_generator_and_shafts_in_si():
    dt = table6_gearbox()
    assert dt.generator.inertia_kgm2 == pytest.approx(151.0)
    assert dt.generator.counter_torque_nm == pytest.approx(25400.0)
    k1 = dt.shafts[0].stiffness_nm_per_rad
    assert k1 == pytest.approx(1e9 * 1e-3 * 180 / math.pi)
    assert dt.output_shaft.damping_nms_per_rad == pytest.approx(1e4 * 1e-3 * 180 / math.pi)


@pytest.mark.parametrize("r1", [6.0, 7.5, 10.0])
def test_sensitivity_variant(r1):
    dt = sensitivity_variant(r1, 300.0)
    s1, s2, s3 = dt.stages
    assert s1.ratio == pytest.approx(r1)
    assert s2.ratio == pytest.approx(100.0 / (r1 * 1.25))
    assert dt.ratio == pytest.approx(100.0)
    base = table6_gearbox().stages[1]
    assert s2.planet_mass_kg == pytest.approx(base.planet_mass_kg * 10.0 / r1)
    assert s2.sun_inertia_kgm2 == pytest.approx(base.sun_inertia_kgm2 * 10.0 / r1)
    assert dt.generator is None and dt.output_torque_nm == 1000.0
    assert s1.sun_mesh.regularisation == pytest.approx(3.0e5)


def test_kinematic_ratios_of_table6():
    a = Assembly(table6_gearbox())
    kappa = dict(zip(a.dof_names, a.kinematic_ratio))
    assert kappa["stage1.sun"] == pytest.approx(10.0)
    assert kappa["stage1.planet[1]"] == pytest.approx(1.0 - 0.9 / 0.4)
    assert kappa["stage2.carrier"] == pytest.approx(10.0)
    assert kappa["stage2.sun"] == pytest.approx(80.0)
    assert kappa["stage3.driven"] == pytest.approx(100.0)
    assert kappa["generator"] == pytest.approx(100.0)
    np.testing.assert_allclose(a.A_all @ a.kinematic_ratio_all, 0.0, atol=1e-12)
    np.testing.assert_allclose(a.S_all @ a.kinematic_ratio_all, 0.0, atol=1e-12)


def _static_equilibrium(a: Assembly, torque_nm: float) -> np.ndarray:
    return static_equilibrium(a, torque_nm).q_rad


def test_static_forces_are_torque_over_base_radius():
    a = Assembly(table6_gearbox())
    q = _static_equilibrium(a, 25400.0)
    f = dict(zip(a.mesh_names, a.loads(q, np.zeros_like(q)).contact_force_n))
    t3 = 25400.0
    t2 = t3 * 1.25
    t1 = t2 * 8.0
    assert f["stage3.F_mesh"] == pytest.approx(t3 / (0.08 * COS20), rel=1e-9)
    assert f["stage2.F_sp[2]"] == pytest.approx(t2 / (3 * 0.1 * COS20), rel=1e-9)
    assert f["stage2.F_rp[3]"] == pytest.approx(t2 / (3 * 0.1 * COS20), rel=1e-9)  # planet balance F_sp = F_rp (eq. 6)
    assert f["stage1.F_sp[1]"] == pytest.approx(t1 / (3 * 0.1 * COS20), rel=1e-9)


def test_jacobian_matches_finite_differences():
    a = Assembly(table6_gearbox(), cut_at_generator=True)
    q = _static_equilibrium(Assembly(table6_gearbox()), 25400.0)[:-1]
    rng = np.random.default_rng(1)
    v = rng.normal(size=a.n_dof) * 1e-3
    qx, vx = np.array([4.4]), np.array([0.01])
    dq, dv, dqx, dvx = a.acceleration_jacobian(q, v, qx, vx)

    def acc(q_, v_, qx_=qx, vx_=vx):
        return a.acceleration(q_, v_, 0.0, 0.0, qx_, vx_)

    for j in range(a.n_dof):
        e = np.zeros(a.n_dof)
        e[j] = 1e-9
        np.testing.assert_allclose(dq[:, j], (acc(q + e, v) - acc(q - e, v)) / 2e-9, rtol=1e-4, atol=1e-3 * np.abs(dq).max())
        np.testing.assert_allclose(dv[:, j], (acc(q, v + e) - acc(q, v - e)) / 2e-9, rtol=1e-4, atol=1e-3 * np.abs(dv).max())
    np.testing.assert_allclose(dqx[:, 0], (acc(q, v, qx + 1e-7) - acc(q, v, qx - 1e-7)) / 2e-7, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(dvx[:, 0], (acc(q, v, qx, vx + 1e-7) - acc(q, v, qx, vx - 1e-7)) / 2e-7, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("form", ["numpy", "compiled"])
def test_the_kernels_folded_acceleration_equals_the_matrix_form(form):
    """The kernel evaluates the folded matrix (inverse inertias, moment arms, shafts, port, driver in one);
    :meth:`Assembly.acceleration` the equations of motion term by term."""
    from components.model import kernel

    step = kernel.step if form == "numpy" else pytest.importorskip("components.compile.jit").load_compiled(kernel.GEARBOX)
    a = Assembly(table6_gearbox(), cut_at_generator=True)
    m, n = a.n_mesh, a.n_dof
    rng = np.random.default_rng(2)
    for scale in (1e-4, 1e-3, 1e-2):
        y = rng.normal(size=2 * n) * scale
        acc, z, defl = np.zeros(n), np.zeros(m + 2 * n + 4), np.zeros((2, m))
        step.acceleration(y, 0.3, 0.02, 0.7, np.ones(m), a.nz_index, a.nz_value, a.port_deflection, a.mesh_offset,
                          a.fast_index, a.fast_value, a.law.table, z, defl, acc)
        ref = a.acceleration(y[:n], y[n:], 0.7, 0.0, np.array([0.3]), np.array([0.02]))
        np.testing.assert_allclose(acc, ref, rtol=1e-10, atol=1e-9 * np.abs(ref).max())


@pytest.mark.parametrize("build", [table3_parallel, table5_planetary, table6_gearbox])
def test_parameter_map_round_trip(build):
    dt = build()
    assert unflatten(dt, flatten(dt)) == dt


def test_cosim_presets_have_an_output_shaft():
    for name in ("table3", "table5", "table6"):
        dt = cosim_preset(name)
        assert dt.generator is not None and dt.output_shaft is not None
    assert Assembly(cosim_preset("table5"), cut_at_generator=True).port_ratio[0] == pytest.approx(1 + 86 / 22)


def test_table3_and_table5_geometry():
    (p,) = table3_parallel().stages
    assert isinstance(p, ParallelStage)
    assert (p.drive_radius_m, p.driven_radius_m) == pytest.approx((0.16, 0.11))
    (s,) = table5_planetary().stages
    assert (s.sun_radius_m, s.planet_radius_m, s.ring_radius_m) == pytest.approx((0.11, 0.16, 0.43))
    assert s.ratio == pytest.approx(4.909, rel=1e-3)
    assert units.kgmm2(3.16e5) == pytest.approx(s.planet_inertia_kgm2)


def test_any_stage_sequence_parallel_then_planetary():
    """A parallel stage driving a planetary stage through a shaft: kinematics and static forces."""
    from components.model.drivetrain import Drivetrain
    from components.model.stages import Shaft

    (par,) = table3_parallel().stages
    (pla,) = table5_planetary().stages
    dt = Drivetrain(
        stages=(par, replace(pla, name="stage2")),
        shafts=(Shaft("shaft1", 1.0e7, 1.0e3),),
        output_torque_nm=500.0,
    )
    a = Assembly(dt)
    assert dt.ratio == pytest.approx(par.ratio * pla.ratio)
    kappa = dict(zip(a.dof_names, a.kinematic_ratio))
    assert kappa["stage1.driven"] == pytest.approx(par.ratio)
    assert kappa["stage2.carrier"] == pytest.approx(par.ratio)
    assert kappa["stage2.sun"] == pytest.approx(par.ratio * pla.ratio)
    q = _static_equilibrium(a, 500.0)
    f = dict(zip(a.mesh_names, a.loads(q, np.zeros_like(q)).contact_force_n))
    sun_torque = 500.0
    carrier_torque = sun_torque * pla.ratio
    assert f["stage2.F_sp[1]"] == pytest.approx(sun_torque / (3 * pla.sun_radius_m * COS20), rel=1e-9)
    assert f["stage1.F_mesh"] == pytest.approx(carrier_torque / (par.driven_radius_m * COS20), rel=1e-9)
